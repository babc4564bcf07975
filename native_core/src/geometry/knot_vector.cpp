#include "geometry/knot_vector.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hs {

std::vector<double> clampedUniformKnots(int count, int degree, const char* countName) {
    if (degree < 1 || degree > kMaxDegree)
        throw std::invalid_argument("degree: must be in 1.." + std::to_string(kMaxDegree) + ", got " + std::to_string(degree));
    if (count < degree + 1)
        throw std::invalid_argument(std::string(countName) + ": need at least degree+1 = " + std::to_string(degree + 1) +
                                    " control points in each direction, got " + std::to_string(count));
    std::vector<double> k(static_cast<size_t>(count + degree + 1));
    const int inner = count - degree;  // number of spans
    for (int i = 0; i < static_cast<int>(k.size()); ++i) {
        if (i <= degree)
            k[i] = 0.0;
        else if (i >= count)
            k[i] = 1.0;
        else
            k[i] = static_cast<double>(i - degree) / inner;
    }
    return k;
}

void validateKnots(const std::vector<double>& knots, int count, int degree, const std::string& name) {
    if (degree < 1 || degree > kMaxDegree)
        throw std::invalid_argument(name + ": degree " + std::to_string(degree) + " is outside 1.." +
                                    std::to_string(kMaxDegree));
    if (count < degree + 1)
        throw std::invalid_argument(name + ": " + std::to_string(count) +
                                    " control points are fewer than degree+1 = " + std::to_string(degree + 1));
    const size_t expected = static_cast<size_t>(count + degree + 1);
    if (knots.size() != expected)
        throw std::invalid_argument(name + ": expected " + std::to_string(expected) + " knots (controls+degree+1), got " +
                                    std::to_string(knots.size()));
    for (size_t i = 0; i < knots.size(); ++i) {
        if (!std::isfinite(knots[i])) throw std::invalid_argument(name + ": knot " + std::to_string(i) + " is not finite");
        if (i > 0 && knots[i] < knots[i - 1])
            throw std::invalid_argument(name + ": knots must be non-decreasing (knot " + std::to_string(i) + ")");
    }
    // Multiplicity of interior knots (those strictly inside the domain) must not exceed the degree,
    // else the surface would be discontinuous; end knots may reach degree+1 (clamped).
    const double a = knots[static_cast<size_t>(degree)], b = knots[static_cast<size_t>(count)];
    if (!(b > a)) throw std::invalid_argument(name + ": the parametric domain is empty");
    size_t i = 0;
    while (i < knots.size()) {
        size_t j = i;
        while (j + 1 < knots.size() && knots[j + 1] == knots[i]) ++j;
        const int mult = static_cast<int>(j - i + 1);
        const bool interior = knots[i] > a && knots[i] < b;
        if ((interior && mult > degree) || mult > degree + 1)
            throw std::invalid_argument(name + ": knot value " + std::to_string(knots[i]) + " has multiplicity " +
                                        std::to_string(mult) + " > degree " + std::to_string(degree));
        i = j + 1;
    }
}

KnotVector::KnotVector(std::vector<double> knots, int count, int degree, const std::string& name)
    : knots_(std::move(knots)), count_(count), degree_(degree) {
    validateKnots(knots_, count_, degree_, name);
}

int KnotVector::span(double t) const {
    const int n = count_ - 1;
    if (t >= knots_[n + 1]) {
        // Last non-empty span (handles clamped ends with repeated knots).
        int s = n;
        while (s > degree_ && knots_[s] >= knots_[n + 1]) --s;
        return s;
    }
    if (t <= knots_[degree_]) {
        int s = degree_;
        while (s < n && knots_[s + 1] <= knots_[degree_]) ++s;
        return s;
    }
    // Binary search: knots_[s] <= t < knots_[s+1].
    const auto it = std::upper_bound(knots_.begin() + degree_, knots_.begin() + n + 2, t);
    return static_cast<int>(it - knots_.begin()) - 1;
}

int KnotVector::basis(double t, int nd, Eigen::Matrix<double, 3, kMaxDegree + 1>& ders) const {
    const int p = degree_;
    t = std::clamp(t, domainStart(), domainEnd());
    const int s = span(t);
    // A2.3: triangular table of basis functions and knot differences.
    double ndu[kMaxDegree + 1][kMaxDegree + 1];
    double left[kMaxDegree + 1], right[kMaxDegree + 1];
    ndu[0][0] = 1.0;
    for (int j = 1; j <= p; ++j) {
        left[j] = t - knots_[s + 1 - j];
        right[j] = knots_[s + j] - t;
        double saved = 0.0;
        for (int r = 0; r < j; ++r) {
            ndu[j][r] = right[r + 1] + left[j - r];
            const double temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    ders.setZero();
    for (int j = 0; j <= p; ++j) ders(0, j) = ndu[j][p];
    nd = std::min(nd, std::min(p, 2));
    double a[2][kMaxDegree + 1];
    for (int r = 0; r <= p; ++r) {
        int s1 = 0, s2 = 1;
        a[0][0] = 1.0;
        for (int k = 1; k <= nd; ++k) {
            double d = 0.0;
            const int rk = r - k, pk = p - k;
            if (r >= k) {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            const int j1 = (rk >= -1) ? 1 : -rk;
            const int j2 = (r - 1 <= pk) ? k - 1 : p - r;
            for (int j = j1; j <= j2; ++j) {
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
                d += a[s2][j] * ndu[rk + j][pk];
            }
            if (r <= pk) {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders(k, r) = d;
            std::swap(s1, s2);
        }
    }
    double factor = p;
    for (int k = 1; k <= nd; ++k) {
        for (int j = 0; j <= p; ++j) ders(k, j) *= factor;
        factor *= (p - k);
    }
    return s;
}

}  // namespace hs
