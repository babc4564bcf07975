// A device that plays a trajectory (timestamps, positions, orientations, button masks), with the
// same interpolation as the Python ReplayDevice: linear positions, normalised linear quaternions
// (sign-aligned), buttons held from the last sample. Lock-free and allocation-free once built.
#pragma once
#include <vector>

#include "devices/device.hpp"

namespace hs {

class ReplayDevice final : public Device {
public:
    /// t strictly increasing; xyz n x 3; quat n x 4 (w, x, y, z), unit; buttons n.
    ReplayDevice(std::vector<double> t, Points xyz, Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> quat,
                 std::vector<std::uint32_t> buttons);
    std::string name() const override { return "replay"; }
    DeviceCaps caps() const override { return {6, false, 0, 0, 0}; }
    bool sample(double t, DeviceSample& out) override;
    /// A tenth of a second after the last sample, so its last button change reaches the simulation.
    bool finished(double t) const override { return t > t_.back() + 0.1; }
    double duration() const { return t_.back(); }

private:
    std::vector<double> t_;
    Points xyz_;
    Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor> q_;
    std::vector<std::uint32_t> buttons_;
    size_t hint_ = 0;  ///< last interval, so a monotone clock finds its sample in O(1)
};

}  // namespace hs
