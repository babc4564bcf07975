#include "geometry/bspline_surface.hpp"

#include <cmath>
#include <stdexcept>

namespace hs {

BSplineSurface::BSplineSurface(int nu, int nv, int degreeU, int degreeV, std::vector<double> knotsU,
                               std::vector<double> knotsV, Points poles, Eigen::VectorXd weights)
    : ku_(std::move(knotsU), nu, degreeU, "knots_u"), kv_(std::move(knotsV), nv, degreeV, "knots_v"),
      poles_(std::move(poles)), weights_(std::move(weights)) {
    if (poles_.rows() != static_cast<Eigen::Index>(nu) * nv)
        throw std::invalid_argument("poles: expected " + std::to_string(nu * nv) + " rows (nu*nv), got " +
                                    std::to_string(poles_.rows()));
    if (poles_.size() && !withinRange(poles_)) throw std::invalid_argument("poles: must be finite and within +-1e9");
    if (weights_.size() != 0) {
        if (weights_.size() != poles_.rows())
            throw std::invalid_argument("weights: expected " + std::to_string(poles_.rows()) + " values, got " +
                                        std::to_string(weights_.size()));
        if (!weights_.allFinite() || (weights_.array() <= 0).any())
            throw std::invalid_argument("weights: must be finite and > 0");
    }
}

void BSplineSurface::checkGridSize(int nu, int nv) {
    requireInRange(nu, "nu", 2, kMaxGrid);
    requireInRange(nv, "nv", 2, kMaxGrid);
}

void BSplineSurface::grid(int nu, int nv, double* points, double* normals) const {
    checkGridSize(nu, nv);
    const double u0 = ku_.domainStart(), u1 = ku_.domainEnd(), v0 = kv_.domainStart(), v1 = kv_.domainEnd();
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
            const double u = u0 + (u1 - u0) * i / (nu - 1), v = v0 + (v1 - v0) * j / (nv - 1);
            const Vec3 p = evaluate(u, v, 1).s, n = normal(u, v);
            const std::size_t k = 3 * (static_cast<std::size_t>(i) * nv + j);
            for (int c = 0; c < 3; ++c) {
                points[k + c] = p[c];
                normals[k + c] = n[c];
            }
        }
}

BSplineSurface BSplineSurface::plane(int nu, int nv, int degreeU, int degreeV, double sx, double sy) {
    if (!(std::isfinite(sx) && std::isfinite(sy) && sx > 0 && sy > 0))
        throw std::invalid_argument("size: must be finite and > 0");
    auto ku = clampedUniformKnots(nu, degreeU);
    auto kv = clampedUniformKnots(nv, degreeV);
    Points poles(nu * nv, 3);
    // Greville abscissae place the poles so the parametrisation is uniform (linear precision).
    auto greville = [](const std::vector<double>& k, int i, int p) {
        double s = 0;
        for (int t = 1; t <= p; ++t) s += k[i + t];
        return s / p;
    };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j)
            poles.row(i * nv + j) << (greville(ku, i, degreeU) - 0.5) * sx, (greville(kv, j, degreeV) - 0.5) * sy, 0.0;
    return BSplineSurface(nu, nv, degreeU, degreeV, std::move(ku), std::move(kv), std::move(poles), {});
}

SurfaceDerivatives BSplineSurface::evaluate(double u, double v, int order) const {
    SurfaceDerivatives d{};
    d.s.setZero(); d.su.setZero(); d.sv.setZero(); d.suu.setZero(); d.suv.setZero(); d.svv.setZero();
    visitBasis(u, v, order, [&](int idx, double R, double Ru, double Rv, double Ruu, double Ruv, double Rvv) {
        const Vec3 P = poles_.row(idx).transpose();
        d.s += R * P; d.su += Ru * P; d.sv += Rv * P;
        d.suu += Ruu * P; d.suv += Ruv * P; d.svv += Rvv * P;
    });
    return d;
}

Vec3 BSplineSurface::normal(double u, double v) const {
    const auto d = evaluate(u, v, 1);
    const Vec3 n = d.su.cross(d.sv);
    const double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

Curvature curvatureFrom(const SurfaceDerivatives& d) {
    Curvature c;
    const Vec3 nn = d.su.cross(d.sv);
    const double len = nn.norm();
    const double E = d.su.dot(d.su), F = d.su.dot(d.sv), G = d.sv.dot(d.sv);
    const double det = E * G - F * F;
    if (!(len > 0) || !(det > 0) || !(E > 0) || !(G > 0)) return c;
    const Vec3 n = nn / len;
    const double L = d.suu.dot(n), M = d.suv.dot(n), N = d.svv.dot(n);
    c.ku = L / E;
    c.kv = N / G;
    c.gauss = (L * N - M * M) / det;
    c.mean = (E * N - 2 * F * M + G * L) / (2 * det);
    const double disc = std::sqrt(std::max(0.0, c.mean * c.mean - c.gauss));
    c.kmin = c.mean - disc;
    c.kmax = c.mean + disc;
    return c;
}

}  // namespace hs
