#include "devices/passivity.hpp"

#include <cmath>
#include <stdexcept>

namespace hs {

double passiveStiffness(double b, double B, double T) {
    if (!std::isfinite(b) || !std::isfinite(B) || !std::isfinite(T) || b < 0 || !(T > 0))
        throw std::invalid_argument("passivity: device damping >= 0, virtual damping finite and period > 0");
    return std::abs(B) >= b ? 0.0 : 2.0 * (b - std::abs(B)) / T;
}

double sampledWallEnergyRatio(double m, double b, double K, double B, double T, double seconds) {
    if (!(m > 0) || !(b > 0) || !(K >= 0) || !std::isfinite(B) || !(T > 0) || !(seconds > 0))
        throw std::invalid_argument("sampled wall: mass, device damping and period > 0, stiffness >= 0");
    double x = 1.0, v = 0.0, xPrev = 1.0;
    const double decay = std::exp(-b * T / m);
    const double e0 = 0.5 * K * x * x;
    const long steps = std::lround(seconds / T);
    for (long k = 0; k < steps; ++k) {
        // the force the loop computes from this sample (velocity by backward difference), held over T
        const double f = -K * x - B * (x - xPrev) / T;
        xPrev = x;
        // m v' = f - b v with f constant: v -> f / b exponentially
        const double vInf = f / b;
        x += vInf * T + (v - vInf) * (m / b) * (1.0 - decay);
        v = vInf + (v - vInf) * decay;
        if (!std::isfinite(x) || std::abs(x) > 1e150) return INFINITY;
    }
    return (0.5 * m * v * v + 0.5 * K * x * x) / e0;
}

}  // namespace hs
