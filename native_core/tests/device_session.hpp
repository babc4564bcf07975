// What the device tests share: the allocation counter (test_core.cpp), whether a sanitizer slows
// the loops, the message of an error, and the scenario every device family plays at its transport: a hand takes the grip
// up 20 mm with the button held, lets go, then the link dies; the session must stop by itself
// with "device lost", its force off, the one stroke kept and the surface pulled up.
#pragma once
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "devices/device.hpp"
#include "runtime/haptic_runtime.hpp"
#include "solvers/dynamic_surface.hpp"

long allocationCount();  // test_core.cpp

// Sanitizers slow the loops several-fold: the simulation then drops backlog and simulates less of
// the pull (seen under ASan on a loaded machine: 0.35 mm), which must still lift the surface.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitized = true;
#else
inline constexpr bool kSanitized = false;
#endif

/// Waits until `done` holds (polling every millisecond), at most `seconds`; returns whether it held.
/// The loops run slowly under sanitizers and on a loaded machine, so the tests wait for what they
/// need (a grab, a count of steps, a force) instead of sleeping a fixed time.
template <class Condition>
bool waitFor(Condition done, double seconds = 30.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
        if (std::chrono::steady_clock::now() > end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return true;
}

/// The message of what `f` throws ("" if it throws nothing).
inline std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

/// A session's end as the tests read it.
struct SessionOutcome {
    hs::RuntimeStatus status;
    hs::StrokeSnapshot stroke;
    hs::RuntimeSettings used;  ///< the settings the runtime ran with (the device's limits filled in)
};

/// Runs a session of `device` over a 100 mm patch until it stops by itself (30 s at most).
inline SessionOutcome sessionUntilItStops(const std::shared_ptr<hs::Device>& device,
                                          const hs::RuntimeSettings& settings = {}) {
    auto surface = std::make_shared<hs::DynamicSurface>(hs::BSplineSurface::plane(8, 8, 3, 3, 100, 100), 24, 24);
    hs::HapticRuntime rt(surface, device, settings);
    rt.start();
    SessionOutcome out;
    out.used = rt.settings();
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (rt.running() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    rt.stop();
    rt.takeStroke(out.stroke);
    out.status = rt.status();
    return out;
}

/// The "device lost" scenario's outcome: stopped by itself, force off, one stroke that lifted the patch.
inline void expectLostAfterAStroke(const SessionOutcome& out) {
    EXPECT_EQ(out.status.error, "device lost");
    EXPECT_EQ(out.status.force.norm(), 0.0);
    EXPECT_EQ(out.status.strokes, 1u);
    ASSERT_GT(out.stroke.poles.rows(), 0);
    EXPECT_GT(out.stroke.poles.col(2).maxCoeff(), kSanitized ? 0.05 : 0.5);  // the surface was pulled up
}
