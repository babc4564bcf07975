// The threaded runtime: lock-free exchange, the haptic estimate against the core's own tool
// reactions, loop life cycle (finish, device loss, zero force at exit), allocation-free loops.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "device_session.hpp"
#include "solvers/dynamic_surface.hpp"
#include "devices/external_device.hpp"
#include "runtime/haptic_runtime.hpp"
#include "devices/replay_device.hpp"
#include "common/triple_buffer.hpp"

// (Sanitizers slow the loops several-fold: there the tests check behaviour and races, not rates.)
using namespace hs;

namespace {
std::shared_ptr<DynamicSurface> patch(int controls = 8, int mesh = 24) {
    return std::make_shared<DynamicSurface>(BSplineSurface::plane(controls, controls, 3, 3, 100, 100), mesh, mesh);
}

// A replayed device whose cursor follows path(s), s from 0 to 1 over `seconds`, with the button
// held (released on the last sample if releaseAtEnd).
template <class Path>
std::shared_ptr<ReplayDevice> replay(double seconds, int n, bool releaseAtEnd, Path path) {
    std::vector<double> t(static_cast<size_t>(n));
    Points xyz(n, 3);
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q(n, 4);
    std::vector<std::uint32_t> buttons(static_cast<size_t>(n), 1);
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        t[static_cast<size_t>(i)] = seconds * s;
        xyz.row(i) = path(s).transpose();
        q.row(i) << 1, 0, 0, 0;
    }
    if (releaseAtEnd) buttons.back() = 0;
    return std::make_shared<ReplayDevice>(t, xyz, q, buttons);
}

std::shared_ptr<ReplayDevice> lift(double seconds, double height, bool releaseAtEnd = true) {
    return replay(seconds, 50, releaseAtEnd, [height](double s) { return Vec3(0, 0, height * std::sin(3.14159 * 0.5 * s)); });
}

// Records the last force it was asked to render, from any thread.
class RecordingDevice final : public Device {
public:
    std::string name() const override { return "recording"; }
    DeviceCaps caps() const override { return {3, true, 1000, 50.0, 40.0}; }
    bool sample(double t, DeviceSample& out) override {
        out.position = Vec3(0, 0, 20.0 * std::min(1.0, t));
        out.buttons = 1;
        out.valid = true;
        return !lost.load();
    }
    void setForce(const Vec3& f) override {
        last.store(f.norm());
        if (f.norm() > 0) nonZero.store(true);
        if (watching.load()) least.store(std::min(least.load(), f.norm()));
    }
    std::atomic<bool> lost{false}, nonZero{false};
    std::atomic<bool> watching{false};  // while set, `least` keeps the smallest force rendered
    std::atomic<double> last{-1}, least{std::numeric_limits<double>::infinity()};
};

// A broken device: every other sample holds NaN, Inf or a zero quaternion, the rest grab and lift.
class GarbageDevice final : public Device {
public:
    std::string name() const override { return "garbage"; }
    DeviceCaps caps() const override { return {6, true, 1000, 50.0, 40.0}; }
    bool sample(double t, DeviceSample& out) override {
        const long n = count++;
        out.position = Vec3(0, 0, 20.0 * std::min(1.0, t));
        out.orientation = Eigen::Quaterniond::Identity();
        switch (n % 8) {
            case 1: out.position.x() = std::numeric_limits<double>::quiet_NaN(); break;
            case 3: out.position.z() = std::numeric_limits<double>::infinity(); break;
            case 5: out.orientation = Eigen::Quaterniond(0, 0, 0, 0); break;
            case 7: out.orientation.w() = std::numeric_limits<double>::quiet_NaN(); break;
            default: break;
        }
        out.buttons = 1;
        out.valid = true;
        return true;
    }
    void setForce(const Vec3& f) override {
        if (!f.allFinite()) nonFinite = true;
    }
    std::atomic<long> count{0};
    std::atomic<bool> nonFinite{false};
};
}  // namespace

TEST(TripleBuffer, ReaderAlwaysSeesAWholeNewestValue) {
    struct Pair { long a = 0, b = 0; };
    TripleBuffer<Pair> buffer;
    std::atomic<bool> done{false};
    std::thread writer([&] {
        for (long i = 1; i <= 200000; ++i) buffer.write({i, -i});
        done = true;
    });
    long last = 0;
    while (!done || buffer.update()) {
        buffer.update();
        const Pair& p = buffer.front();
        ASSERT_EQ(p.a, -p.b);
        ASSERT_GE(p.a, last);
        last = p.a;
    }
    writer.join();
    buffer.update();
    EXPECT_EQ(buffer.front().a, 200000);
}

TEST(HapticEstimate, ReproducesTheToolReactionAtTheSnapshot) {
    // Every tool with a local law (the smooth brush has none: it holds its last reaction); the rope
    // twice: on springs alone, and on a plate, where it pulls kRopePlateGain x 10 harder.
    std::vector<std::string> tools = toolNames();
    tools.push_back("rope on a plate");
    for (const std::string& tool : tools) {
        if (tool == "smooth") continue;
        auto s = patch();
        if (tool == "rope on a plate") s->bendingMap().setUniform(10.0);
        s->setTool(tool.substr(0, tool.find(' ')));
        for (int i = 0; i < s->tool().info().parameterCount(); ++i)
            if (std::string(s->tool().info().parameters[i].name) == "radius") s->tool().setParameter(i, 20);
        Cursor c;
        c.position = Vec3(1, 2, 0.5);
        c.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitZ()));
        c.grab = true;
        s->setCursor(c);
        StepReport r;
        for (int k = 0; k < 30; ++k) {
            c.position.z() += 0.4;
            s->setCursor(c);
            r = s->step(1e-3);
        }
        HapticEstimate e;
        s->describeTool(r.reaction, e);
        e.time = 0.03;
        // The reaction the core reports used the tool's clock before this step's advance; the estimate
        // evaluated at its own clock with the cursor of the step must match it exactly up to that.
        const Vec3 f = estimateForce(e, c.position, c.orientation, e.time);
        EXPECT_TRUE(f.allFinite()) << tool;
        EXPECT_GT(f.norm(), 0) << tool;
        // (the reaction was taken where the step predicted the mesh, the estimate where it ended:
        // the rope on a plate is 4x stiffer, so that gap weighs more at this 400 mm/s pull)
        EXPECT_NEAR((f - r.reaction.force).norm() / r.reaction.force.norm(), 0.0,
                    tool == "rope on a plate" ? 0.05 : 0.03) << tool;
        if (tool == "rope on a plate") {
            EXPECT_DOUBLE_EQ(s->tool().read("gain"), 1 + 10 * kRopePlateGain);
        }
    }
}

TEST(HapticRuntime, ReplayRunsToTheEndAndCommitsTheStroke) {
    auto s = patch();
    RuntimeSettings settings;
    settings.stopWhenFinished = true;
    settings.logSeconds = 2;
    HapticRuntime rt(s, lift(0.6, 20.0), settings);
    rt.start();
    EXPECT_TRUE(waitFor([&] { return !rt.running(); }));  // the replay's end stops it
    rt.stop();
    const RuntimeStatus st = rt.status();
    EXPECT_EQ(st.error, "");
    if (!kSanitized) {
        EXPECT_GT(st.hapticTicks, 500u);
        // The simulation covered the 0.6 s pull in simulated time, as the runtime promises however
        // loaded the machine: behind real time it takes steps of twice simDt, past maxLag it drops
        // the backlog (on a machine running make test's other lanes: 978 steps, some doubled).
        const double simulated = static_cast<double>(st.simSteps + st.doubledSteps) * settings.simDt + st.droppedSimTime;
        EXPECT_GT(simulated, 0.5) << st.simSteps << " steps, " << st.doubledSteps << " doubled";
    }
    EXPECT_EQ(st.strokes, 1u);
    StrokeSnapshot stroke;
    ASSERT_TRUE(rt.takeStroke(stroke));
    // Under a sanitizer on a loaded machine the simulation drops backlog and simulates less of the
    // 0.6 s pull (seen: 2.95 mm under ASan while another FreeCAD GUI test ran); it must still lift.
    EXPECT_GT(stroke.poles.col(2).maxCoeff(), kSanitized ? 0.5 : 5.0);
    EXPECT_FALSE(rt.takeStroke(stroke));
    EXPECT_EQ(st.force.norm(), 0.0);  // zero at exit
    const auto errors = rt.forceErrors();
    ASSERT_GT(errors.size(), 100u);
    // The estimate's accuracy: the median holds on any machine; the tail (p99) only while the
    // simulation kept pace with steps of simDt in all but 1 % of them (a loaded machine makes it
    // drop backlog, and the estimate then extrapolates across it, or keep pace by steps of twice
    // simDt, whose rope force differs from simDt's: bench/haptic_force.py. Seen under Wine with the
    // other lanes running: 6.2 %, no drop; Wine beside two builds doubled 1 to 8 of about 600).
    std::vector<double> sorted = errors;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2], p99 = sorted[sorted.size() * 99 / 100];
    if (!kSanitized) {
        EXPECT_LT(median, 0.01);
        if (st.droppedSimTime == 0 && 100 * st.doubledSteps <= st.simSteps) {
            EXPECT_LT(p99, 0.05) << st.simSteps << " steps";
        }
    }
}

TEST(HapticRuntime, DeviceLossStopsWithZeroForceAndAClamp) {
    auto s = patch();
    auto dev = std::make_shared<RecordingDevice>();
    s->setTool("rope");
    s->tool().set("stiff_stiffness", 1000);  // steeper than the device's 40
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    ASSERT_TRUE(waitFor([&] { return dev->nonZero.load(); }));  // the rope pulls back
    EXPECT_TRUE(rt.running());
    EXPECT_LE(rt.status().force.norm(), 50.0 + 1e-9);  // the device's maximum
    dev->lost = true;
    EXPECT_TRUE(waitFor([&] { return !rt.running(); }));
    rt.stop();
    EXPECT_EQ(rt.status().error, "device lost");
    EXPECT_EQ(dev->last.load(), 0.0);
}

TEST(HapticRuntime, NonFiniteDeviceInputNeverReachesTheSurfaceOrTheForce) {
    auto s = patch();
    auto dev = std::make_shared<GarbageDevice>();
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    // until the valid samples have lifted the grabbed mesh point (the contact: read race-free)
    EXPECT_TRUE(waitFor([&] {
        const RuntimeStatus now = rt.status();
        return dev->count.load() > 100 && now.contactValid && now.contact.z() > 0.02;
    }));
    const RuntimeStatus st = rt.status();
    rt.stop();
    EXPECT_FALSE(dev->nonFinite.load());
    EXPECT_TRUE(st.force.allFinite());
    EXPECT_TRUE(s->poles().allFinite());
    EXPECT_TRUE(s->velocities().allFinite());
    EXPECT_GT(s->poles().col(2).maxCoeff(), 0.01);  // the valid samples still lifted the surface
}

TEST(HapticRuntime, StatusShowsTheCursorAndTheRopeContactForTheOverlay) {
    auto s = patch();
    auto dev = std::make_shared<RecordingDevice>();
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    EXPECT_TRUE(waitFor([&] {
        const RuntimeStatus now = rt.status();
        return now.grab && now.contactValid && now.cursor.z() > 1.0;
    }));
    const RuntimeStatus st = rt.status();
    rt.stop();
    EXPECT_TRUE(st.grab);
    EXPECT_GT(st.cursor.z(), 1.0);  // the device lifts the cursor 20 mm/s
    EXPECT_NEAR(st.cursor.x(), 0.0, 1e-12);
    ASSERT_TRUE(st.contactValid);   // the rope holds a mesh point
    EXPECT_LT(st.contact.z(), st.cursor.z());
    EXPECT_LT(std::abs(st.contact.x()) + std::abs(st.contact.y()), 10.0);  // the point under the cursor
}

TEST(HapticRuntime, AirbrushSpraysAlongTheCursorAsOneStrokeAndRendersNoForce) {
    auto s = patch();
    RuntimeSettings settings;
    settings.stopWhenFinished = true;
    // The cursor sweeps along x over the patch with the button held, then lets go.
    HapticRuntime rt(s, replay(0.5, 40, true, [](double u) { return Vec3(-30.0 + 60.0 * u, 0, 1.0); }), settings);
    AirbrushSettings a;
    a.map = AirbrushSettings::Map::Stiffness;
    a.factor = 4.0;
    a.rate = 100;
    rt.setAirbrush(a);
    rt.start();
    EXPECT_TRUE(waitFor([&] { return !rt.running(); }));  // the replay's end stops it
    rt.stop();
    const RuntimeStatus st = rt.status();
    EXPECT_EQ(st.error, "");
    EXPECT_EQ(st.strokes, 1u);  // one spray, no grab
    StrokeSnapshot stroke;
    ASSERT_TRUE(rt.takeStroke(stroke));
    EXPECT_FALSE(rt.takeStroke(stroke));
    ASSERT_EQ(stroke.painted, AirbrushSettings::Map::Stiffness);
    PaintedMap shown;  // what the GUI showed during the spray
    ASSERT_TRUE(rt.takePaintedMap(shown));
    EXPECT_EQ(shown.map, AirbrushSettings::Map::Stiffness);
    EXPECT_EQ(shown.values.size(), shown.rows * shown.cols);
    EXPECT_GT(shown.values.maxCoeff(), 150.0);
    const MaterialMap& m = s->stiffnessMap();
    ASSERT_FALSE(m.uniform());
    ASSERT_EQ(stroke.maps[2].values.size(), m.values().size());
    EXPECT_EQ((stroke.maps[2].values - m.values()).cwiseAbs().maxCoeff(), 0.0);
    // Stiffer along the path (v = 0.5, u from 0.2 to 0.8), untouched far from it, never past the target.
    EXPECT_GT(m.at(0.5, 0.5), 150.0);
    EXPECT_GT(m.at(0.3, 0.5), 150.0);
    EXPECT_GT(m.at(0.7, 0.5), 150.0);
    EXPECT_NEAR(m.at(0.5, 0.05), 100.0, 1e-9);
    EXPECT_LE(m.values().maxCoeff(), 400.0 + 1e-9);
    // The tool never grabbed: no force, and the patch stayed flat.
    EXPECT_EQ(st.force.norm(), 0.0);
    EXPECT_LT(s->poles().col(2).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(HapticRuntime, SwitchingTheAirbrushOnMidGrabReleasesTheTool) {
    auto s = patch();
    auto dev = std::make_shared<RecordingDevice>();  // holds the button and lifts
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    // the rope holds a mesh point (read through status: race-free)
    EXPECT_TRUE(waitFor([&] { return rt.status().contactValid; }));
    AirbrushSettings a;
    a.map = AirbrushSettings::Map::Mass;
    rt.setAirbrush(a);
    ASSERT_TRUE(waitFor([&] { return rt.status().spraying; }));
    const std::uint64_t spraySteps = rt.status().simSteps;
    EXPECT_TRUE(waitFor([&] { return rt.status().simSteps > spraySteps + 50; }));  // some spraying done
    const RuntimeStatus st = rt.status();
    rt.stop();
    EXPECT_TRUE(st.spraying);
    StrokeSnapshot stroke;
    ASSERT_TRUE(rt.takeStroke(stroke));  // the grab's end
    EXPECT_EQ(stroke.painted, AirbrushSettings::Map::Off);
    ASSERT_TRUE(rt.takeStroke(stroke));  // the spray, ended by the stop
    EXPECT_EQ(stroke.painted, AirbrushSettings::Map::Mass);
    EXPECT_FALSE(s->massMap().uniform());
    EXPECT_THROW(rt.setAirbrush(AirbrushSettings{AirbrushSettings::Map::Mass, 0.0}), std::invalid_argument);
    EXPECT_THROW(rt.setAirbrush(AirbrushSettings{AirbrushSettings::Map::Mass, 0.1, 3.0, 0.25, 0.0}), std::invalid_argument);
}

namespace {
bool takeEvent(HapticRuntime& rt, StrokeSnapshot& out) {
    return waitFor([&] { return rt.takeStroke(out); });
}
}  // namespace

TEST(HapticRuntime, EditsReachARunningSessionWithoutLettingGoOfTheTool) {
    auto s = patch();
    auto dev = std::make_shared<RecordingDevice>();
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    ASSERT_TRUE(waitFor([&] { return dev->last.load() > 2.0 && rt.status().cursor.z() > 15.0; })) << "the rope never pulled";
    const double held = dev->last.load();
    dev->watching = true;
    // A stiffer material, configured off the simulation thread, swapped in between two steps.
    auto stiffer = patch();
    stiffer->stiffnessMap().setUniform(300.0);
    stiffer->setTool("rope");
    rt.postEdit({7, stiffer, false, false, false});  // (its maps are the edit: not the live ones)
    StrokeSnapshot e;
    ASSERT_TRUE(takeEvent(rt, e));
    EXPECT_EQ(e.edit, 7u);
    EXPECT_EQ(e.maps[2].values.size(), 1);
    EXPECT_EQ(e.maps[2].values[0], 300.0);
    EXPECT_GT(e.poles.col(2).maxCoeff(), 1.0);  // the pulled shape, not the new surface's flat one
    // Keep shape: the pulled shape becomes the rest shape, still holding.
    rt.postEdit({8, nullptr, false, true, true});
    ASSERT_TRUE(takeEvent(rt, e));
    EXPECT_EQ(e.edit, 8u);
    const RuntimeStatus during = rt.status();
    dev->watching = false;
    // A restore (undo) takes its surface as it is: flat and at rest, the rope grabbing anew.
    auto flat = patch();
    rt.postEdit({9, flat, true, false, false});
    ASSERT_TRUE(takeEvent(rt, e));
    EXPECT_EQ(e.edit, 9u);
    EXPECT_EQ(e.poles.col(2).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(e.velocities.cwiseAbs().maxCoeff(), 0.0);
    rt.stop();
    EXPECT_TRUE(during.grab);
    EXPECT_EQ(during.error, "");
    EXPECT_EQ(during.strokes, 0u);  // no edit let go of the rope
    // The force never dropped out over the edits (it eases with the softer rest shape, never to zero).
    // (Under a sanitizer the simulation can fall past the watchdog's limit while edits are factored,
    // and the safety layer then fades the force, as it should: there only the behaviour is checked.)
    if (!kSanitized) {
        EXPECT_GT(dev->least.load(), 0.05 * held) << "held " << held;
    }
    RecordProperty("held_force", std::to_string(held));
    RecordProperty("least_force_over_edits", std::to_string(dev->least.load()));
    EXPECT_EQ(rt.surface(), flat);
    EXPECT_EQ(stiffer->stiffnessMap().values()[0], 300.0);
    // The keep-shape edit made the pulled mesh the rest shape of the surface it then stepped.
    EXPECT_NE(stiffer->springs().rest(), stiffer->springs().initialRest());
}

TEST(HapticRuntime, EditsPostedFromTwoThreadsWhileTheHapticLoopReadsAllApplyOnceInOrder) {
    // Two threads post edits (material changes and keep-shape) as fast as they can while the rope
    // is held and the haptic thread renders; the main thread collects the events meanwhile. Every
    // edit applies exactly once, each thread's in the order it posted them, and the force stays
    // finite and on. (Under TSan this is the queue's race test.)
    auto s = patch();
    auto dev = std::make_shared<RecordingDevice>();
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    ASSERT_TRUE(waitFor([&] { return dev->last.load() > 2.0; })) << "the rope never pulled";
    dev->watching = true;
    constexpr int kPerThread = 20;
    auto poster = [&rt](std::uint64_t first) {
        for (int i = 0; i < kPerThread; ++i) {
            const std::uint64_t id = first + static_cast<std::uint64_t>(i);
            if (i % 3 == 2) {
                rt.postEdit({id, nullptr, false, true, true});  // keep shape
                continue;
            }
            auto next = patch();
            next->stiffnessMap().setUniform(100.0 + static_cast<double>(id));
            next->setTool("rope");
            rt.postEdit({id, next, false, false, false});
        }
    };
    std::thread a(poster, 1000), b(poster, 2000);
    std::vector<std::uint64_t> seen;
    StrokeSnapshot e;
    const bool all = waitFor([&] {
        while (rt.takeStroke(e))
            if (e.edit != 0) seen.push_back(e.edit);
        return seen.size() >= 2 * kPerThread;
    });
    a.join();
    b.join();
    dev->watching = false;
    const RuntimeStatus status = rt.status();
    rt.stop();
    ASSERT_TRUE(all) << "only " << seen.size() << " of " << 2 * kPerThread << " edits came back";
    std::vector<std::uint64_t> fromA, fromB;
    for (std::uint64_t id : seen) (id < 2000 ? fromA : fromB).push_back(id);
    ASSERT_EQ(fromA.size(), static_cast<size_t>(kPerThread));
    ASSERT_EQ(fromB.size(), static_cast<size_t>(kPerThread));
    for (int i = 0; i < kPerThread; ++i) {
        EXPECT_EQ(fromA[static_cast<size_t>(i)], 1000u + static_cast<std::uint64_t>(i));
        EXPECT_EQ(fromB[static_cast<size_t>(i)], 2000u + static_cast<std::uint64_t>(i));
    }
    EXPECT_EQ(status.error, "");
    EXPECT_TRUE(status.grab);
    EXPECT_TRUE(std::isfinite(dev->least.load()));
    // (Under a sanitizer the two posting threads, each factoring surfaces, can starve the simulation
    // past the watchdog's limit, and the safety layer then fades the force out, as it should.)
    if (!kSanitized) {
        EXPECT_GT(dev->least.load(), 0.0) << "the force dropped out during the edits";
    }
}

TEST(HapticRuntime, RefusesEditsThatCannotApply) {
    auto s = patch();
    HapticRuntime rt(s, std::make_shared<RecordingDevice>(), RuntimeSettings{});
    EXPECT_THROW(rt.postEdit({0, patch(), false, true, false}), std::invalid_argument);  // no id
    EXPECT_THROW(rt.postEdit({1, s, false, true, false}), std::invalid_argument);        // the live surface itself
    EXPECT_THROW(rt.postEdit({2, patch(8, 16), false, true, false}), std::invalid_argument);  // another sampling
    EXPECT_THROW(rt.postEdit({3, patch(6, 24), false, true, false}), std::invalid_argument);  // another control net
}

TEST(HapticEstimate, SafetyLayerFadesStaleSnapshotsLimitsStiffnessAndClamps) {
    HapticEstimate e;
    e.kind = EstimateKind::Hold;
    e.time = 1.0;
    e.slope = 10;
    const Vec3 f(3, 0, 0);
    ForceLimits limits{100, 100, 0.01, 0.02};
    EXPECT_EQ(limitForce(e, f, 1.005, limits), f);                              // fresh
    EXPECT_NEAR(limitForce(e, f, 1.02, limits).x(), 1.5, 1e-12);                // half faded
    EXPECT_EQ(limitForce(e, f, 1.05, limits), Vec3::Zero());                    // fully faded
    limits.maxStiffness = 5;                                                    // law twice too steep
    EXPECT_NEAR(limitForce(e, f, 1.0, limits).x(), 1.5, 1e-12);
    limits.maxForce = 1;
    EXPECT_NEAR(limitForce(e, f, 1.0, limits).norm(), 1.0, 1e-12);
    EXPECT_EQ(limitForce(e, Vec3(NAN, 0, 0), 1.0, limits), Vec3::Zero());
}

TEST(HapticRuntime, LoopsDoNotAllocateOnceRunning) {
    auto s = patch(12, 40);
    RuntimeSettings settings;
    HapticRuntime rt(s, lift(3.0, 25.0, false), settings);
    rt.start();
    // past the grab and the first factorisation
    ASSERT_TRUE(waitFor([&] { return rt.status().contactValid && rt.status().simSteps > 20; }));
    const long before = allocationCount();
    const std::uint64_t stepsBefore = rt.status().simSteps;
    // a window that really covers stepping (sanitizers are slow: fewer steps there)
    const bool stepped = waitFor([&] { return rt.status().simSteps > stepsBefore + (kSanitized ? 50u : 500u); });
    const long after = allocationCount();
    rt.stop();
    EXPECT_TRUE(stepped);
    EXPECT_EQ(after - before, 0);
}

TEST(HapticRuntime, RefusesBadSettings) {
    auto s = patch();
    auto dev = std::make_shared<ExternalDevice>();
    RuntimeSettings bad;
    bad.hapticRate = 10000;
    EXPECT_THROW(HapticRuntime(s, dev, bad), std::invalid_argument);
    bad = RuntimeSettings{};
    bad.simDt = 0;
    EXPECT_THROW(HapticRuntime(s, dev, bad), std::invalid_argument);
    EXPECT_THROW(HapticRuntime(s, nullptr, RuntimeSettings{}), std::invalid_argument);
}

TEST(HapticRuntime, LatencyIsMeasuredAndTheTimingSettingsAreChecked) {
    auto s = patch();
    RuntimeSettings settings;
    settings.stopWhenFinished = true;
    settings.spin = 2e-4;   // spins the last 0.2 ms before each tick
    settings.simNice = 5;   // the simulation thread yields to the haptic one
    HapticRuntime rt(s, lift(0.3, 10.0), settings);
    rt.start();
    EXPECT_TRUE(waitFor([&] { return !rt.running(); }));
    rt.stop();
    const RuntimeStatus st = rt.status();
    EXPECT_EQ(st.error, "");
    EXPECT_GT(st.latencyP50, 0.0);
    EXPECT_GE(st.latencyP99, st.latencyP50);
    EXPECT_LT(st.latencyP50, 0.001);  // reading a replay and writing nowhere takes microseconds
    for (auto bad : {std::pair{-1e-6, 0}, std::pair{0.002, 0}, std::pair{0.0, -1}, std::pair{0.0, 20}}) {
        RuntimeSettings b;
        b.spin = bad.first;
        b.simNice = bad.second;
        EXPECT_THROW(HapticRuntime(patch(), lift(0.1, 1.0), b), std::invalid_argument);
    }
}

TEST(HapticRuntime, ASimulationBehindRealTimeCatchesUpWithDoubleSteps) {
    // 4,096 mass points at 10 µs steps (a step takes 150 µs in a release build): no machine keeps
    // real time, so the simulation is always behind; it takes steps of twice its length (prepared
    // before the clock starts) and stays stable and finite; with catch-up off it only drops
    // backlog. (Small enough that a sanitized build on a loaded machine still makes dozens of
    // steps in the stroke: at 128 x 128 it made a few, and once missed the grab altogether.)
    for (const bool catchUp : {true, false}) {
        auto s = std::make_shared<DynamicSurface>(BSplineSurface::plane(16, 16, 3, 3, 100, 100), 64, 64);
        RuntimeSettings settings;
        settings.simDt = 1e-5;
        settings.catchUp = catchUp;
        settings.stopWhenFinished = true;
        HapticRuntime rt(s, lift(0.6, 20.0), settings);
        rt.start();
        EXPECT_TRUE(waitFor([&] { return !rt.running(); }, 60.0));
        rt.stop();
        const RuntimeStatus st = rt.status();
        EXPECT_EQ(st.error, "") << catchUp;
        EXPECT_EQ(st.refusedSteps, 0u) << catchUp;
        EXPECT_TRUE(s->poles().allFinite()) << catchUp;
        if (catchUp) {  // (how many depends on the machine: under ASan a step takes tens of ms)
            EXPECT_GT(st.doubledSteps, 0u);
            EXPECT_LE(st.doubledSteps, st.simSteps);
        } else {
            EXPECT_EQ(st.doubledSteps, 0u);
        }
        EXPECT_GT(st.droppedSimTime, 0.0) << catchUp;  // (even doubled, it cannot keep up)
        StrokeSnapshot stroke;
        ASSERT_TRUE(rt.takeStroke(stroke)) << catchUp;
        // it still pulled (how far depends on how much time a sanitizer or a busy machine let it simulate)
        EXPECT_GT(st.simSteps, 5u) << catchUp;  // (ASan's debug build: about 30 in the stroke)
        EXPECT_GT(stroke.poles.col(2).maxCoeff(), 0.0) << catchUp;
    }
}

TEST(ExternalDevice, ABurstIsPassedOnInOrderAndAGrabHeldItsShortestTime) {
    // A GUI thread busy drawing delivers a whole drag at once: each sample is passed on in turn
    // (hovers merged into the newest), and the release only once the grab has lasted kShortestGrab.
    ExternalDevice dev;
    DeviceSample s;
    s.valid = true;
    for (double x : {1.0, 2.0, 3.0}) {  // hovers: only the newest counts
        s.position = Vec3(x, 0, 0);
        dev.push(s);
    }
    s.buttons = 1;
    for (double z : {0.0, 5.0, 10.0}) {
        s.position = Vec3(3, 0, z);
        dev.push(s);
    }
    s.buttons = 0;
    dev.push(s);
    DeviceSample out;
    std::vector<std::pair<double, std::uint32_t>> seen;
    double t = 1.0;
    for (int tick = 0; tick < 400; ++tick, t += 1e-3) {
        ASSERT_TRUE(dev.sample(t, out));
        if (seen.empty() || seen.back() != std::pair{out.position.z(), out.buttons}) seen.emplace_back(out.position.z(), out.buttons);
        if (tick == 0) {
            EXPECT_EQ(out.position.x(), 3.0);
        }
        if (tick >= 1 && tick < static_cast<int>(ExternalDevice::kShortestGrab / 1e-3)) {
            EXPECT_EQ(out.buttons, 1u) << tick;  // (from where the button went down, for the shortest grab)
        }
    }
    const std::vector<std::pair<double, std::uint32_t>> expected{{0.0, 0u}, {0.0, 1u}, {5.0, 1u}, {10.0, 1u}, {10.0, 0u}};
    EXPECT_EQ(seen, expected);
}

TEST(HapticRuntime, AWholeDragDeliveredInOneBurstIsStillAStroke) {
    // The same burst into a resting (idle) session: the device kept only the newest sample, the
    // release, and the stroke was lost (a mouse session under load on FreeCAD 1.1).
    auto s = patch(8, 24);
    auto dev = std::make_shared<ExternalDevice>();
    DeviceSample d;
    d.valid = true;
    d.position = Vec3(20, 0, 0);
    dev->push(d);
    HapticRuntime rt(s, dev, RuntimeSettings{});
    rt.start();
    ASSERT_TRUE(waitFor([&] {  // at rest: the simulation idles
        const auto steps = rt.status().simSteps;
        std::this_thread::sleep_for(std::chrono::milliseconds(60));
        return rt.status().simSteps == steps;
    }));
    d.buttons = 1;
    for (int i = 0; i <= 5; ++i) {
        d.position = Vec3(20, 0, 3.0 * i);
        dev->push(d);
    }
    d.buttons = 0;
    dev->push(d);
    StrokeSnapshot stroke;
    ASSERT_TRUE(waitFor([&] { return rt.takeStroke(stroke); }));
    rt.stop();
    EXPECT_EQ(rt.status().error, "");
    EXPECT_GT(stroke.poles.col(2).maxCoeff(), 0.5);
}
