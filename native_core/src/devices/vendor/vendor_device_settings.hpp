// Settings shared by the devices behind a vendor's library (OpenHaptics, Force Dimension DHD).
#pragma once
#include <string>
#include <vector>

#include "devices/device_mapping.hpp"

namespace hs {

struct VendorDeviceSettings {
    DeviceMapping mapping;
    /// Library names or paths tried in order (empty: the vendor's usual names).
    std::vector<std::string> library;
    /// The haptic loop's rate (Hz) the passivity bound is taken at: the servo rate for OpenHaptics
    /// (its scheduler), the session's haptic rate for DHD (it is polled).
    double rateHz = kDefaultHapticRate;
    double maxForce = 0;        ///< N; 0: the device's rating (device_limits.hpp)
    double staleAfter = 0.1;    ///< s without a servo frame before the device counts as lost
    void validate() const {
        mapping.validate();
        requireInRange(rateHz, "rate", 100.0, 10000.0);
        requirePositive(maxForce, "max_force", true);
        requireInRange(staleAfter, "stale_after", 0.005, 10.0);
    }
};

/// What devices.list() learns about a vendor's devices without keeping one open.
struct VendorProbe {
    bool loaded = false;     ///< the vendor's library loaded
    std::string library;     ///< which one
    int attached = 0;        ///< devices found (OpenHaptics: 0 or 1, its default device)
    std::string model;       ///< the first one's model, where the library names it
    std::string why;         ///< why none is usable ("" when one is)
};

}  // namespace hs
