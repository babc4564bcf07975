#include "devices/vendor/dhd_device.hpp"

#include <algorithm>
#include <stdexcept>

#include "devices/device_limits.hpp"

namespace hs {

namespace {
// DHD's frame: x towards the user, y right, z up (m); the document's seen from the front has x
// right, y away from the user, z up.
Vec3 toDocument(const Vec3& v) { return Vec3(v.y(), -v.x(), v.z()); }
Vec3 toDevice(const Vec3& v) { return Vec3(-v.y(), v.x(), v.z()); }
}  // namespace

DhdDevice::DhdDevice(VendorDeviceSettings settings)
    : settings_((settings.validate(), std::move(settings))),
      library_(SharedLibrary::open(!settings_.library.empty() ? settings_.library
                                   : kWindows ? std::vector<std::string>{"dhd64.dll", "drd64.dll"}
                                              : std::vector<std::string>{"libdhd.so", "libdhd.so.3", "libdrd.so", "libdrd.so.3"},
                                   "Force Dimension DHD")) {
    const SharedLibrary& l = library_;
    api_.getDeviceCount = l.function<decltype(api_.getDeviceCount)>("dhdGetDeviceCount");
    api_.open = l.function<decltype(api_.open)>("dhdOpen");
    api_.close = l.function<decltype(api_.close)>("dhdClose");
    api_.enableForce = l.function<decltype(api_.enableForce)>("dhdEnableForce");
    api_.getPosition = l.function<decltype(api_.getPosition)>("dhdGetPosition");
    api_.setForce = l.function<decltype(api_.setForce)>("dhdSetForce");
    api_.getButtonMask = l.function<decltype(api_.getButtonMask)>("dhdGetButtonMask");
    api_.getSystemName = l.function<decltype(api_.getSystemName)>("dhdGetSystemName");
    api_.errorGetLastStr = l.function<decltype(api_.errorGetLastStr)>("dhdErrorGetLastStr");
}

VendorProbe DhdDevice::probe(const std::vector<std::string>& library) {
    VendorProbe p;
    VendorDeviceSettings settings;
    settings.library = library;
    try {
        DhdDevice dev(settings);
        p.loaded = true;
        p.library = dev.library_.name();
        p.attached = std::max(0, dev.api_.getDeviceCount());
        if (p.attached == 0) p.why = dev.lastError("no device attached");
    } catch (const std::runtime_error& e) {
        p.why = e.what();
    }
    return p;
}

DhdDevice::~DhdDevice() { shutdown(); }

std::string DhdDevice::lastError(const std::string& what) const {
    const char* text = api_.errorGetLastStr();
    return "Force Dimension: " + what + ": " + (text && *text ? text : "no reason given");
}

DeviceCaps DhdDevice::caps() const {
    DeviceCaps c;
    c.dof = 3;
    c.forceOutput = true;
    c.rateHz = 0;  // polled at the session's rate
    const DeviceLimits& row = limitsFor(model_);
    c.maxForce = settings_.mapping.sessionForce(settings_.maxForce > 0 ? settings_.maxForce : row.ratedForce);
    c.maxStiffness = settings_.mapping.sessionStiffness(passiveStiffnessFor(row, settings_.rateHz));
    return c;
}

void DhdDevice::start() {
    shutdown();
    if (api_.getDeviceCount() < 1) throw std::runtime_error(lastError("no device attached"));
    id_ = api_.open();
    if (id_ < 0) throw std::runtime_error(lastError("cannot open the device (in use by another program, or no permission?)"));
    const char* name = api_.getSystemName(static_cast<char>(id_));
    model_ = name ? name : "";
    forceLimit_ = settings_.maxForce > 0 ? settings_.maxForce : limitsFor(model_).ratedForce;
    if (api_.enableForce(1, static_cast<char>(id_)) < 0) {
        const std::string why = lastError("cannot enable force");
        shutdown();
        throw std::runtime_error(why);
    }
    lost_ = false;
    valid_ = false;
}

void DhdDevice::shutdown() {
    if (id_ < 0) return;
    const char id = static_cast<char>(id_);
    api_.setForce(0, 0, 0, id);
    api_.enableForce(0, id);
    api_.close(id);
    id_ = -1;
}

void DhdDevice::stop() { shutdown(); }

bool DhdDevice::sample(double, DeviceSample& out) {
    if (lost_ || id_ < 0) return false;
    double x = 0, y = 0, z = 0;
    const char id = static_cast<char>(id_);
    if (api_.getPosition(&x, &y, &z, id) < 0) {  // (1 is DHD_TIMEGUARD: a sample not yet due, still good)
        lost_ = true;
        return false;
    }
    const int buttons = api_.getButtonMask(id);
    if (buttons < 0) {
        lost_ = true;
        return false;
    }
    const Vec3 p = 1000.0 * Vec3(x, y, z);
    if (p.allFinite()) {
        position_ = p;
        valid_ = true;
    } else {
        malformed_.fetch_add(1, std::memory_order_relaxed);
    }
    out.position = settings_.mapping.position(toDocument(position_));
    out.orientation = Eigen::Quaterniond::Identity();
    out.buttons = static_cast<std::uint32_t>(buttons);
    out.valid = valid_;
    return true;
}

void DhdDevice::setForce(const Vec3& force) {
    if (lost_ || id_ < 0) return;
    Vec3 f = force.allFinite() ? settings_.mapping.newtons(force) : Vec3::Zero();
    if (f.norm() > forceLimit_) f *= forceLimit_ / f.norm();
    const Vec3 d = toDevice(f);
    if (api_.setForce(d.x(), d.y(), d.z(), static_cast<char>(id_)) < 0) lost_ = true;
}

}  // namespace hs
