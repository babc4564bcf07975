#include "common/platform/dbus_connection.hpp"

#include <sys/socket.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace hs {

namespace {

constexpr std::uint8_t kMethodCall = 1, kMethodReturn = 2, kError = 3;
constexpr std::uint8_t kPath = 1, kInterface = 2, kMember = 3, kErrorName = 4, kReplySerial = 5, kDestination = 6,
                       kSignature = 8;
constexpr std::uint32_t kMaxBody = 1u << 20, kMaxFields = 1u << 16;
constexpr int kMaxSkipped = 256;  // messages read while waiting for a reply (signals: NameAcquired, ...)

void pad(std::vector<std::uint8_t>& b, std::size_t n) {
    while (b.size() % n) b.push_back(0);
}
void putU32(std::vector<std::uint8_t>& b, std::uint32_t v) {
    pad(b, 4);
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void putString(std::vector<std::uint8_t>& b, const std::string& s) {
    putU32(b, static_cast<std::uint32_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    b.push_back(0);
}
void putSignature(std::vector<std::uint8_t>& b, const std::string& s) {
    b.push_back(static_cast<std::uint8_t>(s.size()));
    b.insert(b.end(), s.begin(), s.end());
    b.push_back(0);
}
void putField(std::vector<std::uint8_t>& b, std::uint8_t code, char type, const std::string& value) {
    pad(b, 8);
    b.push_back(code);
    putSignature(b, std::string(1, type));
    if (type == 'g') putSignature(b, value);
    else putString(b, value);
}

/// Reads a little-endian message (or its body) with D-Bus alignment from its start.
class Reader {
public:
    Reader(const std::vector<std::uint8_t>& b, std::size_t at = 0) : b_(b), at_(at) {}
    std::size_t at() const { return at_; }
    void align(std::size_t n) { at_ = (at_ + n - 1) / n * n; }
    std::uint64_t unsignedOf(std::size_t bytes) {
        align(bytes);
        need(bytes);
        std::uint64_t v = 0;
        for (std::size_t i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(b_[at_ + i]) << (8 * i);
        at_ += bytes;
        return v;
    }
    std::string string() {
        const auto n = static_cast<std::size_t>(unsignedOf(4));
        return text(n);
    }
    std::string signature() { return text(static_cast<std::size_t>(unsignedOf(1))); }
    /// A value of basic type `type` as an integer (y n q i u x t), else std::runtime_error.
    std::int64_t integer(char type) {
        switch (type) {
            case 'y': return static_cast<std::int64_t>(unsignedOf(1));
            case 'n': return static_cast<std::int16_t>(unsignedOf(2));
            case 'q': return static_cast<std::int64_t>(unsignedOf(2));
            case 'i': return static_cast<std::int32_t>(unsignedOf(4));
            case 'u': return static_cast<std::int64_t>(unsignedOf(4));
            case 'x': return static_cast<std::int64_t>(unsignedOf(8));
            case 't': return static_cast<std::int64_t>(unsignedOf(8));
            default: throw std::runtime_error(std::string("D-Bus: expected an integer, got type ") + type);
        }
    }

private:
    void need(std::size_t n) const {
        if (at_ + n > b_.size()) throw std::runtime_error("D-Bus: a message ended early");
    }
    std::string text(std::size_t n) {
        need(n + 1);
        std::string s(reinterpret_cast<const char*>(b_.data() + at_), n);
        at_ += n + 1;
        return s;
    }
    const std::vector<std::uint8_t>& b_;
    std::size_t at_;
};

std::runtime_error failure(const std::string& what) {
    return std::runtime_error(what + ": " + std::strerror(errno));
}

}  // namespace

void DBusWriter::align(std::size_t n) { pad(b_, n); }
void DBusWriter::u32(std::uint32_t v) { putU32(b_, v); }
void DBusWriter::u64(std::uint64_t v) {
    align(8);
    for (int i = 0; i < 8; ++i) b_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void DBusWriter::string(const std::string& s) { putString(b_, s); }

std::string DBusReply::firstString() const {
    if (signature.empty() || signature[0] != 's') return "";
    Reader r(body);
    return r.string();
}

std::int64_t DBusReply::firstInteger() const {
    if (signature.empty()) throw std::runtime_error("D-Bus: the reply has no value");
    Reader r(body);
    char type = signature[0];
    if (type == 'v') {
        const std::string inner = r.signature();
        if (inner.size() != 1) throw std::runtime_error("D-Bus: expected a number, got a " + inner);
        type = inner[0];
    }
    return r.integer(type);
}

std::string DBusConnection::systemBusAddress() {
    const char* env = std::getenv("DBUS_SYSTEM_BUS_ADDRESS");
    return env && *env ? env : "unix:path=/var/run/dbus/system_bus_socket";
}

DBusConnection::DBusConnection(const std::string& address, double timeoutSeconds) {
    std::string reasons;
    std::stringstream list(address);
    for (std::string entry; std::getline(list, entry, ';');) {
        if (entry.rfind("unix:", 0) != 0) continue;
        std::string path, abstract;
        std::stringstream keys(entry.substr(5));
        for (std::string kv; std::getline(keys, kv, ',');) {
            if (kv.rfind("path=", 0) == 0) path = kv.substr(5);
            if (kv.rfind("abstract=", 0) == 0) abstract = kv.substr(9);
        }
        const std::string& name = path.empty() ? abstract : path;
        sockaddr_un sa{};
        if (name.empty() || name.size() + 1 >= sizeof sa.sun_path) continue;
        sa.sun_family = AF_UNIX;
        const std::size_t offset = path.empty() ? 1 : 0;  // (an abstract name starts with a zero byte)
        std::memcpy(sa.sun_path + offset, name.data(), name.size());
        const auto length = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + offset + name.size() + (path.empty() ? 0 : 1));
        const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (fd < 0) throw failure("D-Bus: socket");
        if (::connect(fd, reinterpret_cast<const sockaddr*>(&sa), length) == 0) {
            fd_ = fd;
            break;
        }
        reasons += " " + name + ": " + std::strerror(errno) + ";";
        ::close(fd);
    }
    if (fd_ < 0) throw std::runtime_error("no D-Bus system bus at " + address + (reasons.empty() ? "" : " (" + reasons + ")"));
    timeval tv{};
    tv.tv_sec = static_cast<time_t>(timeoutSeconds);
    tv.tv_usec = static_cast<suseconds_t>((timeoutSeconds - std::floor(timeoutSeconds)) * 1e6);
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(fd_, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    // EXTERNAL: the bus reads the uid from the socket; we name it, in hex of its decimal digits.
    std::string hex;
    static const char digits[] = "0123456789abcdef";
    for (char c : std::to_string(::getuid())) {
        hex += digits[(static_cast<unsigned char>(c) >> 4) & 15];
        hex += digits[static_cast<unsigned char>(c) & 15];
    }
    const std::string auth = std::string(1, '\0') + "AUTH EXTERNAL " + hex + "\r\n";
    send(std::vector<std::uint8_t>(auth.begin(), auth.end()));
    const std::string answer = readLine();
    if (answer.rfind("OK ", 0) != 0) throw std::runtime_error("D-Bus: the bus refused us: " + answer);
    const std::string begin = "BEGIN\r\n";
    send(std::vector<std::uint8_t>(begin.begin(), begin.end()));
    const DBusReply hello = call("org.freedesktop.DBus", "/org/freedesktop/DBus", "org.freedesktop.DBus", "Hello", "", {});
    if (hello.error) throw std::runtime_error("D-Bus: Hello failed: " + hello.errorName);
}

DBusConnection::~DBusConnection() {
    if (fd_ >= 0) ::close(fd_);
}

void DBusConnection::send(const std::vector<std::uint8_t>& message) {
    std::size_t sent = 0;
    while (sent < message.size()) {
        const ssize_t n = ::send(fd_, message.data() + sent, message.size() - sent, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) throw failure("D-Bus: send");
        sent += static_cast<std::size_t>(n);
    }
}

void DBusConnection::readExactly(std::uint8_t* out, std::size_t n) {
    std::size_t got = 0;
    while (got < n) {
        const ssize_t k = ::recv(fd_, out + got, n - got, 0);
        if (k < 0 && errno == EINTR) continue;
        if (k < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) throw std::runtime_error("D-Bus: no answer in time");
        if (k <= 0) throw k == 0 ? std::runtime_error("D-Bus: the bus closed the connection") : failure("D-Bus: recv");
        got += static_cast<std::size_t>(k);
    }
}

std::string DBusConnection::readLine() {
    std::string line;
    std::uint8_t c = 0;
    while (line.size() < 512) {
        readExactly(&c, 1);
        if (c == '\n') break;
        if (c != '\r') line += static_cast<char>(c);
    }
    return line;
}

DBusReply DBusConnection::call(const std::string& destination, const std::string& path, const std::string& interface,
                               const std::string& member, const std::string& signature,
                               const std::vector<std::uint8_t>& body) {
    const std::uint32_t serial = ++serial_;
    std::vector<std::uint8_t> m{'l', kMethodCall, 0, 1};
    putU32(m, static_cast<std::uint32_t>(body.size()));
    putU32(m, serial);
    putU32(m, 0);  // the header fields' length, filled in below
    const std::size_t fields = m.size();
    putField(m, kPath, 'o', path);
    if (!interface.empty()) putField(m, kInterface, 's', interface);
    putField(m, kMember, 's', member);
    putField(m, kDestination, 's', destination);
    if (!signature.empty()) putField(m, kSignature, 'g', signature);
    const auto length = static_cast<std::uint32_t>(m.size() - fields);
    for (int i = 0; i < 4; ++i) m[12 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(length >> (8 * i));
    pad(m, 8);
    m.insert(m.end(), body.begin(), body.end());
    send(m);
    for (int skipped = 0; skipped < kMaxSkipped; ++skipped) {
        std::vector<std::uint8_t> header(16);
        readExactly(header.data(), 16);
        if (header[0] != 'l') throw std::runtime_error("D-Bus: a big-endian message (not read by this client)");
        Reader fixed(header, 4);
        const auto bodyLength = static_cast<std::uint32_t>(fixed.unsignedOf(4));
        fixed.unsignedOf(4);  // (its serial)
        const auto fieldsLength = static_cast<std::uint32_t>(fixed.unsignedOf(4));
        if (bodyLength > kMaxBody || fieldsLength > kMaxFields) throw std::runtime_error("D-Bus: a message too large");
        header.resize((16 + fieldsLength + 7) / 8 * 8);
        readExactly(header.data() + 16, header.size() - 16);
        DBusReply reply;
        reply.body.resize(bodyLength);
        if (bodyLength) readExactly(reply.body.data(), bodyLength);
        std::uint32_t replyTo = 0;
        Reader r(header, 16);
        while (r.at() < 16 + fieldsLength) {
            r.align(8);
            const auto code = static_cast<std::uint8_t>(r.unsignedOf(1));
            const std::string type = r.signature();
            std::string text;
            std::int64_t number = 0;
            if (type == "s" || type == "o") text = r.string();
            else if (type == "g") text = r.signature();
            else if (type == "u") number = r.integer('u');
            else throw std::runtime_error("D-Bus: a header field of type " + type);
            if (code == kReplySerial) replyTo = static_cast<std::uint32_t>(number);
            if (code == kErrorName) reply.errorName = text;
            if (code == kSignature) reply.signature = text;
        }
        const std::uint8_t type = header[1];
        if ((type == kMethodReturn || type == kError) && replyTo == serial) {
            reply.error = type == kError;
            return reply;
        }
    }
    throw std::runtime_error("D-Bus: no reply among " + std::to_string(kMaxSkipped) + " messages");
}

}  // namespace hs
