// libFuzzer harness: arbitrary bytes as a Falcon USB stream, fed in chunks whose sizes the input's
// bytes choose; every frame the reader yields must encode back to a frame that decodes the same.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "devices/falcon/falcon_frames.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    hs::falcon::FrameReader reader;
    std::size_t at = 0;
    while (at < size) {
        const std::size_t n = 1 + data[at] % 48;
        const std::size_t len = n < size - at ? n : size - at;
        reader.feed(data + at, len);
        at += len;
        hs::falcon::Status s, back;
        while (reader.next(s)) {
            const hs::falcon::Frame f = hs::falcon::encodeStatus(s);
            if (!hs::falcon::decodeStatus(f.data(), back) || back.encoder != s.encoder || back.homed != s.homed ||
                back.buttons != s.buttons)
                std::abort();
        }
        hs::falcon::Command c;
        if (len >= hs::falcon::kFrameSize && hs::falcon::decodeCommand(data + at - len, c)) {
            const hs::falcon::Frame f = hs::falcon::encodeCommand(c);
            hs::falcon::Command again;
            if (!hs::falcon::decodeCommand(f.data(), again) || again.motor != c.motor) std::abort();
        }
    }
    return 0;
}
