// A device fed from outside the haptic loop (the mouse in the 3D view, a script). The feeder's
// samples are queued, not overwritten: a GUI thread busy drawing delivers a whole drag (press,
// moves, release) in one burst, and a device that kept only the newest sample showed the haptic
// loop the release alone: the stroke was lost (under load, one drag in five on FreeCAD 1.1). The
// haptic loop takes one queued sample per tick while the button is held or changes (the drag's
// path kept, its grab where the button went down), and holds a grab at least kShortestGrab before
// its release (a burst's drag, replayed in a few ticks, is still a stroke the surface follows).
// No allocation: a fixed ring under a mutex the haptic thread only tries (a tick that finds it
// taken reads the cursor it had).
#pragma once
#include <array>
#include <atomic>
#include <cstddef>
#include <mutex>
#include <stdexcept>

#include "devices/device.hpp"

namespace hs {

class ExternalDevice final : public Device {
public:
    /// s a grab is held at least before its release is passed on (a hand's quickest drag).
    static constexpr double kShortestGrab = 0.25;
    /// Samples queued at most: a drag's moves beyond it replace the newest (its path coarser).
    static constexpr std::size_t kQueued = 256;

    explicit ExternalDevice(std::string name = "mouse") : name_(std::move(name)) {}
    std::string name() const override { return name_; }
    DeviceCaps caps() const override { return {6, false, 0, 0, 0}; }
    /// Feeder thread (one): the next cursor (orientation normalised); throws std::invalid_argument
    /// for a non-finite position or orientation or a zero quaternion, which never reach the loop.
    void push(DeviceSample s) {
        if (!s.position.allFinite() || !s.orientation.coeffs().allFinite() || !(s.orientation.norm() > 0))
            throw std::invalid_argument("position/orientation: must be finite (and a non-zero quaternion)");
        s.orientation.normalize();
        std::lock_guard<std::mutex> lock(mutex_);
        if (count_ > 0) {
            DeviceSample& last = queue_[(first_ + count_ - 1) % kQueued];
            // a hover after a hover only moves the cursor; a full queue keeps the newest
            if ((!grabs(last) && !grabs(s) && last.buttons == s.buttons) || count_ == kQueued) {
                last = s;
                return;
            }
        }
        queue_[(first_ + count_) % kQueued] = s;
        ++count_;
    }
    /// Marks the device lost (e.g. its view closed): the session stops.
    void lose() { lost_.store(true, std::memory_order_release); }
    bool sample(double t, DeviceSample& out) override {
        if (lost_.load(std::memory_order_acquire)) return false;
        std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
        if (lock.owns_lock() && count_ > 0) {
            const DeviceSample& next = queue_[first_];
            const bool held = grabs(current_);
            if (!(held && !grabs(next) && t < grabbedAt_ + kShortestGrab)) {
                if (!held && grabs(next)) grabbedAt_ = t;
                current_ = next;
                first_ = (first_ + 1) % kQueued;
                --count_;
            }
        }
        out = current_;
        return true;
    }
    /// Last force the loop asked for (for display).
    Vec3 lastForce() const {
        return Vec3(force_[0].load(std::memory_order_relaxed), force_[1].load(std::memory_order_relaxed),
                    force_[2].load(std::memory_order_relaxed));
    }
    void setForce(const Vec3& f) override {
        for (int i = 0; i < 3; ++i) force_[i].store(f[i], std::memory_order_relaxed);
    }

private:
    static bool grabs(const DeviceSample& s) { return (s.buttons & 1u) != 0; }

    std::string name_;
    std::mutex mutex_;
    std::array<DeviceSample, kQueued> queue_{};
    std::size_t first_ = 0, count_ = 0;
    DeviceSample current_;   // (the haptic thread's alone)
    double grabbedAt_ = 0;   // (idem)
    std::atomic<bool> lost_{false};
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
};

}  // namespace hs
