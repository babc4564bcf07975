// Non-linear response laws for spring stiffness and mass-point damping.
#pragma once
#include "common/names.hpp"
#include <cmath>

#include "common/types.hpp"

namespace hs {

/// g(x) maps a linear response x to the actual one; `scale` is the characteristic value s:
/// linear g = x; cubic hardening g = x + x^3 / s^2; saturating g = s tanh(x / s).
enum class LawKind { Linear, CubicHardening, Saturating };

inline constexpr std::array<Named<LawKind>, 3> kLawNames{{
    {"linear", LawKind::Linear}, {"cubic", LawKind::CubicHardening}, {"saturating", LawKind::Saturating}}};

struct ResponseLaw {
    LawKind kind = LawKind::Linear;
    double scale = 1.0;

    double value(double x) const {
        switch (kind) {
            case LawKind::CubicHardening: return x + x * x * x / (scale * scale);
            case LawKind::Saturating: return scale * std::tanh(x / scale);
            case LawKind::Linear: break;
        }
        return x;
    }
    double slope(double x) const {
        switch (kind) {
            case LawKind::CubicHardening: return 1 + 3 * x * x / (scale * scale);
            case LawKind::Saturating: { const double c = 1 / std::cosh(x / scale); return c * c; }
            case LawKind::Linear: break;
        }
        return 1.0;
    }
    /// Energy of a spring whose force is g(k e), as a function of extension e.
    double energy(double k, double e) const {
        const double x = k * e;
        switch (kind) {
            case LawKind::CubicHardening: return 0.5 * k * e * e + x * x * x * x / (4 * k * scale * scale);
            case LawKind::Saturating: {
                // s^2/k * log cosh(x/s), written to stay finite for large |x/s|.
                const double a = std::abs(x / scale);
                return scale * scale / k * (a + std::log1p(std::exp(-2 * a)) - std::log(2.0));
            }
            case LawKind::Linear: break;
        }
        return 0.5 * k * e * e;
    }
    /// Damping multiplier for a point whose spring force magnitude is f: g(f) / f (1 at f = 0).
    double dampingFactor(double f) const {
        if (kind == LawKind::Linear || f <= 0) return 1.0;
        return value(f) / f;
    }
    /// Throws std::invalid_argument unless the scale is in [1e-12, 1e12].
    void validate() const { requireInRange(scale, "scale", 1e-12, 1e12); }
};

}  // namespace hs
