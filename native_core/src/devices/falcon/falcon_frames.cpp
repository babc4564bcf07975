#include "devices/falcon/falcon_frames.hpp"

#include <algorithm>
#include <cstring>

namespace hs::falcon {

namespace {
constexpr std::uint8_t kOffset = 0x41;

void putWord(Frame& f, int at, std::uint16_t w) {
    for (int k = 0; k < 4; ++k) f[static_cast<std::size_t>(at + k)] = static_cast<std::uint8_t>(kOffset + ((w >> (4 * k)) & 0xF));
}

std::uint16_t getWord(const std::uint8_t* f, int at) {
    std::uint16_t w = 0;
    for (int k = 0; k < 4; ++k) w = static_cast<std::uint16_t>(w | ((f[at + k] - kOffset) & 0xF) << (4 * k));
    return w;
}

bool wellFormed(const std::uint8_t* f) {
    if (f[0] != '<' || f[kFrameSize - 1] != '>') return false;
    for (std::size_t i = 1; i + 1 < kFrameSize; ++i)
        if (f[i] < kOffset || f[i] > kOffset + 0xF) return false;
    return true;
}

Frame frameWith(const std::array<std::int16_t, 3>& words, std::uint8_t flags) {
    Frame f{};
    f[0] = '<';
    f[kFrameSize - 1] = '>';
    for (int i = 0; i < 3; ++i) putWord(f, 1 + 4 * i, static_cast<std::uint16_t>(words[static_cast<std::size_t>(i)]));
    f[13] = static_cast<std::uint8_t>(kOffset + (flags & 0xF));
    f[14] = kOffset;
    return f;
}
}  // namespace

Frame encodeCommand(const Command& c) {
    return frameWith(c.motor, static_cast<std::uint8_t>((c.leds & (kGreenLed | kBlueLed | kRedLed)) | (c.homing ? 1 : 0)));
}

bool decodeCommand(const std::uint8_t* frame, Command& out) {
    if (!wellFormed(frame)) return false;
    for (int i = 0; i < 3; ++i) out.motor[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(getWord(frame, 1 + 4 * i));
    const int flags = frame[13] - kOffset;
    out.leds = static_cast<std::uint8_t>(flags & (kGreenLed | kBlueLed | kRedLed));
    out.homing = (flags & 1) != 0;
    return true;
}

// The status byte carries the homing bits in its high nibble and the buttons in its low one; a
// nibble plus 0x41 cannot hold both, so the firmware sends the byte itself plus 0x41 (modulo 256).
Frame encodeStatus(const Status& s) {
    Frame f = frameWith(s.encoder, 0);
    f[13] = static_cast<std::uint8_t>(kOffset + (((s.homed & 0x7) << 4) | (s.buttons & 0xF)));
    return f;
}

bool decodeStatus(const std::uint8_t* frame, Status& out) {
    if (frame[0] != '<' || frame[kFrameSize - 1] != '>') return false;
    for (std::size_t i = 1; i + 1 < kFrameSize; ++i)
        if (i != 13 && (frame[i] < kOffset || frame[i] > kOffset + 0xF)) return false;
    const int status = static_cast<std::uint8_t>(frame[13] - kOffset);
    if (status & 0x80) return false;  // (three homing bits and four buttons: bit 7 is never set)
    for (int i = 0; i < 3; ++i) out.encoder[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(getWord(frame, 1 + 4 * i));
    out.homed = static_cast<std::uint8_t>((status >> 4) & 0x7);
    out.buttons = static_cast<std::uint8_t>(status & 0xF);
    return true;
}

int FrameReader::feed(const std::uint8_t* data, std::size_t n) {
    const std::uint64_t before = frames_;
    while (n > 0) {
        const std::size_t take = std::min(n, pending_.size() - pendingLen_);
        std::memcpy(pending_.data() + pendingLen_, data, take);
        pendingLen_ += take;
        data += take;
        n -= take;
        scan();
    }
    return static_cast<int>(frames_ - before);
}

void FrameReader::scan() {
    std::size_t at = 0;
    while (pendingLen_ - at >= kFrameSize || (at < pendingLen_ && pending_[at] != '<')) {
        if (pending_[at] != '<') {
            ++at;
            ++skipped_;
            continue;
        }
        Status s;
        if (!decodeStatus(pending_.data() + at, s)) {  // a '<' that does not start a frame
            ++at;
            ++skipped_;
            continue;
        }
        ready_[(readyHead_ + readyCount_) % ready_.size()] = s;
        if (readyCount_ < ready_.size()) ++readyCount_;
        else readyHead_ = (readyHead_ + 1) % ready_.size();  // full: the oldest goes
        ++frames_;
        at += kFrameSize;
    }
    std::memmove(pending_.data(), pending_.data() + at, pendingLen_ - at);
    pendingLen_ -= at;
}

bool FrameReader::next(Status& out) {
    if (readyCount_ == 0) return false;
    out = ready_[readyHead_];
    readyHead_ = (readyHead_ + 1) % ready_.size();
    --readyCount_;
    return true;
}

bool FrameReader::latest(Status& out) {
    if (readyCount_ == 0) return false;
    out = ready_[(readyHead_ + readyCount_ - 1) % ready_.size()];
    readyHead_ = (readyHead_ + readyCount_) % ready_.size();
    readyCount_ = 0;
    return true;
}

}  // namespace hs::falcon
