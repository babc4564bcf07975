// Runs a libFuzzer harness without libFuzzer (GCC builds, ctest under the sanitizers): feeds it each
// file named on the command line, the descriptor and every report inside hid-recorder fixtures
// (*.hid), and then seeded random mutations of all of those, so the harnesses are exercised on
// every `make test` and cannot rot. The real fuzzing is `make fuzz` (clang, libFuzzer).
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "devices/hid/recorded_transport.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s MUTATIONS FILE...\n", argv[0]);
        return 2;
    }
    const int mutations = std::atoi(argv[1]);
    std::vector<std::vector<std::uint8_t>> seeds;
    for (int i = 2; i < argc; ++i) {
        std::ifstream in(argv[i], std::ios::binary);
        if (!in) {
            std::fprintf(stderr, "cannot read %s\n", argv[i]);
            return 2;
        }
        std::stringstream ss;
        ss << in.rdbuf();
        const std::string text = ss.str();
        seeds.emplace_back(text.begin(), text.end());
        const std::string name(argv[i]);
        if (name.size() > 4 && name.compare(name.size() - 4, 4, ".hid") == 0) {
            const hs::HidRecording rec = hs::parseHidRecording(text);
            seeds.push_back(rec.descriptor);
            for (const auto& e : rec.events) seeds.push_back(e.bytes);
        }
    }
    for (const auto& s : seeds) LLVMFuzzerTestOneInput(s.data(), s.size());
    std::mt19937 rng(12345);
    for (int m = 0; m < mutations; ++m) {
        std::vector<std::uint8_t> s = seeds[rng() % seeds.size()];
        const int edits = 1 + static_cast<int>(rng() % 8);
        for (int e = 0; e < edits; ++e) {
            const unsigned kind = rng() % 4;
            if (kind == 0 && !s.empty()) s[rng() % s.size()] = static_cast<std::uint8_t>(rng());
            else if (kind == 1) s.insert(s.begin() + static_cast<long>(s.empty() ? 0 : rng() % s.size()), static_cast<std::uint8_t>(rng()));
            else if (kind == 2 && !s.empty()) s.erase(s.begin() + static_cast<long>(rng() % s.size()));
            else if (!s.empty()) s.resize(rng() % (s.size() + 1));
        }
        LLVMFuzzerTestOneInput(s.data(), s.size());
    }
    std::printf("%zu seeds, %d mutations: no crash\n", seeds.size(), mutations);
    return 0;
}
