// A rope pulled slowly up from `start` for 50 steps of `dt` (after two steps to warm up), as
// the no-allocation tests of the stepping hot path drive it: the allocations those 50 made.
#pragma once
#include "solvers/dynamic_surface.hpp"

long allocationCount();  // test_core.cpp

inline long allocationsWhilePulling(hs::DynamicSurface& s, double dt, const hs::Vec3& start = hs::Vec3::Zero()) {
    hs::Cursor c;
    c.position = start;
    c.grab = true;
    s.setCursor(c);
    s.step(dt);
    s.step(dt);
    const long before = allocationCount();
    for (int k = 0; k < 50; ++k) {
        c.position.z() += 0.05;
        s.setCursor(c);
        s.step(dt);
    }
    return allocationCount() - before;
}
