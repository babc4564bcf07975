// HID PID force feedback (usage page 0x0F): the report layout read from the device's report
// descriptor, one constant-force effect per force axis created, loaded and started (the sequence the
// Linux kernel's hid-pidff uses), magnitudes streamed by a writer thread that the haptic loop only
// hands values to (never blocks it), and every effect stopped on exit.
#pragma once
#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "devices/device.hpp"
#include "devices/hid/hid_report_descriptor.hpp"
#include "devices/hid/hid_transport.hpp"

namespace hs {

namespace pid {
constexpr std::uint16_t kPage = 0x0F;
constexpr std::uint32_t SetEffect = usage(kPage, 0x21), EffectBlockIndex = usage(kPage, 0x22),
                        EffectType = usage(kPage, 0x25), EtConstant = usage(kPage, 0x26),
                        Duration = usage(kPage, 0x50), Gain = usage(kPage, 0x52), AxesEnable = usage(kPage, 0x55),
                        Magnitude = usage(kPage, 0x70), SetConstantForce = usage(kPage, 0x73),
                        EffectOperation = usage(kPage, 0x77), OpStart = usage(kPage, 0x79), OpStop = usage(kPage, 0x7b),
                        LoopCount = usage(kPage, 0x7c), BlockLoad = usage(kPage, 0x89), BlockLoadStatus = usage(kPage, 0x8b),
                        BlockLoadSuccess = usage(kPage, 0x8c), DeviceControl = usage(kPage, 0x96),
                        EnableActuators = usage(kPage, 0x97), DisableActuators = usage(kPage, 0x98),
                        StopAllEffects = usage(kPage, 0x99), CreateNewEffect = usage(kPage, 0xab);
}  // namespace pid

/// Where each PID report and field lives on one device.
struct PidLayout {
    HidReportLayout hid;
    std::uint8_t setEffectId = 0, constantId = 0, operationId = 0, controlId = 0, createId = 0, blockLoadId = 0;
    int axes = 1;  ///< force axes (from Set Effect's Axes Enable), at most 3
    /// Throws std::invalid_argument naming the first missing report.
    static PidLayout fromDescriptor(const std::vector<std::uint8_t>& descriptor);
};

/// Sets the field carrying `u` (variable: the value; array: selects u) in a report buffer.
bool setPidField(const HidReportLayout& layout, ReportType type, std::uint8_t id, std::uint32_t u,
                 std::int64_t value, std::vector<std::uint8_t>& report, std::uint32_t collection = 0);

struct PidSettings {
    double fullScaleForce = 1000.0;  ///< force (our units) that maps to the device's largest magnitude
    double writePeriod = 1e-3;       ///< s between magnitude updates (the writer thread's rate)
};

class PidForceDriver {
public:
    PidForceDriver(std::shared_ptr<HidTransport> transport, PidSettings settings);
    ~PidForceDriver();
    /// Enable actuators, create + load + set + start one constant effect per axis. Throws when the
    /// device refuses (Block Load never succeeds, writes fail).
    void start();
    /// Stop every effect, stop all, disable actuators; joins the writer. Idempotent.
    void stop();
    /// Haptic thread: hand over the newest force (atomics only).
    void setForce(const Vec3& f);
    const PidLayout& layout() const { return layout_; }
    std::uint64_t writes() const { return writes_.load(std::memory_order_relaxed); }
    int axes() const { return layout_.axes; }

private:
    void writerLoop();
    bool writeConstant(int axis, std::int64_t magnitude);
    std::shared_ptr<HidTransport> transport_;
    PidSettings settings_;
    PidLayout layout_;
    std::vector<std::uint8_t> effects_;  // block index per axis
    std::int64_t magnitudeMax_ = 10000;
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
    std::atomic<bool> running_{false};
    std::atomic<std::uint64_t> writes_{0};
    std::thread writer_;
};

/// Position and buttons from one device, forces to a PID driver.
class ForceFeedbackDevice final : public Device {
public:
    ForceFeedbackDevice(std::shared_ptr<Device> input, std::shared_ptr<PidForceDriver> output, double maxForce,
                        double maxStiffness);
    std::string name() const override { return input_->name() + " + HID PID force"; }
    DeviceCaps caps() const override;
    void start() override;
    void stop() override;
    bool sample(double t, DeviceSample& out) override { return input_->sample(t, out); }
    void setForce(const Vec3& f) override { output_->setForce(f); }
    bool finished(double t) const override { return input_->finished(t); }

private:
    std::shared_ptr<Device> input_;
    std::shared_ptr<PidForceDriver> output_;
    double maxForce_, maxStiffness_;
};

}  // namespace hs
