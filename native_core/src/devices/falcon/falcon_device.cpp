#include "devices/falcon/falcon_device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "devices/device_limits.hpp"

namespace hs {

namespace {
constexpr double kCentreZ = 0.11;  // m: the middle of the workspace along the device's z
// The device's frame (x right, y up, z towards the user) to the document's seen from the front
// (x right, z up, y away from the user): a rotation.
falcon::Vec3d toDocument(const falcon::Vec3d& v) { return falcon::Vec3d(v.x(), -v.z(), v.y()); }
falcon::Vec3d toDevice(const Vec3& v) { return falcon::Vec3d(v.x(), v.z(), -v.y()); }
}  // namespace

void FalconSettings::validate() const {
    mapping.validate();
    requirePositive(countsPerNewtonMetre, "counts_per_newton_metre");
    requirePositive(maxForce, "max_force");
    requireInRange(homingTimeout, "homing_timeout", 0.01, 600.0);
    requireInRange(readTimeout, "read_timeout", 0.0, 0.1);
    requireInRange(rateHz, "rate", 100.0, 10000.0);
}

FalconDevice::FalconDevice(std::shared_ptr<falcon::Transport> transport, FalconSettings settings)
    : transport_(std::move(transport)), settings_(settings) {
    if (!transport_) throw std::invalid_argument("transport: none given");
    settings_.validate();
}

DeviceCaps FalconDevice::caps() const {
    DeviceCaps c;
    c.dof = 3;
    c.forceOutput = true;
    c.rateHz = settings_.rateHz;
    c.maxForce = settings_.mapping.sessionForce(settings_.maxForce);
    c.maxStiffness = settings_.mapping.sessionStiffness(passiveStiffnessFor(limitsFor("Novint Falcon"), settings_.rateHz));
    return c;
}

bool FalconDevice::exchange(const falcon::Command& command, double timeout, falcon::Status& status) {
    const falcon::Frame frame = falcon::encodeCommand(command);
    if (!transport_->write(frame.data(), frame.size())) {
        lost_ = true;
        return false;
    }
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
    bool got = false;
    do {
        const double left = std::chrono::duration<double>(end - std::chrono::steady_clock::now()).count();
        const long n = transport_->read(buffer_.data(), buffer_.size(), std::max(0.0, left));
        if (n < 0) {
            lost_ = true;
            return false;
        }
        if (n > 0 && reader_.feed(buffer_.data(), static_cast<std::size_t>(n)) > 0) got = reader_.latest(status);
    } while (!got && std::chrono::steady_clock::now() < end);
    skipped_.store(reader_.skippedBytes(), std::memory_order_relaxed);
    return got;
}

void FalconDevice::start() {
    falcon::Command homing;
    homing.homing = true;
    homing.leds = falcon::kRedLed;
    falcon::Status status;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(settings_.homingTimeout);
    while (true) {
        if (exchange(homing, 0.01, status) && status.allHomed()) break;
        if (lost_) throw std::runtime_error("Falcon: the device stopped answering (unplugged, or its firmware is not loaded)");
        if (std::chrono::steady_clock::now() > end)
            throw std::runtime_error("Falcon: not homed within " + std::to_string(settings_.homingTimeout) +
                                     " s: move the grip slowly all the way in and out until the LED turns green");
    }
    command_ = falcon::Command{};
    command_.leds = falcon::kGreenLed;
    positioned_ = false;
}

void FalconDevice::stop() {
    if (lost_) return;
    falcon::Command idle;
    idle.leds = falcon::kBlueLed;
    falcon::Status status;
    exchange(idle, settings_.readTimeout, status);
}

bool FalconDevice::sample(double, DeviceSample& out) {
    if (lost_) return false;
    falcon::Status status;
    if (exchange(command_, settings_.readTimeout, status)) {
        frames_.fetch_add(1, std::memory_order_relaxed);
        falcon::Vec3d motor;
        for (int i = 0; i < 3; ++i) motor[i] = falcon::angleOfCount(status.encoder[static_cast<std::size_t>(i)]);
        falcon::Vec3d tip;
        if (falcon::forwardKinematics(motor, tip_, tip)) {
            tip_ = tip;
            positioned_ = true;
        }
        buttons_ = status.buttons;
    } else {
        if (lost_) return false;
        missed_.fetch_add(1, std::memory_order_relaxed);
    }
    out.position = settings_.mapping.position(1000.0 * toDocument(tip_ - falcon::Vec3d(0, 0, kCentreZ)));
    out.orientation = Eigen::Quaterniond::Identity();
    out.buttons = buttons_;
    out.valid = positioned_;
    return true;
}

void FalconDevice::setForce(const Vec3& force) {
    Vec3 f = force.allFinite() ? settings_.mapping.newtons(force) : Vec3::Zero();
    if (f.norm() > settings_.maxForce) f *= settings_.maxForce / f.norm();
    falcon::Vec3d torques;
    if (!positioned_ || !falcon::motorTorques(tip_, toDevice(f), torques)) torques.setZero();
    // counts: the torques scaled (the firmware's sign), all by the same factor if one would
    // overflow, so the force keeps its direction
    falcon::Vec3d counts = -settings_.countsPerNewtonMetre * torques;
    const double largest = counts.cwiseAbs().maxCoeff();
    if (largest > 32767.0) counts *= 32767.0 / largest;
    for (int i = 0; i < 3; ++i) command_.motor[static_cast<std::size_t>(i)] = static_cast<std::int16_t>(std::lround(counts[i]));
}

}  // namespace hs
