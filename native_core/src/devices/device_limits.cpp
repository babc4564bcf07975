#include "devices/device_limits.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "devices/passivity.hpp"

namespace hs {

namespace {
// b = K T / 2 at T = 1 ms for CHAI3D's recommended stiffness K.
constexpr double fromChai3d(double stiffness) { return stiffness * 1e-3 / 2; }
const char* kChai = "CHAI3D device info (max force, recommended stiffness); b = K T / 2 at 1 kHz";

bool prefixOf(const std::string& prefix, const std::string& s) {
    if (prefix.size() > s.size()) return false;
    for (std::size_t i = 0; i < prefix.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(prefix[i])) != std::tolower(static_cast<unsigned char>(s[i]))) return false;
    return true;
}
}  // namespace

const std::vector<DeviceLimits>& deviceLimitsTable() {
    static const std::vector<DeviceLimits> table = {
        {"Novint Falcon", 8.0, fromChai3d(3000), 0.15, {1000, 1000}, kChai},
        {"Touch X", 7.9, fromChai3d(1000), 0.05, {1000, 1000}, kChai},  // the old Phantom Desktop
        {"Phantom Omni", 3.3, fromChai3d(700), 0.045, {1000, 1000}, kChai},
        {"Touch", 3.3, fromChai3d(400), 0.045, {1000, 1000}, kChai},
        {"omega.3", 12.0, fromChai3d(5000), 0.2, {1000, 4000}, kChai},
        {"delta.3", 20.0, fromChai3d(5000), 0.4, {1000, 4000}, kChai},
        {"sigma.7", 20.0, fromChai3d(4000), 0.3, {1000, 4000}, kChai},
        {"lambda.7", 20.0, fromChai3d(8000), 0.3, {1000, 4000}, kChai},
    };
    return table;
}

const DeviceLimits& limitsFor(const std::string& model) {
    const auto& t = deviceLimitsTable();
    const DeviceLimits* best = nullptr;
    for (const DeviceLimits& row : t)  // the longest matching name ("Touch X" before "Touch")
        if (prefixOf(row.model, model) && (!best || row.model.size() > best->model.size())) best = &row;
    if (best) return *best;
    return *std::min_element(t.begin(), t.end(), [](const DeviceLimits& a, const DeviceLimits& b) { return a.damping < b.damping; });
}

double passiveStiffnessFor(const DeviceLimits& limits, double rateHz, double virtualDamping) {
    if (!(rateHz > 0)) throw std::invalid_argument("rate: must be > 0");
    return passiveStiffness(limits.damping, virtualDamping, 1.0 / rateHz);
}

}  // namespace hs
