// 3D Systems Touch / Phantom through OpenHaptics' HD API, loaded at run time (libHD.so), never
// linked. As the HD API asks, the device is touched only inside a servo callback on OpenHaptics'
// own scheduler thread: it reads the position and buttons into a triple buffer and writes the
// latest force the haptic loop asked for. The haptic loop itself never calls the library.
#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>

#include "devices/device.hpp"
#include "common/platform/shared_library.hpp"
#include "common/triple_buffer.hpp"
#include "devices/vendor/vendor_device_settings.hpp"

namespace hs {

class OpenHapticsDevice final : public Device {
public:
    /// Loads the library and its calls (std::runtime_error naming what is missing).
    explicit OpenHapticsDevice(VendorDeviceSettings settings);
    ~OpenHapticsDevice() override;
    std::string name() const override { return "openhaptics"; }
    DeviceCaps caps() const override;
    /// Opens the default device, enables force and starts the scheduler (std::runtime_error with
    /// the library's error text); waits for the first servo frame.
    void start() override;
    void stop() override;
    bool sample(double t, DeviceSample& out) override;
    void setForce(const Vec3& force) override;
    /// Loads the library, opens the default device and closes it again.
    static VendorProbe probe(const std::vector<std::string>& library = {});
    /// The device's model as the library names it ("" before start).
    std::string model() const { return model_; }
    std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }
    /// Servo frames whose position was not finite (kept the last one).
    std::uint64_t malformed() const { return malformed_.load(std::memory_order_relaxed); }

    // The HD API's C calls and types (hd.h), declared here: nothing of the vendor's is needed to
    // build.
    using HHD = unsigned int;
    using HDenum = unsigned int;
    struct HDErrorInfo {
        unsigned int errorCode;
        int internalErrorCode;
        HHD hHD;
    };
    using Callback = unsigned int (*)(void*);

private:
    struct Api {
        HHD (*initDevice)(const char*);
        void (*disableDevice)(HHD);
        HDErrorInfo (*getError)();
        const char* (*getErrorString)(unsigned int);
        void (*enable)(HDenum);
        void (*startScheduler)();
        void (*stopScheduler)();
        unsigned long (*scheduleAsynchronous)(Callback, void*, unsigned short);
        void (*unschedule)(unsigned long);
        void (*beginFrame)(HHD);
        void (*endFrame)(HHD);
        void (*getDoublev)(HDenum, double*);
        void (*getIntegerv)(HDenum, int*);
        void (*setDoublev)(HDenum, const double*);
        const char* (*getString)(HDenum);
    };
    struct Frame {
        Vec3 position = Vec3::Zero();  ///< mm, device frame
        std::uint32_t buttons = 0;
        std::uint64_t count = 0;
        bool valid = false;
    };
    static unsigned int servoCallback(void* self);
    unsigned int servo();
    std::string lastError(const char* what) const;
    void shutdown();

    VendorDeviceSettings settings_;
    SharedLibrary library_;
    Api api_{};
    HHD handle_ = 0;
    bool open_ = false, scheduled_ = false;
    unsigned long callback_ = 0;
    std::string model_;
    double maxForce_ = 0, nominalStiffness_ = 0;
    double forceLimit_ = 0;  // N, set by start(): the clamp per tick
    TripleBuffer<Frame> frameBuffer_{Frame{}};
    std::atomic<double> force_[3] = {0.0, 0.0, 0.0};
    std::atomic<bool> lost_{false};
    std::atomic<std::uint64_t> frames_{0}, malformed_{0};
    Vec3 servoLast_ = Vec3::Zero();  // the servo thread's own
    bool servoValid_ = false;
    std::uint64_t lastCount_ = 0;
    std::chrono::steady_clock::time_point lastFrameAt_{};
};

}  // namespace hs
