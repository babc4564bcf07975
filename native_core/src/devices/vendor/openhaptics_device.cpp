#include "devices/vendor/openhaptics_device.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "devices/device_limits.hpp"

namespace hs {

namespace {
// hdDefines.h
constexpr unsigned int kSuccess = 0;
constexpr unsigned int kInvalidHandle = 0xFFFFFFFF;
constexpr unsigned int kCallbackDone = 0, kCallbackContinue = 1;
constexpr unsigned short kMaxSchedulerPriority = 0xFFFF;
constexpr unsigned int kCurrentButtons = 0x2000, kCurrentPosition = 0x2050, kCurrentForce = 0x2700;
constexpr unsigned int kDeviceModelType = 0x2501, kUpdateRate = 0x2600, kNominalMaxStiffness = 0x2602,
                       kNominalMaxForce = 0x2603, kForceOutput = 0x4000;
// The HD frame: x right, y up, z towards the user (mm); the document's seen from the front has
// z up and y away from the user.
Vec3 toDocument(const Vec3& v) { return Vec3(v.x(), -v.z(), v.y()); }
Vec3 toDevice(const Vec3& v) { return Vec3(v.x(), v.z(), -v.y()); }
}  // namespace

OpenHapticsDevice::OpenHapticsDevice(VendorDeviceSettings settings)
    : settings_((settings.validate(), std::move(settings))),
      library_(SharedLibrary::open(!settings_.library.empty() ? settings_.library
                                   : kWindows ? std::vector<std::string>{"hd.dll"}
                                              : std::vector<std::string>{"libHD.so", "libHD.so.3.4", "libHD.so.3"},
                                   "OpenHaptics (3D Systems Touch, Phantom)")) {
    const SharedLibrary& l = library_;
    api_.initDevice = l.function<decltype(api_.initDevice)>("hdInitDevice");
    api_.disableDevice = l.function<decltype(api_.disableDevice)>("hdDisableDevice");
    api_.getError = l.function<decltype(api_.getError)>("hdGetError");
    api_.getErrorString = l.function<decltype(api_.getErrorString)>("hdGetErrorString");
    api_.enable = l.function<decltype(api_.enable)>("hdEnable");
    api_.startScheduler = l.function<decltype(api_.startScheduler)>("hdStartScheduler");
    api_.stopScheduler = l.function<decltype(api_.stopScheduler)>("hdStopScheduler");
    api_.scheduleAsynchronous = l.function<decltype(api_.scheduleAsynchronous)>("hdScheduleAsynchronous");
    api_.unschedule = l.function<decltype(api_.unschedule)>("hdUnschedule");
    api_.beginFrame = l.function<decltype(api_.beginFrame)>("hdBeginFrame");
    api_.endFrame = l.function<decltype(api_.endFrame)>("hdEndFrame");
    api_.getDoublev = l.function<decltype(api_.getDoublev)>("hdGetDoublev");
    api_.getIntegerv = l.function<decltype(api_.getIntegerv)>("hdGetIntegerv");
    api_.setDoublev = l.function<decltype(api_.setDoublev)>("hdSetDoublev");
    api_.getString = l.function<decltype(api_.getString)>("hdGetString");
}

VendorProbe OpenHapticsDevice::probe(const std::vector<std::string>& library) {
    VendorProbe p;
    VendorDeviceSettings settings;
    settings.library = library;
    try {
        OpenHapticsDevice dev(settings);
        p.loaded = true;
        p.library = dev.library_.name();
        dev.handle_ = dev.api_.initDevice(nullptr);
        if (dev.handle_ == kInvalidHandle || dev.api_.getError().errorCode != kSuccess) {
            p.why = dev.lastError("no device (is it plugged in, and set up with Touch Setup?)");
            return p;
        }
        dev.open_ = true;  // (closed by its destructor)
        const char* model = dev.api_.getString(kDeviceModelType);
        p.model = model ? model : "";
        p.attached = 1;
    } catch (const std::runtime_error& e) {
        p.why = e.what();
    }
    return p;
}

OpenHapticsDevice::~OpenHapticsDevice() { shutdown(); }

std::string OpenHapticsDevice::lastError(const char* what) const {
    const HDErrorInfo e = api_.getError();
    const char* text = api_.getErrorString(e.errorCode);
    return std::string("OpenHaptics: ") + what + ": " + (text ? text : "error") + " (code " +
           std::to_string(e.errorCode) + ", internal " + std::to_string(e.internalErrorCode) + ")";
}

DeviceCaps OpenHapticsDevice::caps() const {
    DeviceCaps c;
    c.dof = 3;
    c.forceOutput = true;
    c.rateHz = settings_.rateHz;
    const DeviceLimits& row = limitsFor(model_);
    // (before start(): the setting, else the table's rating)
    c.maxForce = settings_.mapping.sessionForce(forceLimit_ > 0 ? forceLimit_ : settings_.maxForce > 0 ? settings_.maxForce : row.ratedForce);
    double k = passiveStiffnessFor(row, settings_.rateHz);
    if (nominalStiffness_ > 0) k = std::min(k, nominalStiffness_);  // the vendor's own figure, if lower
    c.maxStiffness = settings_.mapping.sessionStiffness(k);
    return c;
}

void OpenHapticsDevice::start() {
    shutdown();
    lost_.store(false);
    frames_.store(0);
    for (auto& f : force_) f.store(0.0);
    handle_ = api_.initDevice(nullptr);  // HD_DEFAULT_DEVICE
    if (handle_ == kInvalidHandle || api_.getError().errorCode != kSuccess)
        throw std::runtime_error(lastError("no device (is it plugged in, and set up with Touch Setup?)"));
    open_ = true;
    const char* model = api_.getString(kDeviceModelType);
    model_ = model ? model : "";
    double v = 0;
    api_.getDoublev(kNominalMaxForce, &v);
    maxForce_ = v > 0 && std::isfinite(v) ? v : 0;
    v = 0;
    api_.getDoublev(kNominalMaxStiffness, &v);  // N/mm
    nominalStiffness_ = v > 0 && std::isfinite(v) ? 1000 * v : 0;
    const double rated = limitsFor(model_).ratedForce;
    forceLimit_ = settings_.maxForce > 0 ? settings_.maxForce : maxForce_ > 0 ? std::min(maxForce_, rated) : rated;
    api_.enable(kForceOutput);
    callback_ = api_.scheduleAsynchronous(&OpenHapticsDevice::servoCallback, this, kMaxSchedulerPriority);
    scheduled_ = true;
    api_.startScheduler();
    if (api_.getError().errorCode != kSuccess) {
        const std::string why = lastError("the servo scheduler did not start");
        shutdown();
        throw std::runtime_error(why);
    }
    // the first frame, so the first sample is real
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (frames_.load() == 0 && !lost_.load() && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (frames_.load() == 0) {
        shutdown();
        throw std::runtime_error("OpenHaptics: the scheduler ran no servo frame within 2 s");
    }
    lastCount_ = 0;
    lastFrameAt_ = std::chrono::steady_clock::now();
}

void OpenHapticsDevice::shutdown() {
    for (auto& f : force_) f.store(0.0);
    if (scheduled_) {
        api_.stopScheduler();
        api_.unschedule(callback_);
        scheduled_ = false;
    }
    if (open_) {
        api_.disableDevice(handle_);
        open_ = false;
    }
}

void OpenHapticsDevice::stop() { shutdown(); }

unsigned int OpenHapticsDevice::servoCallback(void* self) { return static_cast<OpenHapticsDevice*>(self)->servo(); }

// OpenHaptics' scheduler thread: one frame per servo tick.
unsigned int OpenHapticsDevice::servo() {
    api_.beginFrame(handle_);
    double p[3] = {0, 0, 0};
    int buttons = 0;
    api_.getDoublev(kCurrentPosition, p);
    api_.getIntegerv(kCurrentButtons, &buttons);
    const Vec3 f = lost_.load(std::memory_order_relaxed)
                       ? Vec3::Zero()
                       : Vec3(force_[0].load(std::memory_order_relaxed), force_[1].load(std::memory_order_relaxed),
                              force_[2].load(std::memory_order_relaxed));
    api_.setDoublev(kCurrentForce, f.data());
    api_.endFrame(handle_);
    if (api_.getError().errorCode != kSuccess) {  // e.g. the device was unplugged: stop rendering
        lost_.store(true, std::memory_order_release);
        return kCallbackDone;
    }
    Frame& fr = frameBuffer_.back();
    const Vec3 pos(p[0], p[1], p[2]);
    if (pos.allFinite()) {
        fr.position = pos;
        fr.valid = true;
    } else {
        malformed_.fetch_add(1, std::memory_order_relaxed);  // keep the last good position
        fr.position = servoLast_;
        fr.valid = servoValid_;
    }
    servoLast_ = fr.position;
    servoValid_ = fr.valid;
    fr.buttons = static_cast<std::uint32_t>(buttons);
    fr.count = frames_.fetch_add(1, std::memory_order_relaxed) + 1;
    frameBuffer_.publish();
    return kCallbackContinue;
}

bool OpenHapticsDevice::sample(double, DeviceSample& out) {
    if (lost_.load(std::memory_order_acquire)) return false;
    frameBuffer_.update();
    const Frame& fr = frameBuffer_.front();
    const auto now = std::chrono::steady_clock::now();
    if (fr.count != lastCount_) {
        lastCount_ = fr.count;
        lastFrameAt_ = now;
    } else if (std::chrono::duration<double>(now - lastFrameAt_).count() > settings_.staleAfter) {
        lost_.store(true);  // the scheduler stopped calling us
        return false;
    }
    out.position = settings_.mapping.position(toDocument(fr.position));
    out.orientation = Eigen::Quaterniond::Identity();
    out.buttons = fr.buttons;
    out.valid = fr.valid;
    return true;
}

void OpenHapticsDevice::setForce(const Vec3& force) {
    Vec3 f = force.allFinite() ? settings_.mapping.newtons(force) : Vec3::Zero();
    if (f.norm() > forceLimit_) f *= forceLimit_ / f.norm();
    const Vec3 d = toDevice(f);
    for (int i = 0; i < 3; ++i) force_[i].store(d[i], std::memory_order_relaxed);
}

}  // namespace hs
