// The simulation's view of the hand (CursorHistory: the cursor at the step's end, written by the
// haptic thread, read by the simulation's) and the loops replayed on a virtual clock
// (replayMultirate): states reaching the haptic loop late.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "devices/replay_device.hpp"
#include "replay_strokes.hpp"
#include "runtime/cursor_history.hpp"
#include "runtime/multirate_replay.hpp"
#include "solvers/dynamic_surface.hpp"

using namespace hs;

namespace {
DeviceSample sampleAt(double x, std::uint32_t buttons) {
    DeviceSample s;
    s.position = Vec3(x, 2 * x, 3 * x);
    s.buttons = buttons;
    s.valid = true;
    return s;
}

// A rope stroke (bench/haptic_force.py's), let go 0.2 s before the end.
std::shared_ptr<ReplayDevice> ropeStroke(double seconds) { return replayStroke(seconds, seconds - 0.2, pulledUpAndAround); }

std::unique_ptr<DynamicSurface> scene(int mesh) {
    auto s = std::make_unique<DynamicSurface>(BSplineSurface::plane(mesh / 4, mesh / 4, 3, 3, 100, 100), mesh, mesh);
    s->dampingMap().setUniform(5.0);
    return s;
}

// p99 over the grabbed ticks of |force - exact| / max(|exact|, 5 % of the largest |exact|).
double forceErrorP99(const MultirateTicks& run, const MultirateTicks& exact, double from, double to) {
    double largest = 0;
    for (Eigen::Index i = 0; i < exact.force.rows(); ++i) largest = std::max(largest, exact.force.row(i).norm());
    std::vector<double> e;
    for (size_t i = 0; i < run.t.size(); ++i)
        if (run.t[i] >= from && run.t[i] < to) {
            const auto k = static_cast<Eigen::Index>(i);
            e.push_back((run.force.row(k) - exact.force.row(k)).norm() / std::max(exact.force.row(k).norm(), 0.05 * largest));
        }
    std::sort(e.begin(), e.end());
    return e[static_cast<size_t>(0.99 * static_cast<double>(e.size() - 1))];
}
}  // namespace

TEST(CursorHistory, GivesTheHandAtATimeBetweenItsSamples) {
    CursorHistory h;
    DeviceSample out;
    EXPECT_FALSE(h.at(0.0, out));  // nothing yet
    h.push(1.0, sampleAt(10, 0));
    h.push(2.0, sampleAt(20, 1));
    h.push(3.0, sampleAt(30, 1));
    ASSERT_TRUE(h.at(1.25, out));
    EXPECT_NEAR(out.position.x(), 12.5, 1e-12);
    EXPECT_NEAR(out.position.z(), 37.5, 1e-12);
    EXPECT_EQ(out.buttons, 0u);  // the buttons of the sample before: pressed only from t = 2
    ASSERT_TRUE(h.at(2.0, out));
    EXPECT_EQ(out.buttons, 1u);
    EXPECT_NEAR(out.position.y(), 40, 1e-12);
    ASSERT_TRUE(h.at(9.0, out));  // after the newest: the newest
    EXPECT_NEAR(out.position.x(), 30, 1e-12);
    ASSERT_TRUE(h.at(0.0, out));  // before the oldest: the oldest
    EXPECT_NEAR(out.position.x(), 10, 1e-12);
}

TEST(CursorHistory, KeepsTheLatestSamplesWhenItWrapsAround) {
    CursorHistory h;
    const auto n = static_cast<int>(3 * CursorHistory::kSlots + 7);
    for (int i = 0; i < n; ++i) h.push(i, sampleAt(i, static_cast<std::uint32_t>(i % 2)));
    DeviceSample out;
    ASSERT_TRUE(h.at(n - 10.5, out));
    EXPECT_NEAR(out.position.x(), n - 10.5, 1e-9);
    EXPECT_EQ(out.buttons, static_cast<std::uint32_t>((n - 11) % 2));
    ASSERT_TRUE(h.at(0, out));  // long gone: the oldest kept
    EXPECT_NEAR(out.position.x(), n - static_cast<double>(CursorHistory::kSlots - 1), 1e-9);
}

TEST(CursorHistory, AReaderBesideTheWriterNeverSeesATornSample) {
    // The haptic thread pushes while the simulation's reads: every read is a sample the writer
    // wrote or lies between two (x, 2x, 3x stays on its line, with the earlier one's buttons),
    // never half of one. TSan checks the rest.
    CursorHistory h;
    std::atomic<bool> done{false};
    std::atomic<int> bad{0}, reads{0};
    std::thread reader([&] {
        DeviceSample out;
        double t = 0;
        while (!done.load()) {
            if (h.at(t, out)) {
                reads.fetch_add(1);
                const Vec3 p = out.position;
                if (std::abs(p.y() - 2 * p.x()) > 1e-6 * (1 + std::abs(p.x())) || std::abs(p.z() - 3 * p.x()) > 1e-6 * (1 + std::abs(p.x())))
                    bad.fetch_add(1);
                // the buttons of the sample at or before t, whose index is floor(x)
                if (out.buttons != (static_cast<long>(std::floor(p.x())) % 3 == 0 ? 1u : 0u)) bad.fetch_add(1);
            }
            t += 3.7;
        }
    });
    for (int i = 0; i < 200000 || reads.load() < 10000; ++i) h.push(i, sampleAt(i, i % 3 == 0 ? 1u : 0u));
    done.store(true);
    reader.join();
    EXPECT_EQ(bad.load(), 0);
    EXPECT_GT(reads.load(), 0);
}

TEST(MultirateReplay, StatesReachTheHapticLoopWhenTheirStepAndLatencyAreOver) {
    auto device = ropeStroke(0.5);
    auto a = scene(24);
    const MultirateTicks now = replayMultirate(*a, *device, 0.5, MultirateSettings{});
    for (size_t i = 2; i < now.t.size(); ++i) EXPECT_NEAR(now.stateTime[i], now.t[i], 1e-9) << i;  // cost 0: every tick's own state
    MultirateSettings late;
    late.latency = 0.004;
    auto b = scene(24);
    const MultirateTicks behind = replayMultirate(*b, *device, 0.5, late);
    for (size_t i = 10; i < behind.t.size(); ++i) EXPECT_NEAR(behind.stateTime[i], behind.t[i] - 0.004, 1e-9) << i;
    // the same states, later: the estimate bridges 4 ms from a state with its velocity
    EXPECT_LT(forceErrorP99(behind, now, 0.1, 0.3), 0.05);
    MultirateSettings bad;
    bad.stepCost = -1;
    EXPECT_THROW(replayMultirate(*a, *device, 0.5, bad), std::invalid_argument);
}

// Passivity with a lagging simulation (issue 49): over a stroke that pulls the hand up and down
// three times, the work the rendered force does on the hand (a zero-order hold: each tick's force
// over the hand's move to the next tick) never adds up above zero, whether the simulation keeps
// pace, falls behind and drops its backlog (a step costing 3 or 20 times its simulated time) or
// its states arrive 50 ms late. A force estimated from stale states that led the hand instead of
// lagging it would give energy back and fail this.
TEST(MultirateReplay, NoEnergyIsMadeWhenTheSimulationLags) {
    const double seconds = 1.5, pi = 3.14159265358979;
    const auto device = replayStroke(seconds, seconds - 0.2, [pi](double t) {
        const double tau = t > 0.1 ? t - 0.1 : 0.0;
        return Vec3(12.3 + 3 * std::sin(3 * pi * tau), -7.1, 6 * std::pow(std::sin(4 * pi * tau), 2));
    });
    struct Lag {
        double cost, latency;
    };
    for (const char* tool : {"rope", "magnet"})
        for (const Lag lag : {Lag{0, 0}, Lag{0.003, 0}, Lag{0.02, 0.02}, Lag{0, 0.05}}) {
            auto surface = scene(32);
            surface->setTool(tool);
            MultirateSettings s;
            s.stepCost = lag.cost;
            s.latency = lag.latency;
            const MultirateTicks run = replayMultirate(*surface, *device, seconds, s);
            double work = 0, most = 0, moved = 0;
            for (Eigen::Index k = 0; k + 1 < run.cursor.rows(); ++k) {
                const double dw = run.force.row(k).dot(run.cursor.row(k + 1) - run.cursor.row(k));
                work += dw;
                moved += std::abs(dw);
                most = std::max(most, work);
            }
            const std::string what = std::string(tool) + ", step cost " + std::to_string(lag.cost) + " s, latency " +
                                     std::to_string(lag.latency) + " s";
            ASSERT_TRUE(run.force.allFinite()) << what;
            EXPECT_GT(moved, 1.0) << what << ": the force did work";  // (N mm: the stroke was felt)
            EXPECT_LE(most, 1e-9 * moved) << what << ": the device gave the hand energy";
            if (lag.cost > 0) {
                EXPECT_GT(run.droppedSimTime, 0.1) << what << ": the simulation fell behind";
            }
        }
}
