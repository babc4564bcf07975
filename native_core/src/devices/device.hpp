// One interface for every input/output device the haptic loop talks to. sample() and setForce()
// run on the haptic thread: implementations must not block, allocate or take the GIL there.
#pragma once
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "geometry/bspline_surface.hpp"

namespace hs {

/// The haptic loop's rate unless a session asks for another (Hz): the runtime's default and the one
/// the force devices take their passivity bounds at.
inline constexpr double kDefaultHapticRate = 1000;

struct DeviceCaps {
    int dof = 3;               ///< 3 (position) or 6 (position and orientation)
    bool forceOutput = false;  ///< can render a force
    double rateHz = 0;         ///< native report rate, 0 if unknown or a replay
    double maxForce = 0;       ///< largest force it can render (force units), 0 without output
    double maxStiffness = 0;   ///< largest stable stiffness (force per length), 0 without output
};

struct DeviceSample {
    Vec3 position = Vec3::Zero();  ///< cursor in the document frame (mm)
    Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
    std::uint32_t buttons = 0;     ///< bit 0 = button 1 = grab
    bool valid = false;
};

/// The same reading (the simulation gives its surface a cursor only when the reading changed).
inline bool sameSample(const DeviceSample& a, const DeviceSample& b) {
    return a.valid == b.valid && a.buttons == b.buttons && a.position == b.position &&
           a.orientation.coeffs() == b.orientation.coeffs();
}

class Device {
public:
    virtual ~Device() = default;
    virtual std::string name() const = 0;
    virtual DeviceCaps caps() const = 0;
    /// Called once from the session's thread before the loops start, and after they stop.
    virtual void start() {}
    virtual void stop() {}
    /// Latest cursor at session time t (s). False when the device is lost: the session stops.
    virtual bool sample(double t, DeviceSample& out) = 0;
    /// Force to render (device frame = document frame); a no-op for input-only devices.
    virtual void setForce(const Vec3&) {}
    /// True when a finite trajectory has played to its end.
    virtual bool finished(double) const { return false; }
};

}  // namespace hs
