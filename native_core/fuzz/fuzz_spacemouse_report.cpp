// libFuzzer harness: arbitrary bytes as a stream of SpaceMouse input reports (the first byte of
// each chunk gives the chunk's length, so one input is many reports of any length, including 0).
#include <cstddef>
#include <cstdint>

#include "devices/hid/spacemouse.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    hs::SpaceMouseParser parser;
    std::size_t at = 0;
    while (at < size) {
        const std::size_t n = data[at] % 65;
        ++at;
        const std::size_t len = n < size - at ? n : size - at;
        parser.feed(data + at, len);
        at += len;
        double out[6];
        hs::hidToFreeCAD(parser.state().axes, 350.0, out);
    }
    return 0;
}
