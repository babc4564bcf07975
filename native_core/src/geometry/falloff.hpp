// Radial weight profiles shared by the magnet tool and the airbrush.
#pragma once
#include "common/names.hpp"
#include <algorithm>
#include <cmath>

namespace hs {

/// constant: 1; spherical: sqrt(1 - s^2) (a hemisphere); conical: 1 - s (a cone);
/// cylindrical: 1, with distance measured to the cursor axis instead of the cursor point.
enum class Falloff { Constant, Spherical, Cylindrical, Conical };

inline constexpr std::array<Named<Falloff>, 4> kFalloffNames{{
    {"constant", Falloff::Constant}, {"spherical", Falloff::Spherical}, {"cylindrical", Falloff::Cylindrical},
    {"conical", Falloff::Conical}}};

/// Weight at normalised distance s = r / radius; zero outside the radius.
inline double falloffWeight(Falloff f, double s) {
    if (!(s <= 1.0)) return 0.0;
    s = std::max(0.0, s);
    switch (f) {
        case Falloff::Spherical: return std::sqrt(std::max(0.0, 1.0 - s * s));
        case Falloff::Conical: return 1.0 - s;
        case Falloff::Constant:
        case Falloff::Cylindrical: return 1.0;
    }
    return 0.0;
}

}  // namespace hs
