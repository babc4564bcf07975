// Each force device's limits in one table: its rated force and the stiffest spring it renders
// passively (Colgate & Schenkel: K <= 2 (b - |B|) / T, passivity.hpp), from its mechanism's
// damping b. No vendor publishes b, so it is derived here from the stiffness CHAI3D recommends for
// the device (cHapticDeviceInfo m_maxLinearStiffness), taken as the passivity bound at CHAI3D's
// 1 kHz servo rate: b = K_chai T / 2. What the table adds over CHAI3D's figure is how the bound
// moves with the servo rate and with virtual damping. The Falcon's rows are also checked against
// the emulated Falcon (mass 0.15 kg, b 2 N s/m) in test_passivity.
#pragma once
#include <string>
#include <vector>

namespace hs {

struct DeviceLimits {
    std::string model;
    double ratedForce;        ///< N: CHAI3D's m_maxLinearForce
    double damping;           ///< N s/m: b, derived as above
    double mass;              ///< kg at the grip: an order of magnitude, for the closed-loop check only
                              ///< (the bound does not depend on it)
    double servoRates[2];     ///< Hz: its usual rate and the fastest it allows (equal if one)
    std::string source;       ///< where the numbers come from
};

/// The table (README "Force devices"); rows are matched by model name, see limitsFor.
const std::vector<DeviceLimits>& deviceLimitsTable();
/// The row whose model name is a case-insensitive prefix of `model` (e.g. "Touch X" matches
/// "Touch X"), else the most conservative row (the smallest damping), so an unknown device is
/// rendered softly rather than unstably.
const DeviceLimits& limitsFor(const std::string& model);
/// The passive stiffness bound (N/m) for the row at `rateHz` with virtual damping B (N s/m).
double passiveStiffnessFor(const DeviceLimits& limits, double rateHz, double virtualDamping = 0.0);

}  // namespace hs
