// The haptic loop's period where the core runs (issue 50 item 3: under Wine for Windows, beside
// bench/loops.py on Linux): a replayed rope stroke on a 64 x 64 clay-free patch (16 x 16 controls)
// in the threaded runtime at 1 kHz with real-time priority asked for, SECONDS long; prints the
// priority the system granted, the loops' rates and the haptic period's percentiles.
//     loop_period [SECONDS]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <thread>

#include "devices/replay_device.hpp"
#include "runtime/haptic_runtime.hpp"
#include "solvers/dynamic_surface.hpp"

using namespace hs;

int main(int argc, char** argv) {
    const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
    if (!(seconds > 0.5 && seconds < 600)) {
        std::fprintf(stderr, "loop_period: SECONDS from 0.5 to 600\n");
        return 2;
    }
    auto surface = std::make_shared<DynamicSurface>(BSplineSurface::plane(16, 16, 3, 3, 100, 100), 64, 64);
    const int n = 200;
    std::vector<double> t(n);
    Points xyz(n, 3);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q(n, 4);
    std::vector<std::uint32_t> buttons(n, 1);  // (held throughout: the loops never idle)
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        t[static_cast<size_t>(i)] = seconds * s;
        xyz.row(i) << 0, 0, 10.0 * std::sin(3.14159 * s);
        q.row(i) << 1, 0, 0, 0;
    }
    RuntimeSettings settings;
    settings.realtime = true;
    settings.stopWhenFinished = true;
    HapticRuntime runtime(surface, std::make_shared<ReplayDevice>(t, xyz, q, buttons), settings);
    runtime.start();
    while (runtime.status().running) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const RuntimeStatus s = runtime.status();
    runtime.stop();
    std::printf("priority: %s\nhaptic %.0f Hz, simulation %.0f Hz over %.1f s; period p50 %.3f ms, p99 %.3f ms, "
                "max %.3f ms%s%s\n",
                runtime.realtimeHow().c_str(), s.hapticHz, s.simHz, s.elapsed, 1e3 * s.periodP50, 1e3 * s.periodP99,
                1e3 * s.periodMax, s.error.empty() ? "" : "; error: ", s.error.c_str());
    return s.error.empty() ? 0 : 1;
}
