// The intermediate representation the haptic loop renders between simulation steps (paper section
// 5; Adachi 1995, Mark et al. 1996): a small, fixed-size local model of the active tool published by
// the simulation after every step. The haptic loop evaluates the tool's own force law on it with the
// latest cursor, extrapolating the contact points linearly in time, so the force stays smooth when
// the simulation is slower than the haptic rate. Trivially copyable: it crosses threads by value.
#pragma once
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "geometry/bspline_surface.hpp"

namespace hs {

enum class EstimateKind : std::uint8_t {
    None,         ///< no tool grabbed: zero force
    Rope,         ///< one contact point, the rope's tension law
    Linear,       ///< linear in the cursor: F = -k D (W c + S(t)), S = sum w_i (o_i - x_i), D a projector
                  ///< (the magnet: D = I; flatten: D = n n^T)
    Orientation,  ///< five springs to the cursor frame
    Hold,         ///< no local model (smooth brush): the last exact reaction is held
};

struct HapticEstimate {
    static constexpr int kMaxPoints = 5;
    std::uint64_t sequence = 0;
    double time = 0;      ///< simulated time of the state (s); the runtime keeps it within max_lag of
                          ///< the session clock, the haptic loop extrapolates from it to now
    double toolTime = 0;  ///< seconds since the grab at that time (drives the ramp and the rope's reel)
    EstimateKind kind = EstimateKind::None;
    double maxForce = 0, rampTime = 0;
    // rope
    double stiffness = 0, stiffStiffness = 0, threshold = 0, length0 = 0, reelTime = 0;
    // rope and orientation: contact points and their velocities (finite differences between steps)
    int points = 0;
    Vec3 x[kMaxPoints] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
    Vec3 v[kMaxPoints] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  // (zero until a second state gives them)
    /// orientation: target of point k is c + spacing[k] * (R axis[k]) (axis 0 = none, 1 = x, 2 = y)
    int axis[kMaxPoints] = {0, 0, 0, 0, 0};
    double spacing[kMaxPoints] = {0, 0, 0, 0, 0};
    // linear (magnet, flatten)
    double weightSum = 0;
    Eigen::Matrix3d direction = Eigen::Matrix3d::Identity();
    Vec3 offsetSum = Vec3::Zero(), offsetRate = Vec3::Zero();
    // hold
    Vec3 heldForce = Vec3::Zero();
    /// Largest force-displacement slope of the law at this state (for the device's stiffness limit).
    double slope = 0;
};

/// Stamps `current` (as the tool describes the state a step of `taken` seconds left at `time`)
/// with its time and sequence, and its velocities by finite differences from `previous` where that
/// is the previous state of the same grab (else zero).
void followEstimate(const HapticEstimate& previous, HapticEstimate& current, double time, std::uint64_t sequence, double taken);

/// Reaction force on a cursor at (position, orientation) at simulation time t, from the estimate
/// extrapolated to t. Allocation-free, no locks: safe on the haptic thread.
Vec3 estimateForce(const HapticEstimate& e, const Vec3& position, const Eigen::Quaterniond& orientation, double t);

/// The safety layer between the estimate and the device.
struct ForceLimits {
    double maxForce = INFINITY;      ///< clamp on the rendered force
    double maxStiffness = INFINITY;  ///< steeper laws are scaled down to this slope
    double staleLimit = 0.02;        ///< s: older snapshots start fading the force
    double fadeTime = 0.05;          ///< s: from full force to zero once stale
};

/// Force to send to the device: non-finite becomes zero, the law's slope is limited to the device's
/// stiffness, a stale snapshot (simulation stalled) fades it out, and the magnitude is clamped.
Vec3 limitForce(const HapticEstimate& e, const Vec3& force, double t, const ForceLimits& limits);

/// Linear interpolation of two snapshots of the same grab (for measuring the estimate's error
/// against the exact trajectory): positions and magnet sums blend, parameters come from b.
HapticEstimate blendEstimates(const HapticEstimate& a, const HapticEstimate& b, double s);

}  // namespace hs
