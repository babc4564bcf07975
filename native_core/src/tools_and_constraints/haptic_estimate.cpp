#include "tools_and_constraints/haptic_estimate.hpp"

#include <algorithm>
#include <cmath>

namespace hs {

Vec3 estimateForce(const HapticEstimate& e, const Vec3& c, const Eigen::Quaterniond& q, double t) {
    const double dt = std::max(0.0, t - e.time);
    const double toolTime = e.toolTime + dt;
    Vec3 f = Vec3::Zero();  // force of the tool on the surface; the cursor feels -f
    switch (e.kind) {
        case EstimateKind::None:
            return Vec3::Zero();
        case EstimateKind::Hold:
            return e.heldForce;
        case EstimateKind::Rope: {
            const Vec3 x = e.x[0] + dt * e.v[0];
            const Vec3 toCursor = c - x;
            const double dist = toCursor.norm();
            const double rest = e.reelTime > 0 ? e.length0 * std::max(0.0, 1.0 - toolTime / e.reelTime) : 0.0;
            const double ext = dist - rest;
            if (ext <= 0 || !(dist > 0)) return Vec3::Zero();
            const double tension = e.stiffness * std::min(ext, e.threshold) + e.stiffStiffness * std::max(0.0, ext - e.threshold);
            f = tension / dist * toCursor;
            break;
        }
        case EstimateKind::Linear:  // sum k w_i D (c + o_i - x_i) = k D (W c + S)
            f = e.stiffness * (e.direction * (e.weightSum * c + e.offsetSum + dt * e.offsetRate));
            break;
        case EstimateKind::Orientation: {
            for (int k = 0; k < e.points; ++k) {
                Vec3 target = c;
                if (e.axis[k] == 1) target += e.spacing[k] * (q * Vec3::UnitX());
                if (e.axis[k] == 2) target += e.spacing[k] * (q * Vec3::UnitY());
                f += e.stiffness * (target - (e.x[k] + dt * e.v[k]));
            }
            break;
        }
    }
    double scale = e.rampTime > 0 ? std::min(1.0, toolTime / e.rampTime) : 1.0;
    const double mag = f.norm() * scale;
    if (mag > e.maxForce) scale *= e.maxForce / mag;
    return -scale * f;
}

void followEstimate(const HapticEstimate& previous, HapticEstimate& current, double time, std::uint64_t sequence, double taken) {
    current.time = time;
    current.sequence = sequence;
    const bool sameGrab = previous.kind == current.kind && previous.points == current.points &&
                          current.kind != EstimateKind::None && previous.sequence + 1 == current.sequence &&
                          current.toolTime > previous.toolTime;
    for (int k = 0; k < current.points; ++k) current.v[k] = sameGrab ? Vec3((current.x[k] - previous.x[k]) / taken) : Vec3::Zero();
    current.offsetRate = sameGrab ? Vec3((current.offsetSum - previous.offsetSum) / taken) : Vec3::Zero();
}

Vec3 limitForce(const HapticEstimate& e, const Vec3& f, double t, const ForceLimits& limits) {
    if (!f.allFinite()) return Vec3::Zero();
    double scale = 1.0;
    if (e.slope > limits.maxStiffness) scale = limits.maxStiffness / e.slope;
    const double age = t - e.time;
    if (age > limits.staleLimit) scale *= std::max(0.0, 1.0 - (age - limits.staleLimit) / limits.fadeTime);
    Vec3 out = scale * f;
    const double mag = out.norm();
    if (mag > limits.maxForce) out *= limits.maxForce / mag;
    return out;
}

HapticEstimate blendEstimates(const HapticEstimate& a, const HapticEstimate& b, double s) {
    HapticEstimate r = b;
    if (a.kind != b.kind || a.points != b.points) return r;
    r.time = a.time + s * (b.time - a.time);
    r.toolTime = a.toolTime + s * (b.toolTime - a.toolTime);
    for (int k = 0; k < b.points; ++k) {
        r.x[k] = a.x[k] + s * (b.x[k] - a.x[k]);
        r.v[k] = Vec3::Zero();
    }
    r.offsetSum = a.offsetSum + s * (b.offsetSum - a.offsetSum);
    r.offsetRate = Vec3::Zero();
    r.heldForce = a.heldForce + s * (b.heldForce - a.heldForce);
    return r;
}

}  // namespace hs
