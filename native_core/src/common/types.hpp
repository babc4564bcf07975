// The types and limits every part of the core shares.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace hs {

using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;  ///< one 3D point per row
using Vec3 = Eigen::Vector3d;

/// Largest coordinate accepted anywhere (poles, cursor, targets): 1e9 (1000 km in mm). Beyond it
/// squared lengths times stiffness leave the double range; nothing real is that large.
constexpr double kMaxCoordinate = 1e9;
/// Largest material value (mass, damping, stiffness per unit area) and smallest non-zero one.
constexpr double kMaxMaterial = 1e12, kMinMaterial = 1e-12;
inline bool withinRange(const Eigen::Ref<const Eigen::MatrixXd>& x) {
    return x.allFinite() && x.cwiseAbs().maxCoeff() <= kMaxCoordinate;
}

/// The core's range checks: each throws std::invalid_argument naming the parameter, so every
/// caller (the Python binding, the runtime, tests) gets the same validation.
inline double requireInRange(double value, const char* name, double lo, double hi) {
    if (!(value >= lo && value <= hi)) {  // (NaN fails)
        char text[160];
        std::snprintf(text, sizeof text, "%s: must be in [%g, %g], got %g", name, lo, hi, value);
        throw std::invalid_argument(text);
    }
    return value;
}
inline int requireInRange(int value, const char* name, int lo, int hi) {
    if (value < lo || value > hi)
        throw std::invalid_argument(std::string(name) + ": must be in " + std::to_string(lo) + ".." +
                                    std::to_string(hi) + ", got " + std::to_string(value));
    return value;
}
/// Finite and > 0 (or >= 0 with `allowZero`).
inline double requirePositive(double value, const char* name, bool allowZero = false) {
    if (!std::isfinite(value) || value < 0 || (!allowZero && value == 0))
        throw std::invalid_argument(std::string(name) + ": must be finite and " + (allowZero ? ">= 0" : "> 0"));
    return value;
}
inline Vec3 requirePoint(const Vec3& x, const char* name) {
    if (!withinRange(x)) throw std::invalid_argument(std::string(name) + ": must be finite and within +-1e9");
    return x;
}

}  // namespace hs
