// The Novint Falcon's standard-firmware frames (the firmware Novint's SDK loads; libnifalcon
// documents it): 16 bytes between '<' and '>'. Host to device: three 16-bit motor commands, then
// the LED bits and the homing-mode bit. Device to host: three 16-bit encoder counts, then the
// homing status of each encoder and the grip's buttons. Each 16-bit value travels as four
// nibbles, least significant first, and every byte between the delimiters is a nibble plus 0x41,
// so a frame is printable and '<' / '>' never occur inside one. One command frame written, one
// status frame read, per I/O cycle. No allocation anywhere here: the haptic thread runs it.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>

namespace hs::falcon {

constexpr std::size_t kFrameSize = 16;
using Frame = std::array<std::uint8_t, kFrameSize>;

/// LED bits of a command frame.
constexpr std::uint8_t kGreenLed = 0x2, kBlueLed = 0x4, kRedLed = 0x8;

/// What the host sends: motor commands (signed, the firmware's units), LEDs, homing mode.
struct Command {
    std::array<std::int16_t, 3> motor{};
    std::uint8_t leds = 0;  ///< kGreenLed | kBlueLed | kRedLed
    bool homing = false;    ///< the motors seek their index marks (the device is homed once it has)
};

/// What the device answers: encoder counts, which encoders are homed, the grip's buttons.
struct Status {
    std::array<std::int16_t, 3> encoder{};
    std::uint8_t homed = 0;    ///< bit i: encoder i has seen its index mark
    std::uint8_t buttons = 0;  ///< the grip's four buttons (bits 0..3)
    bool allHomed() const { return (homed & 0x7) == 0x7; }
};

Frame encodeCommand(const Command& c);
/// False unless `frame` is a well-formed command frame (the emulator reads them).
bool decodeCommand(const std::uint8_t* frame, Command& out);
Frame encodeStatus(const Status& s);
/// False unless `frame` is a well-formed status frame: '<', 14 bytes in 0x41..0x50, '>'.
bool decodeStatus(const std::uint8_t* frame, Status& out);

/// Status frames out of a byte stream as the USB transport delivers it: a frame may come split
/// over reads or several in one, after noise (a transfer cut short, a stale byte). Bytes that do
/// not start a well-formed frame are skipped, and counted.
class FrameReader {
public:
    /// Takes `n` bytes; returns how many status frames became available.
    int feed(const std::uint8_t* data, std::size_t n);
    /// The oldest available frame, if any.
    bool next(Status& out);
    /// The newest available frame, dropping the older ones (what a haptic tick wants).
    bool latest(Status& out);
    std::uint64_t skippedBytes() const { return skipped_; }
    std::uint64_t frames() const { return frames_; }

private:
    void scan();
    std::array<std::uint8_t, 4 * kFrameSize> pending_{};  ///< bytes not yet framed
    std::size_t pendingLen_ = 0;
    std::array<Status, 8> ready_{};                        ///< decoded, not yet taken (a ring)
    std::size_t readyHead_ = 0, readyCount_ = 0;
    std::uint64_t skipped_ = 0, frames_ = 0;
};

}  // namespace hs::falcon
