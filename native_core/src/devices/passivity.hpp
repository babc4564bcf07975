// How stiff a device can render a virtual spring and stay passive (Colgate & Schenkel 1997): a
// spring K with damping B, sampled and held every T seconds on a device whose mechanism damps
// with b, is passive when b > K T / 2 + |B|, so K <= 2 (b - |B|) / T. And the check that the bound
// is real: the device as a mass with damping, coupled to the sampled spring, started displaced.
#pragma once

namespace hs {

/// The largest passive stiffness (force per length) for device damping b, virtual damping B and
/// period T (consistent units); 0 when |B| >= b. std::invalid_argument for b < 0, T <= 0 or a
/// value that is not finite.
double passiveStiffness(double deviceDamping, double virtualDamping, double period);

/// A device of mass m and damping b held by a spring K with damping B that is sampled every T and
/// held in between (what a haptic loop renders), released from rest 1 unit away: its energy
/// (kinetic + the spring's) after `seconds`, over the energy at the start. Below 1: the wall took
/// energy out; growing: it puts energy in. Exact between samples (the mass-damper's closed form).
double sampledWallEnergyRatio(double mass, double deviceDamping, double stiffness, double virtualDamping,
                              double period, double seconds);

}  // namespace hs
