// A D-Bus connection as far as asking one service one thing needs: the socket, EXTERNAL
// authentication, Hello, a method call and its reply, marshalled here by hand (the wire format is
// small and stable: no libdbus to link or load). Blocking, with a timeout; used once per session
// (RealtimeKit), never in a loop.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace hs {

/// A message body being written (little-endian, aligned as D-Bus aligns from the body's start).
class DBusWriter {
public:
    void u32(std::uint32_t v);
    void u64(std::uint64_t v);
    void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
    void string(const std::string& s);  ///< also an object path
    const std::vector<std::uint8_t>& bytes() const { return b_; }

private:
    void align(std::size_t n);
    std::vector<std::uint8_t> b_;
};

/// What a method call got back.
struct DBusReply {
    bool error = false;
    std::string errorName;               ///< "org.freedesktop.DBus.Error.ServiceUnknown", ...
    std::string signature;               ///< of the body
    std::vector<std::uint8_t> body;
    /// The body's first argument as a string (an error's message), or "".
    std::string firstString() const;
    /// The body's first argument as an integer: a variant of y, n, q, i, u, x or t (a property),
    /// or one of those; throws std::runtime_error otherwise.
    std::int64_t firstInteger() const;
};

class DBusConnection {
public:
    /// The system bus: DBUS_SYSTEM_BUS_ADDRESS, else the well-known socket.
    static std::string systemBusAddress();
    /// Connects to the first usable "unix:path=..." or "unix:abstract=..." of `address` (a ;-list),
    /// authenticates as this process's user and says Hello; throws std::runtime_error saying why not.
    DBusConnection(const std::string& address, double timeoutSeconds);
    ~DBusConnection();
    DBusConnection(const DBusConnection&) = delete;
    DBusConnection& operator=(const DBusConnection&) = delete;

    /// Calls `member` and waits for its reply (other messages are skipped); throws
    /// std::runtime_error where the bus fails or times out (an error reply is returned, not thrown).
    DBusReply call(const std::string& destination, const std::string& path, const std::string& interface,
                   const std::string& member, const std::string& signature, const std::vector<std::uint8_t>& body);

private:
    void send(const std::vector<std::uint8_t>& message);
    void readExactly(std::uint8_t* out, std::size_t n);
    std::string readLine();

    int fd_ = -1;
    std::uint32_t serial_ = 0;
};

}  // namespace hs
