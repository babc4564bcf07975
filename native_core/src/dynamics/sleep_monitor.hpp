// Sleeping: a surface at rest is not stepped until something wakes it.
#pragma once
#include "common/types.hpp"

namespace hs {

/// With no tool active, after `steps` consecutive steps whose largest control-point speed is below
/// tolerance * size per second and whose net force is below tolerance * stiffness * size.
struct SleepSettings {
    bool enabled = true;
    double tolerance = 1e-6;
    int steps = 10;
    void validate() const {
        requirePositive(tolerance, "sleep_tolerance");
        requireInRange(steps, "sleep_steps", 1, 1000000);
    }
};

class SleepMonitor {
public:
    SleepSettings settings;

    bool asleep() const { return asleep_; }
    void wake() { asleep_ = false; quiet_ = 0; }
    /// Whether steps are being watched at all (sleeping on, no tool held); else the count restarts.
    bool watching(bool toolHeld) {
        if (settings.enabled && !toolHeld) return true;
        quiet_ = 0;
        return false;
    }
    /// After a watched step with largest speed `vmax`: whether the net force should now be checked,
    /// the last condition for falling asleep.
    bool quietStep(double vmax, double size) {
        if (!(vmax < settings.tolerance * size)) {
            quiet_ = 0;
            return false;
        }
        return ++quiet_ >= settings.steps;
    }
    /// The net force check's outcome: below `limit` the surface falls asleep; returns whether it did.
    bool settle(double netForce, double limit) {
        if (netForce < settings.tolerance * limit) asleep_ = true;
        else quiet_ = 0;
        return asleep_;
    }

private:
    bool asleep_ = false;
    int quiet_ = 0;
};

}  // namespace hs
