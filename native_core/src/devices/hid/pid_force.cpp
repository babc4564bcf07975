#include "devices/hid/pid_force.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

namespace {
std::uint8_t reportOf(const HidReportLayout& l, ReportType type, std::uint32_t collection, const char* name) {
    for (const auto& f : l.fields)
        if (f.type == type && f.inCollection(collection)) return f.reportId;
    throw std::invalid_argument(std::string("descriptor: no ") + name + " report (not a HID PID force-feedback device?)");
}
}  // namespace

PidLayout PidLayout::fromDescriptor(const std::vector<std::uint8_t>& descriptor) {
    PidLayout p;
    p.hid = parseReportDescriptor(descriptor);
    p.setEffectId = reportOf(p.hid, ReportType::Output, pid::SetEffect, "Set Effect");
    p.constantId = reportOf(p.hid, ReportType::Output, pid::SetConstantForce, "Set Constant Force");
    p.operationId = reportOf(p.hid, ReportType::Output, pid::EffectOperation, "Effect Operation");
    p.controlId = reportOf(p.hid, ReportType::Output, pid::DeviceControl, "Device Control");
    p.createId = reportOf(p.hid, ReportType::Feature, pid::CreateNewEffect, "Create New Effect");
    p.blockLoadId = reportOf(p.hid, ReportType::Feature, pid::BlockLoad, "Block Load");
    if (!p.hid.find(ReportType::Output, pid::Magnitude, pid::SetConstantForce))
        throw std::invalid_argument("descriptor: Set Constant Force has no Magnitude field");
    int axes = 0;
    for (const auto& f : p.hid.fields)
        if (f.type == ReportType::Output && f.inCollection(pid::AxesEnable) && !f.constant) axes += static_cast<int>(f.count);
    p.axes = std::clamp(axes, 1, 3);
    return p;
}

bool setPidField(const HidReportLayout& l, ReportType type, std::uint8_t id, std::uint32_t u, std::int64_t value,
                 std::vector<std::uint8_t>& report, std::uint32_t collection) {
    const FieldSlot slot = locateField(l, type, id, u, collection);
    if (!slot.field) return false;
    const std::size_t off = l.usesReportIds ? 1 : 0;
    writeField(report.data() + off, report.size() - off, slot.bit, slot.field->size, slot.array ? slot.choice : value);
    return true;
}

PidForceDriver::PidForceDriver(std::shared_ptr<HidTransport> transport, PidSettings settings)
    : transport_(std::move(transport)), settings_(settings) {
    if (!transport_) throw std::invalid_argument("transport: required");
    if (!(settings_.fullScaleForce > 0) || !(settings_.writePeriod > 0))
        throw std::invalid_argument("settings: full_scale_force and write_period must be > 0");
    layout_ = PidLayout::fromDescriptor(transport_->reportDescriptor());
    if (const HidField* m = layout_.hid.find(ReportType::Output, pid::Magnitude, pid::SetConstantForce))
        magnitudeMax_ = std::max<std::int64_t>(1, std::min<std::int64_t>(m->logicalMax, -static_cast<std::int64_t>(m->logicalMin)));
}

PidForceDriver::~PidForceDriver() {
    try {
        stop();
    } catch (...) {  // a destructor must not throw; the device may already be gone
    }
}

void PidForceDriver::start() {
    if (running_.load()) return;
    const auto& l = layout_.hid;
    auto out = [&](std::uint8_t id) {
        std::vector<std::uint8_t> r(std::max<std::size_t>(l.reportBytes(ReportType::Output, id), 2), 0);
        r[0] = id;
        return r;
    };
    auto send = [&](const std::vector<std::uint8_t>& r) {
        if (transport_->write(r.data(), r.size()) < 0) throw std::runtime_error("HID PID: output report write failed");
    };
    std::vector<std::uint8_t> control = out(layout_.controlId);
    setPidField(l, ReportType::Output, layout_.controlId, pid::EnableActuators, 1, control);
    send(control);
    effects_.clear();
    for (int axis = 0; axis < layout_.axes; ++axis) {
        std::vector<std::uint8_t> create(std::max<std::size_t>(l.reportBytes(ReportType::Feature, layout_.createId), 2), 0);
        create[0] = layout_.createId;
        setPidField(l, ReportType::Feature, layout_.createId, pid::EtConstant, 1, create);
        if (transport_->sendFeature(create.data(), create.size()) < 0) throw std::runtime_error("HID PID: Create New Effect failed");
        std::vector<std::uint8_t> load(std::max<std::size_t>(l.reportBytes(ReportType::Feature, layout_.blockLoadId), 3), 0);
        const FieldSlot idx = locateField(l, ReportType::Feature, layout_.blockLoadId, pid::EffectBlockIndex, pid::BlockLoad);
        const FieldSlot status = locateField(l, ReportType::Feature, layout_.blockLoadId, pid::BlockLoadSuccess, pid::BlockLoad);
        if (!idx.field || !status.field) throw std::invalid_argument("descriptor: Block Load lacks its index or status field");
        bool loaded = false;
        std::int64_t block = 0;
        for (int attempt = 0; attempt < 60 && !loaded; ++attempt) {  // as hid-pidff: poll until success
            std::fill(load.begin(), load.end(), 0);
            load[0] = layout_.blockLoadId;
            const int n = transport_->getFeature(load.data(), load.size());
            if (n < 0) throw std::runtime_error("HID PID: Block Load read failed");
            const std::size_t off = l.usesReportIds ? 1 : 0;
            loaded = readField(load.data() + off, load.size() - off, status.bit, status.field->size, false) == status.choice;
            block = readField(load.data() + off, load.size() - off, idx.bit, idx.field->size, false);
            if (!loaded) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        if (!loaded || block <= 0) throw std::runtime_error("HID PID: the device did not load the effect (pool full?)");
        effects_.push_back(static_cast<std::uint8_t>(block));
        std::vector<std::uint8_t> set = out(layout_.setEffectId);
        setPidField(l, ReportType::Output, layout_.setEffectId, pid::EffectBlockIndex, block, set);
        setPidField(l, ReportType::Output, layout_.setEffectId, pid::EtConstant, 1, set);
        if (const HidField* d = l.find(ReportType::Output, pid::Duration, pid::SetEffect))
            setPidField(l, ReportType::Output, layout_.setEffectId, pid::Duration, std::min<std::int64_t>(d->logicalMax, 0xFFFF), set);  // infinite
        if (const HidField* g = l.find(ReportType::Output, pid::Gain, pid::SetEffect))
            setPidField(l, ReportType::Output, layout_.setEffectId, pid::Gain, g->logicalMax, set);
        const std::uint32_t axisUsage = usage(0x01, static_cast<std::uint16_t>(0x30 + axis));
        setPidField(l, ReportType::Output, layout_.setEffectId, axisUsage, 1, set, pid::AxesEnable);
        send(set);
        if (!writeConstant(axis, 0)) throw std::runtime_error("HID PID: Set Constant Force failed");
        std::vector<std::uint8_t> op = out(layout_.operationId);
        setPidField(l, ReportType::Output, layout_.operationId, pid::EffectBlockIndex, block, op);
        setPidField(l, ReportType::Output, layout_.operationId, pid::OpStart, 1, op);
        setPidField(l, ReportType::Output, layout_.operationId, pid::LoopCount, 1, op);
        send(op);
    }
    running_.store(true);
    writer_ = std::thread([this] { writerLoop(); });
}

bool PidForceDriver::writeConstant(int axis, std::int64_t magnitude) {
    const auto& l = layout_.hid;
    std::vector<std::uint8_t> r(std::max<std::size_t>(l.reportBytes(ReportType::Output, layout_.constantId), 2), 0);
    r[0] = layout_.constantId;
    setPidField(l, ReportType::Output, layout_.constantId, pid::EffectBlockIndex, effects_[static_cast<size_t>(axis)], r);
    setPidField(l, ReportType::Output, layout_.constantId, pid::Magnitude, magnitude, r);
    writes_.fetch_add(1, std::memory_order_relaxed);
    return transport_->write(r.data(), r.size()) >= 0;
}

void PidForceDriver::setForce(const Vec3& f) {
    for (int i = 0; i < 3; ++i) force_[i].store(std::isfinite(f[i]) ? f[i] : 0.0, std::memory_order_relaxed);
}

void PidForceDriver::writerLoop() {
    // The only thread that writes magnitudes: a blocking USB write here never stalls the haptic loop.
    std::int64_t last[3] = {0, 0, 0};
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(settings_.writePeriod));
    auto next = std::chrono::steady_clock::now();
    while (running_.load(std::memory_order_acquire)) {
        next += period;
        std::this_thread::sleep_until(next);
        for (int axis = 0; axis < layout_.axes; ++axis) {
            const double x = std::clamp(force_[axis].load(std::memory_order_relaxed) / settings_.fullScaleForce, -1.0, 1.0);
            const auto m = static_cast<std::int64_t>(std::lround(x * static_cast<double>(magnitudeMax_)));
            if (m != last[axis] && writeConstant(axis, m)) last[axis] = m;
        }
    }
}

void PidForceDriver::stop() {
    const bool wasRunning = running_.exchange(false);
    if (writer_.joinable()) writer_.join();
    if (!wasRunning) return;
    const auto& l = layout_.hid;
    for (std::size_t axis = 0; axis < effects_.size(); ++axis) {
        writeConstant(static_cast<int>(axis), 0);
        std::vector<std::uint8_t> op(std::max<std::size_t>(l.reportBytes(ReportType::Output, layout_.operationId), 2), 0);
        op[0] = layout_.operationId;
        setPidField(l, ReportType::Output, layout_.operationId, pid::EffectBlockIndex, effects_[axis], op);
        setPidField(l, ReportType::Output, layout_.operationId, pid::OpStop, 1, op);
        transport_->write(op.data(), op.size());
    }
    for (std::uint32_t u : {pid::StopAllEffects, pid::DisableActuators}) {
        std::vector<std::uint8_t> c(std::max<std::size_t>(l.reportBytes(ReportType::Output, layout_.controlId), 2), 0);
        c[0] = layout_.controlId;
        setPidField(l, ReportType::Output, layout_.controlId, u, 1, c);
        transport_->write(c.data(), c.size());
    }
}

ForceFeedbackDevice::ForceFeedbackDevice(std::shared_ptr<Device> input, std::shared_ptr<PidForceDriver> output,
                                         double maxForce, double maxStiffness)
    : input_(std::move(input)), output_(std::move(output)), maxForce_(maxForce), maxStiffness_(maxStiffness) {
    if (!input_ || !output_) throw std::invalid_argument("input/output: required");
    if (!(maxForce_ > 0) || !(maxStiffness_ > 0)) throw std::invalid_argument("max_force/max_stiffness: must be > 0");
}

DeviceCaps ForceFeedbackDevice::caps() const {
    DeviceCaps c = input_->caps();
    c.forceOutput = true;
    c.maxForce = maxForce_;
    c.maxStiffness = maxStiffness_;
    return c;
}

void ForceFeedbackDevice::start() {
    input_->start();
    output_->start();
}

void ForceFeedbackDevice::stop() {
    output_->stop();
    input_->stop();
}

}  // namespace hs
