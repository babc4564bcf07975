// The Novint Falcon as a Device: status frames in (encoder counts to the tip's position by the
// forward kinematics, the grip's buttons), force out (motor torques by virtual work, as motor
// commands), over a Transport. Homing first: the motors seek their index marks until all three
// encoders report homed (the user moves the grip through its range, as Novint's driver asks).
#pragma once
#include <array>
#include <atomic>
#include <memory>

#include "devices/device.hpp"
#include "devices/device_mapping.hpp"
#include "devices/falcon/falcon_frames.hpp"
#include "devices/falcon/falcon_kinematics.hpp"
#include "devices/falcon/falcon_transport.hpp"

namespace hs {

struct FalconSettings {
    /// Where the middle of the Falcon's workspace (0, 0, 0.11 m in its frame) sits in the
    /// document, the travel scale and the session's force unit. The grip's right, up and towards
    /// the user are the document's x, z and -y (a front view).
    DeviceMapping mapping;
    /// Motor command per N m of torque: libnifalcon's conversion (its Stamper kinematics).
    double countsPerNewtonMetre = 1e4;
    /// The largest force rendered (N): the Falcon's rating (device_limits.hpp).
    double maxForce = 8.0;
    /// The servo rate the passivity bound is taken at (Hz): the firmware answers each frame and
    /// the FTDI latency timer (1 ms) sets the pace.
    double rateHz = kDefaultHapticRate;
    double homingTimeout = 10.0;  ///< s: after it, start() throws saying what to do
    double readTimeout = 0.002;   ///< s a tick waits for its status frame before it keeps the last one
    void validate() const;
};

class FalconDevice final : public Device {
public:
    FalconDevice(std::shared_ptr<falcon::Transport> transport, FalconSettings settings);
    std::string name() const override { return "falcon"; }
    DeviceCaps caps() const override;
    /// Homes the device (std::runtime_error if it does not home in time or the link is gone).
    void start() override;
    /// Zero force (the device keeps its last command otherwise).
    void stop() override;
    bool sample(double t, DeviceSample& out) override;
    void setForce(const Vec3& force) override;
    /// Status frames taken, ticks that kept the last position (no frame in time), bytes skipped.
    std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }
    std::uint64_t missed() const { return missed_.load(std::memory_order_relaxed); }
    std::uint64_t skippedBytes() const { return skipped_.load(std::memory_order_relaxed); }

private:
    bool exchange(const falcon::Command& command, double timeout, falcon::Status& status);
    std::shared_ptr<falcon::Transport> transport_;
    FalconSettings settings_;
    falcon::FrameReader reader_;
    std::array<std::uint8_t, 64> buffer_{};
    falcon::Vec3d tip_ = falcon::Vec3d(0, 0, 0.11);  ///< the tip's position (m, device frame)
    falcon::Command command_;
    bool lost_ = false, positioned_ = false;
    std::uint8_t buttons_ = 0;
    std::atomic<std::uint64_t> frames_{0}, missed_{0}, skipped_{0};
};

}  // namespace hs
