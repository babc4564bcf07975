// libFuzzer harness: arbitrary text as a hid-recorder recording. Malformed text must be refused
// with std::invalid_argument naming the line; a recording that parses is then replayed through a
// RecordedTransport into the SpaceMouse parser.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "devices/hid/recorded_transport.hpp"
#include "devices/hid/spacemouse.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    hs::HidRecording rec;
    try {
        rec = hs::parseHidRecording(std::string(reinterpret_cast<const char*>(data), size));
    } catch (const std::invalid_argument&) {
        return 0;
    }
    hs::RecordedTransport transport(rec, false, true);
    hs::SpaceMouseParser parser;
    std::uint8_t buf[64];
    for (int i = 0; i < 1000; ++i) {
        const int n = transport.read(buf, sizeof buf, 0);
        if (n < 0) break;
        parser.feed(buf, static_cast<std::size_t>(n));
    }
    return 0;
}
