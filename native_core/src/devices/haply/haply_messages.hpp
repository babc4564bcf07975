// The Haply Inverse Service's simulation-channel messages (WebSocket JSON, port 10001; Haply's
// "Simulation Channel" and "Control Commands" docs): the inventory it sends on connecting and the
// state update it sends for each message it receives, read with simdjson's DOM parser (a whole
// message validated before any field is read) into fixed buffers (no allocation per message once
// the parser is sized), and the command the client
// sends each tick (set_cursor_force), written into a caller's buffer.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/types.hpp"

namespace hs::haply {

/// The largest message read (bytes); a longer one is malformed.
constexpr std::size_t kMaxMessage = 1 << 18;

/// One Inverse3 in the inventory.
struct Inverse3Info {
    std::string deviceId;
    bool ready = false, inUse = false, calibrated = false;
};

/// What a state update says about the Inverse3 being driven and the handle's buttons.
struct State {
    Vec3 position = Vec3::Zero();  ///< m, Haply's frame (x right, y forward, z up)
    Vec3 velocity = Vec3::Zero();  ///< m/s
    std::uint32_t buttons = 0;     ///< bit 0: a Verse Grip's button (or a wireless one's first)
    bool found = false;            ///< the device's entry was in the message
};

class Reader {
public:
    Reader();
    ~Reader();
    Reader(const Reader&) = delete;
    Reader& operator=(const Reader&) = delete;
    /// The buffer a message is assembled in (capacity kMaxMessage plus simdjson's padding).
    char* buffer() { return buffer_.get(); }
    /// The Inverse3s of an inventory message in buffer()[0, n); false if it is not valid JSON or
    /// has no "inverse3" array. Allocates (it runs once per connection).
    bool inventory(std::size_t n, std::vector<Inverse3Info>& out, std::string& why);
    /// The state of `deviceId` and the buttons in the message in buffer()[0, n); false for input
    /// that is not a state update (`state` keeps what it had). No allocation.
    bool state(std::size_t n, const char* deviceId, State& state);

private:
    struct Parser;
    std::unique_ptr<Parser> parser_;
    std::unique_ptr<char[]> buffer_;
};

/// Writes the per-tick command, a force in N on `deviceId` (plus, with `first`, the session's
/// profile and the identity basis), into out; its length, or 0 if it does not fit.
std::size_t writeForceCommand(char* out, std::size_t capacity, const char* deviceId, const Vec3& force, bool first);

}  // namespace hs::haply
