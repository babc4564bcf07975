#include "devices/hid/spacemouse.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hs {

const std::vector<SpaceMouseModel>& spaceMouseModels() {
    static const std::vector<SpaceMouseModel> models = {
        {0x046d, 0xc603, "SpaceMouse Plus XT"},     {0x046d, 0xc625, "SpacePilot"},
        {0x046d, 0xc626, "SpaceNavigator"},         {0x046d, 0xc627, "SpaceExplorer"},
        {0x046d, 0xc628, "SpaceNavigator for Notebooks"}, {0x046d, 0xc629, "SpacePilot Pro"},
        {0x046d, 0xc62b, "SpaceMouse Pro"},         {0x256f, 0xc62e, "SpaceMouse Wireless (cable)"},
        {0x256f, 0xc62f, "SpaceMouse Wireless (receiver)"}, {0x256f, 0xc631, "SpaceMouse Pro Wireless (cable)"},
        {0x256f, 0xc632, "SpaceMouse Pro Wireless (receiver)"}, {0x256f, 0xc633, "SpaceMouse Enterprise"},
        {0x256f, 0xc635, "SpaceMouse Compact"},     {0x256f, 0xc636, "SpaceMouse Module"},
        {0x256f, 0xc638, "SpaceMouse Pro Wireless (Bluetooth)"}, {0x256f, 0xc63a, "SpaceMouse Wireless (new)"},
        {0x256f, 0xc652, "3Dconnexion Universal Receiver"},
    };
    return models;
}

const SpaceMouseModel* findSpaceMouse(std::uint16_t vid, std::uint16_t pid) {
    for (const auto& m : spaceMouseModels())
        if (m.vendorId == vid && m.productId == pid) return &m;
    return nullptr;
}

namespace {
std::int16_t le16(const std::uint8_t* p) { return static_cast<std::int16_t>(p[0] | (p[1] << 8)); }
}  // namespace

bool SpaceMouseParser::feed(const std::uint8_t* r, std::size_t n) {
    if (n == 0 || r == nullptr) {
        ++state_.malformed;
        return false;
    }
    const std::uint8_t id = r[0];
    SpaceMouseState before = state_;
    switch (id) {
        case 0x01:
            if (n >= 13) {  // combined: all six axes
                for (int k = 0; k < 6; ++k) state_.axes[k] = le16(r + 1 + 2 * k);
                state_.combinedLayout = true;
            } else if (n >= 7) {
                for (int k = 0; k < 3; ++k) state_.axes[k] = le16(r + 1 + 2 * k);
            } else {
                ++state_.malformed;
                return false;
            }
            break;
        case 0x02:
            if (n < 7) {
                ++state_.malformed;
                return false;
            }
            for (int k = 0; k < 3; ++k) state_.axes[3 + k] = le16(r + 1 + 2 * k);
            break;
        case 0x03: {
            if (n < 2) {
                ++state_.malformed;
                return false;
            }
            std::uint32_t b = 0;
            for (std::size_t k = 1; k < std::min<std::size_t>(n, 5); ++k) b |= std::uint32_t(r[k]) << (8 * (k - 1));
            reportButtons_ = b;
            state_.buttons = reportButtons_ | enterpriseButtons_;
            break;
        }
        case 0x1c:
        case 0x1d: {  // Enterprise keys: keycode = b1 << 1 | (id & 1); a zero b1 releases them
            if (n < 2) {
                ++state_.malformed;
                return false;
            }
            if (r[1] == 0) enterpriseButtons_ = 0;
            else enterpriseButtons_ |= 1u << (((unsigned(r[1]) << 1) | (id & 1u)) % 32);
            state_.buttons = reportButtons_ | enterpriseButtons_;
            break;
        }
        case 0x17:  // battery level (wireless): known, not used
            ++state_.ignored;
            ++state_.reports;
            return false;
        default:
            ++state_.unknown;
            return false;
    }
    ++state_.reports;
    return !std::equal(before.axes, before.axes + 6, state_.axes) || before.buttons != state_.buttons;
}

void hidToFreeCAD(const std::int16_t a[6], double fullScale, double out[6]) {
    const double sign[6] = {1, -1, -1, 1, -1, -1};
    for (int k = 0; k < 6; ++k) out[k] = std::clamp(sign[k] * a[k] / fullScale, -1.0, 1.0);
}

SpaceMouseDevice::SpaceMouseDevice(std::unique_ptr<HidTransport> transport, SpaceMouseSettings settings)
    : transport_(std::move(transport)), settings_(settings), position_(settings.origin) {
    if (!transport_) throw std::invalid_argument("transport: required");
    if (!(settings_.fullScale > 0) || !(settings_.deadZone >= 0 && settings_.deadZone < 1) ||
        !std::isfinite(settings_.translationScale) || !std::isfinite(settings_.rotationScale) || !settings_.origin.allFinite())
        throw std::invalid_argument("settings: full_scale > 0, 0 <= dead_zone < 1, finite scales and origin");
    info_ = transport_->info();
}

SpaceMouseDevice::~SpaceMouseDevice() { stop(); }

std::string SpaceMouseDevice::name() const {
    const SpaceMouseModel* m = findSpaceMouse(info_.vendorId, info_.productId);
    return m ? m->name : (info_.name.empty() ? "SpaceMouse" : info_.name);
}

void SpaceMouseDevice::start() {
    if (running_.exchange(true)) return;
    lost_.store(false);
    io_ = std::thread([this] { ioLoop(); });
}

void SpaceMouseDevice::stop() {
    running_.store(false);
    if (io_.joinable()) io_.join();
}

void SpaceMouseDevice::ioLoop() {
    SpaceMouseParser parser;
    std::uint8_t buf[64];  // hidraw truncates a report longer than the buffer: read 64
    while (running_.load(std::memory_order_acquire)) {
        const int n = transport_->read(buf, sizeof buf, 10);
        if (n < 0) {
            lost_.store(true, std::memory_order_release);
            break;
        }
        if (n > 0) {
            parser.feed(buf, static_cast<std::size_t>(n));
            published_.write(parser.state());
        }
    }
}

SpaceMouseState SpaceMouseDevice::state() {
    published_.update();
    return published_.front();
}

bool SpaceMouseDevice::sample(double t, DeviceSample& out) {
    if (lost_.load(std::memory_order_acquire)) return false;
    published_.update();
    const SpaceMouseState& s = published_.front();
    double v[6];
    hidToFreeCAD(s.axes, settings_.fullScale, v);
    const double dz = settings_.deadZone;
    for (double& x : v) x = std::abs(x) <= dz ? 0.0 : std::copysign((std::abs(x) - dz) / (1 - dz), x);
    const Vec3 move(v[0], v[1], v[2]), turn(v[3], v[4], v[5]);
    if (settings_.mode == SpaceMouseSettings::Mode::Rate) {
        const double dt = lastT_ < 0 ? 0.0 : std::clamp(t - lastT_, 0.0, 0.1);  // zero-order hold
        position_ += dt * settings_.translationScale * move;
        const Vec3 w = dt * settings_.rotationScale * turn;
        if (w.norm() > 0) orientation_ = (Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized())) * orientation_).normalized();
        out.position = position_;
        out.orientation = orientation_;
    } else {
        out.position = settings_.origin + settings_.translationScale * move;
        const Vec3 w = settings_.rotationScale * turn;
        out.orientation = w.norm() > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(w.norm(), w.normalized()))
                                       : Eigen::Quaterniond::Identity();
    }
    lastT_ = t;
    out.buttons = s.buttons;
    out.valid = true;
    return true;
}

}  // namespace hs
