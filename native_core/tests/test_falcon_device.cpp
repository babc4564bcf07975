// The Falcon as a Device, against the emulated Falcon: homing, the tip tracked through the
// kinematics, a spring rendered in a closed loop with the device's mass and damping, a rope
// stroke in a threaded session, a lost link, a noisy stream; no allocation per tick.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <thread>

#include "device_session.hpp"
#include "solvers/dynamic_surface.hpp"
#include "devices/falcon/falcon_device.hpp"
#include "falcon_emulator.hpp"
#include "runtime/haptic_runtime.hpp"

using namespace hs;

namespace {
std::shared_ptr<falcon::Emulator> emulator() {
    auto e = std::make_shared<falcon::Emulator>();
    e->homingFrames = 5;
    return e;
}
}  // namespace

TEST(FalconDevice, HomesThenTracksTheGrip) {
    auto e = emulator();
    e->hand = [](double t) { return falcon::Vec3d(0.02 * std::sin(t), 0.01, 0.11 - 0.01 * t); };
    e->buttons = [](double t) { return std::uint8_t(t > 0.5 ? 1 : 0); };
    FalconDevice dev(e, {});
    dev.start();
    EXPECT_TRUE(e->last.homing);  // (homed: the next frame says so)
    DeviceSample s;
    for (int k = 0; k < 1500; ++k) {
        ASSERT_TRUE(dev.sample(k * 1e-3, s));
        dev.setForce(Vec3::Zero());
    }
    ASSERT_TRUE(s.valid);
    EXPECT_TRUE(e->last.leds & falcon::kGreenLed);
    EXPECT_FALSE(e->last.homing);
    // the document's x, z, -y are the grip's right, up, towards the user; to the counts' resolution
    const falcon::Vec3d tip = e->tip;
    EXPECT_NEAR(s.position.x(), 1000 * tip.x(), 0.3);
    EXPECT_NEAR(s.position.z(), 1000 * tip.y(), 0.3);
    EXPECT_NEAR(s.position.y(), -1000 * (tip.z() - 0.11), 0.3);
    EXPECT_EQ(s.buttons, 1u);
    EXPECT_EQ(dev.missed(), 0u);
}

TEST(FalconDevice, AHomingThatNeverEndsSaysWhatToDo) {
    auto e = emulator();
    e->homingFrames = 1000000;
    FalconSettings settings;
    settings.homingTimeout = 0.05;
    FalconDevice dev(e, settings);
    try {
        dev.start();
        FAIL() << "no error";
    } catch (const std::runtime_error& ex) {
        EXPECT_NE(std::string(ex.what()).find("move the grip"), std::string::npos) << ex.what();
    }
}

TEST(FalconDevice, ASpringRenderedInAClosedLoopHoldsTheGrip) {
    // The hand pulls 20 mm up through a 300 N/m spring; a rendered 400 N/m spring towards the
    // middle holds it at the two springs' balance (300/700 of the way), through the kinematics'
    // torques and the emulated mass and damping, without oscillating away.
    auto e = emulator();
    e->hand = [](double) { return falcon::Vec3d(0, 0.02, 0.11); };
    FalconDevice dev(e, {});
    dev.start();
    DeviceSample s;
    double settled = 0, energyLate = 0;
    for (int k = 0; k < 3000; ++k) {
        ASSERT_TRUE(dev.sample(k * 1e-3, s));
        const Vec3 f = -400.0 * s.position;  // mN/mm (the session's units) = 400 N/m towards the middle
        dev.setForce(f);
        if (k > 2500) {
            settled = std::max(settled, std::abs(s.position.z() - 20.0 * 300 / 700));
            energyLate = std::max(energyLate, 0.5 * e->mass * e->velocity.squaredNorm());
        }
    }
    EXPECT_LT(settled, 0.3);  // mm
    EXPECT_LT(energyLate, 1e-6);  // J: at rest
    EXPECT_GT(e->largestForce, 3.0);  // N: the motors did the holding
}

TEST(FalconDevice, ATickDoesNotAllocate) {
    auto e = emulator();
    FalconDevice dev(e, {});
    dev.start();
    DeviceSample s;
    dev.sample(0, s);
    const long before = allocationCount();
    for (int k = 0; k < 200; ++k) {
        dev.sample(k * 1e-3, s);
        dev.setForce(Vec3(0.5, -1, 2));
    }
    EXPECT_EQ(allocationCount() - before, 0);
}

TEST(FalconDevice, NoiseAndSplitReadsAreSkipped) {
    auto e = emulator();
    e->noiseEvery = 7;
    e->readChunk = 5;
    e->hand = [](double) { return falcon::Vec3d(0.01, 0, 0.11); };
    FalconDevice dev(e, {});
    dev.start();
    DeviceSample s;
    for (int k = 0; k < 600; ++k) {
        ASSERT_TRUE(dev.sample(k * 1e-3, s));
        dev.setForce(Vec3::Zero());
    }
    EXPECT_GT(dev.skippedBytes(), 100u);
    EXPECT_NEAR(s.position.x(), 1000 * e->tip.x(), 0.5);
}

TEST(FalconDevice, ARopeStrokeInAThreadedSessionAndALostLink) {
    auto surface = std::make_shared<DynamicSurface>(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 24, 24);
    auto e = emulator();
    // the hand takes the grip 20 mm up over 0.6 s with the button held, then lets go
    e->hand = [](double t) { return falcon::Vec3d(0, 0.02 * std::min(1.0, t / 0.6), 0.11); };
    e->buttons = [](double t) { return std::uint8_t(t < 0.8 ? 1 : 0); };
    e->loseAfter = 1400;  // then the link dies
    const SessionOutcome out = sessionUntilItStops(std::make_shared<FalconDevice>(e, FalconSettings{}));
    expectLostAfterAStroke(out);
    EXPECT_GT(e->largestForce, 0.05);                 // and pulled the grip back: force out
}
