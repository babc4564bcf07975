// Force Dimension devices (omega, delta, sigma, lambda) through the DHD SDK, loaded at run time
// (libdhd.so), never linked. DHD has no scheduler of its own: the haptic loop polls it, position
// and buttons in, force out, on the haptic thread (the SDK is thread-safe and does not allocate
// per call).
#pragma once
#include <atomic>
#include <cstdint>

#include "devices/device.hpp"
#include "common/platform/shared_library.hpp"
#include "devices/vendor/vendor_device_settings.hpp"

namespace hs {

class DhdDevice final : public Device {
public:
    /// Loads the library and its calls (std::runtime_error naming what is missing).
    explicit DhdDevice(VendorDeviceSettings settings);
    ~DhdDevice() override;
    std::string name() const override { return "dhd"; }
    DeviceCaps caps() const override;
    /// Opens the first device and enables force (std::runtime_error with the SDK's error text).
    void start() override;
    void stop() override;
    bool sample(double t, DeviceSample& out) override;
    void setForce(const Vec3& force) override;
    std::string model() const { return model_; }
    /// Loads the library and counts the devices (none is opened).
    static VendorProbe probe(const std::vector<std::string>& library = {});
    /// Samples whose position was not finite (kept the last one).
    std::uint64_t malformed() const { return malformed_.load(std::memory_order_relaxed); }

private:
    // dhdc.h's calls used here; char is the device id (-1: the default device).
    struct Api {
        int (*getDeviceCount)();
        int (*open)();
        int (*close)(char);
        int (*enableForce)(unsigned char, char);
        int (*getPosition)(double*, double*, double*, char);
        int (*setForce)(double, double, double, char);
        int (*getButtonMask)(char);
        const char* (*getSystemName)(char);
        const char* (*errorGetLastStr)();
    };
    std::string lastError(const std::string& what) const;
    void shutdown();

    VendorDeviceSettings settings_;
    SharedLibrary library_;
    Api api_{};
    int id_ = -1;
    std::string model_;
    double forceLimit_ = 0;  // N, set by start(): the clamp per tick
    bool lost_ = false, valid_ = false;
    Vec3 position_ = Vec3::Zero();  // mm, device frame
    std::atomic<std::uint64_t> malformed_{0};
};

}  // namespace hs
