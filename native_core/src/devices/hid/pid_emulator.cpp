#include "devices/hid/pid_emulator.hpp"

#include <chrono>
#include <cstring>
#include <thread>

#include "devices/hid/pid_force.hpp"

namespace hs {

namespace {
// A compact PID descriptor in the layout common to Arduino/MOZA-style firmware: outputs 1 Set
// Effect, 5 Set Constant Force, 10 Effect Operation, 12 Device Control; features 5 Create New
// Effect, 6 Block Load.
std::vector<std::uint8_t> emulatorDescriptor() {
    return {
        0x05, 0x01, 0x09, 0x04, 0xA1, 0x01,                    // Generic Desktop, Joystick, Application
        0x05, 0x0F,                                            // PID page
        0x09, 0x21, 0xA1, 0x02, 0x85, 0x01,                    // Set Effect, report 1
        0x09, 0x22, 0x15, 0x01, 0x25, 0x28, 0x75, 0x08, 0x95, 0x01, 0x91, 0x02,   // block index
        0x09, 0x25, 0xA1, 0x02, 0x09, 0x26, 0x15, 0x01, 0x25, 0x01, 0x75, 0x08, 0x95, 0x01, 0x91, 0x00, 0xC0,  // type
        0x09, 0x50, 0x15, 0x00, 0x27, 0xFF, 0xFF, 0x00, 0x00, 0x75, 0x10, 0x95, 0x01, 0x91, 0x02,  // duration
        0x09, 0x52, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, 0x01, 0x91, 0x02,              // gain
        0x09, 0x55, 0xA1, 0x02, 0x05, 0x01, 0x09, 0x30, 0x09, 0x31, 0x09, 0x32, 0x15, 0x00, 0x25, 0x01,
        0x75, 0x01, 0x95, 0x03, 0x91, 0x02, 0x95, 0x05, 0x91, 0x03, 0xC0, 0x05, 0x0F,               // axes enable
        0xC0,
        0x09, 0x73, 0xA1, 0x02, 0x85, 0x05,                    // Set Constant Force, report 5
        0x09, 0x22, 0x15, 0x01, 0x25, 0x28, 0x75, 0x08, 0x95, 0x01, 0x91, 0x02,
        0x09, 0x70, 0x16, 0xF0, 0xD8, 0x26, 0x10, 0x27, 0x75, 0x10, 0x95, 0x01, 0x91, 0x02,        // -10000..10000
        0xC0,
        0x09, 0x77, 0xA1, 0x02, 0x85, 0x0A,                    // Effect Operation, report 10
        0x09, 0x22, 0x15, 0x01, 0x25, 0x28, 0x75, 0x08, 0x95, 0x01, 0x91, 0x02,
        0x09, 0x78, 0xA1, 0x02, 0x09, 0x79, 0x09, 0x7A, 0x09, 0x7B, 0x15, 0x01, 0x25, 0x03, 0x75, 0x08,
        0x95, 0x01, 0x91, 0x00, 0xC0,
        0x09, 0x7C, 0x15, 0x00, 0x26, 0xFF, 0x00, 0x75, 0x08, 0x95, 0x01, 0x91, 0x02,
        0xC0,
        0x09, 0x96, 0xA1, 0x02, 0x85, 0x0C,                    // Device Control, report 12
        0x09, 0x97, 0x09, 0x98, 0x09, 0x99, 0x09, 0x9A, 0x09, 0x9B, 0x09, 0x9C, 0x15, 0x01, 0x25, 0x06,
        0x75, 0x08, 0x95, 0x01, 0x91, 0x00,
        0xC0,
        0x09, 0xAB, 0xA1, 0x02, 0x85, 0x05,                    // Create New Effect, feature 5
        0x09, 0x25, 0xA1, 0x02, 0x09, 0x26, 0x15, 0x01, 0x25, 0x01, 0x75, 0x08, 0x95, 0x01, 0xB1, 0x00, 0xC0,
        0x05, 0x01, 0x09, 0x3B, 0x15, 0x00, 0x26, 0xFF, 0x01, 0x75, 0x0A, 0x95, 0x01, 0xB1, 0x02,
        0x75, 0x06, 0xB1, 0x01, 0x05, 0x0F,
        0xC0,
        0x09, 0x89, 0xA1, 0x02, 0x85, 0x06,                    // Block Load, feature 6
        0x09, 0x22, 0x15, 0x01, 0x25, 0x28, 0x75, 0x08, 0x95, 0x01, 0xB1, 0x02,
        0x09, 0x8B, 0xA1, 0x02, 0x09, 0x8C, 0x09, 0x8D, 0x09, 0x8E, 0x15, 0x01, 0x25, 0x03, 0x75, 0x08,
        0x95, 0x01, 0xB1, 0x00, 0xC0,
        0x09, 0xAC, 0x15, 0x00, 0x27, 0xFF, 0xFF, 0x00, 0x00, 0x75, 0x10, 0x95, 0x01, 0xB1, 0x02,
        0xC0,
        0xC0,
    };
}

// The value of usage u in a received report: a variable field's value, or 1/0 for whether an
// array field selects it.
std::int64_t field(const HidReportLayout& l, ReportType type, std::uint8_t id, std::uint32_t u, const std::uint8_t* r,
                   std::size_t n, std::uint32_t collection) {
    const FieldSlot slot = locateField(l, type, id, u, collection);
    if (!slot.field) return 0;
    const std::int64_t v = readField(r + 1, n - 1, slot.bit, slot.field->size, !slot.array && slot.field->logicalMin < 0);
    return slot.array ? v == slot.choice : v;
}
}  // namespace

PidEmulator::PidEmulator(int poolSize)
    : descriptor_(emulatorDescriptor()), layout_(parseReportDescriptor(descriptor_)),
      pool_(static_cast<std::size_t>(std::max(1, poolSize))) {}

HidInfo PidEmulator::info() const {
    HidInfo i;
    i.vendorId = 0xF0F0;
    i.productId = 0x0FFB;
    i.name = "HapticSculpt emulated PID device";
    i.usagePage = 0x01;
    i.usage = 0x04;
    return i;
}

int PidEmulator::read(std::uint8_t*, std::size_t, int timeoutMs) {
    if (timeoutMs > 0) std::this_thread::sleep_for(std::chrono::milliseconds(timeoutMs));
    std::lock_guard<std::mutex> lock(mutex_);
    return unplugged_ ? -1 : 0;
}

int PidEmulator::write(const std::uint8_t* r, std::size_t n) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (unplugged_) return -1;
    ++outputs_;
    const std::size_t expected = n ? layout_.reportBytes(ReportType::Output, r[0]) : 0;
    if (n < 2 || n < expected) {
        ++malformed_;
        return static_cast<int>(n);
    }
    const std::uint8_t id = r[0];
    auto effectAt = [&](std::int64_t index) -> EmulatedEffect* {
        if (index < 1 || index > static_cast<std::int64_t>(pool_.size()) || !pool_[static_cast<size_t>(index - 1)].allocated) return nullptr;
        return &pool_[static_cast<size_t>(index - 1)];
    };
    if (id == 1) {  // Set Effect
        EmulatedEffect* e = effectAt(field(layout_, ReportType::Output, id, pid::EffectBlockIndex, r, n, pid::SetEffect));
        if (!e) { ++malformed_; return static_cast<int>(n); }
        e->constant = field(layout_, ReportType::Output, id, pid::EtConstant, r, n, pid::SetEffect) != 0;
        e->duration = field(layout_, ReportType::Output, id, pid::Duration, r, n, pid::SetEffect);
        e->axesMask = 0;
        for (int a = 0; a < 3; ++a)
            if (field(layout_, ReportType::Output, id, usage(0x01, static_cast<std::uint16_t>(0x30 + a)), r, n, pid::AxesEnable)) e->axesMask |= 1 << a;
    } else if (id == 5) {  // Set Constant Force
        EmulatedEffect* e = effectAt(field(layout_, ReportType::Output, id, pid::EffectBlockIndex, r, n, pid::SetConstantForce));
        if (!e) { ++malformed_; return static_cast<int>(n); }
        e->magnitude = field(layout_, ReportType::Output, id, pid::Magnitude, r, n, pid::SetConstantForce);
    } else if (id == 10) {  // Effect Operation
        EmulatedEffect* e = effectAt(field(layout_, ReportType::Output, id, pid::EffectBlockIndex, r, n, pid::EffectOperation));
        if (!e) { ++malformed_; return static_cast<int>(n); }
        if (field(layout_, ReportType::Output, id, pid::OpStart, r, n, pid::EffectOperation)) e->running = true;
        if (field(layout_, ReportType::Output, id, pid::OpStop, r, n, pid::EffectOperation)) e->running = false;
    } else if (id == 12) {  // Device Control
        if (field(layout_, ReportType::Output, id, pid::EnableActuators, r, n, pid::DeviceControl)) actuators_ = true;
        if (field(layout_, ReportType::Output, id, pid::DisableActuators, r, n, pid::DeviceControl)) actuators_ = false;
        if (field(layout_, ReportType::Output, id, pid::StopAllEffects, r, n, pid::DeviceControl)) {
            ++stopAll_;
            for (auto& e : pool_) e.running = false;
        }
    } else {
        ++malformed_;
    }
    return static_cast<int>(n);
}

int PidEmulator::sendFeature(const std::uint8_t* r, std::size_t n) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (unplugged_) return -1;
    if (n < 2 || r[0] != 5) {
        ++malformed_;
        return -1;
    }
    lastCreateOk_ = false;
    for (std::size_t k = 0; k < pool_.size(); ++k)
        if (!pool_[k].allocated) {
            pool_[k] = EmulatedEffect{};
            pool_[k].allocated = true;
            lastCreated_ = static_cast<int>(k + 1);
            lastCreateOk_ = true;
            break;
        }
    return static_cast<int>(n);
}

int PidEmulator::getFeature(std::uint8_t* buf, std::size_t size) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (unplugged_ || size < 4 || buf[0] != 6) return -1;
    std::memset(buf + 1, 0, size - 1);
    buf[1] = lastCreateOk_ ? static_cast<std::uint8_t>(lastCreated_) : 0;
    buf[2] = lastCreateOk_ ? 1 : 2;  // 1 = success, 2 = full
    buf[3] = 0xFF;
    return static_cast<int>(std::min<std::size_t>(size, 5));
}

std::vector<EmulatedEffect> PidEmulator::effects() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return pool_;
}
bool PidEmulator::actuatorsEnabled() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return actuators_;
}
int PidEmulator::stopAllCount() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stopAll_;
}
std::size_t PidEmulator::outputReports() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return outputs_;
}
std::size_t PidEmulator::malformedReports() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return malformed_;
}
void PidEmulator::unplug() {
    std::lock_guard<std::mutex> lock(mutex_);
    unplugged_ = true;
}

}  // namespace hs
