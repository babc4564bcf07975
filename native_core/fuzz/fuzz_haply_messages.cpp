// libFuzzer harness: arbitrary bytes as a message from the Haply Inverse Service, read both as the
// inventory and as a state update; a state the reader accepts is finite. Then a command written
// for a force taken from the input must fit and be a whole JSON object.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "devices/haply/haply_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static hs::haply::Reader reader;  // (sized once, as the device's is)
    const std::size_t n = size < hs::haply::kMaxMessage ? size : hs::haply::kMaxMessage;
    std::memcpy(reader.buffer(), data, n);
    std::vector<hs::haply::Inverse3Info> devices;
    std::string why;
    reader.inventory(n, devices, why);
    std::memcpy(reader.buffer(), data, n);  // (simdjson reads in place: a fresh copy)
    hs::haply::State s;
    if (reader.state(n, "049D", s) && (!s.position.allFinite() || !s.velocity.allFinite())) std::abort();
    double f[3] = {0, 0, 0};
    if (size >= sizeof f) std::memcpy(f, data, sizeof f);
    char out[1024];
    const std::size_t k = hs::haply::writeForceCommand(out, sizeof out, "049D", hs::Vec3(f[0], f[1], f[2]), size % 2 == 0);
    if (k == 0 || out[0] != '{' || out[k - 1] != '}') std::abort();
    return 0;
}
