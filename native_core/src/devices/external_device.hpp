// A device fed from outside the haptic loop (the mouse in the 3D view, a script): the feeder pushes
// the latest cursor, the haptic loop reads it; lock-free, no allocation.
#pragma once
#include <atomic>
#include <stdexcept>

#include "devices/device.hpp"
#include "common/triple_buffer.hpp"

namespace hs {

class ExternalDevice final : public Device {
public:
    explicit ExternalDevice(std::string name = "mouse") : name_(std::move(name)) {}
    std::string name() const override { return name_; }
    DeviceCaps caps() const override { return {6, false, 0, 0, 0}; }
    /// Feeder thread (one): the newest cursor.
    /// Publishes the latest cursor (orientation normalised); throws std::invalid_argument for a
    /// non-finite position or orientation or a zero quaternion, which never reach the loop.
    void push(DeviceSample s) {
        if (!s.position.allFinite() || !s.orientation.coeffs().allFinite() || !(s.orientation.norm() > 0))
            throw std::invalid_argument("position/orientation: must be finite (and a non-zero quaternion)");
        s.orientation.normalize();
        latest_.write(s);
    }
    /// Marks the device lost (e.g. its view closed): the session stops.
    void lose() { lost_.store(true, std::memory_order_release); }
    bool sample(double, DeviceSample& out) override {
        if (lost_.load(std::memory_order_acquire)) return false;
        latest_.update();
        out = latest_.front();
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
    std::string name_;
    TripleBuffer<DeviceSample> latest_;
    std::atomic<bool> lost_{false};
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
};

}  // namespace hs
