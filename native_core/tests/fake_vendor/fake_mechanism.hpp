// The device behind the fake vendor libraries: a grip of mass m with the mechanism's damping,
// driven by the motors' force and by a hand holding it through a spring; the hand follows a
// scripted path (a replayed stroke) with its buttons. Device time advances by a fixed step per
// servo frame, so a run is deterministic. No allocation after the script is set.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace fake {

struct Waypoint {
    double t = 0, x = 0, y = 0, z = 0;  // s, m in the device's frame
    int buttons = 0;
};

struct Mechanism {
    double mass = 0.05, damping = 1.0;            // kg, N s/m
    double handStiffness = 300, handDamping = 3;  // N/m, N s/m
    double dt = 0.001;
    std::array<Waypoint, 64> script{};
    std::size_t scriptLength = 0;
    double time = 0, largestForce = 0;
    double tip[3] = {0, 0, 0}, velocity[3] = {0, 0, 0}, force[3] = {0, 0, 0};

    void reset() {
        time = largestForce = 0;
        for (int i = 0; i < 3; ++i) tip[i] = velocity[i] = force[i] = 0;
        scriptLength = 0;
    }
    void setScript(const double* rows, int n) {  // rows of (t, x, y, z, buttons)
        scriptLength = static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(script.size())));
        for (std::size_t k = 0; k < scriptLength; ++k) {
            const double* r = rows + 5 * k;
            script[k] = {r[0], r[1], r[2], r[3], static_cast<int>(r[4])};
        }
        if (scriptLength) {
            tip[0] = script[0].x, tip[1] = script[0].y, tip[2] = script[0].z;
        }
    }
    // the hand's point and buttons now (linear between waypoints, held after the last)
    Waypoint hand() const {
        if (scriptLength == 0) return {};
        std::size_t k = 0;
        while (k + 1 < scriptLength && script[k + 1].t <= time) ++k;
        if (k + 1 >= scriptLength) return script[k];
        const Waypoint &a = script[k], &b = script[k + 1];
        const double s = (time - a.t) / (b.t - a.t);
        return {time, a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), a.z + s * (b.z - a.z), a.buttons};
    }
    void step() {
        const Waypoint h = hand();
        const double hp[3] = {h.x, h.y, h.z};
        double norm = 0;
        for (int i = 0; i < 3; ++i) norm += force[i] * force[i];
        largestForce = std::max(largestForce, std::sqrt(norm));
        for (int i = 0; i < 3; ++i) {
            const double f = force[i] + handStiffness * (hp[i] - tip[i]) - (handDamping + damping) * velocity[i];
            velocity[i] += dt * f / mass;
            tip[i] += dt * velocity[i];
        }
        time += dt;
    }
    int buttons() const { return hand().buttons; }
};

}  // namespace fake
