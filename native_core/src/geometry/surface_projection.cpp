#include "geometry/surface_projection.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace hs {

namespace {

// Parameters k per distinct knot span, both domain ends included.
std::vector<double> sampleParameters(const KnotVector& knots, int k) {
    const auto& t = knots.knots();
    std::vector<double> out;
    for (int i = knots.degree(); i < knots.count(); ++i) {
        if (!(t[i + 1] > t[i])) continue;
        for (int s = 0; s < k; ++s) out.push_back(t[i] + (t[i + 1] - t[i]) * s / k);
    }
    out.push_back(knots.domainEnd());
    return out;
}

Points gridPoints(const BSplineSurface& s, const std::vector<double>& us, const std::vector<double>& vs) {
    Points p(static_cast<Eigen::Index>(us.size() * vs.size()), 3);
    Eigen::Index row = 0;
    for (double u : us)
        for (double v : vs) p.row(row++) = s.evaluate(u, v, 0).s.transpose();
    return p;
}

constexpr int kMaxIterations = 30;

}  // namespace

SurfaceProjection::SurfaceProjection(BSplineSurface surface, int samplesPerSpan)
    : surface_(std::move(surface)),
      startU_(sampleParameters(surface_.knotsU(), requireInRange(samplesPerSpan, "samples_per_span", 1, 64))),
      startV_(sampleParameters(surface_.knotsV(), samplesPerSpan)),
      samples_(gridPoints(surface_, startU_, startV_), "surface samples") {}

SurfaceFoot SurfaceProjection::project(const Vec3& x) const {
    double d2 = 0;
    const Eigen::Index k = samples_.nearest(x, d2);
    const Eigen::Index nv = static_cast<Eigen::Index>(startV_.size());
    return descend(x, startU_[k / nv], startV_[k % nv]);
}

SurfaceFoot SurfaceProjection::project(const Vec3& x, double u, double v) const {
    if (!std::isfinite(u) || !std::isfinite(v)) return project(x);
    const SurfaceFoot warm = descend(x, u, v);
    double d2 = 0;
    const Eigen::Index k = samples_.nearest(x, d2);
    if (warm.distance * warm.distance <= d2) return warm;
    const Eigen::Index nv = static_cast<Eigen::Index>(startV_.size());
    const SurfaceFoot cold = descend(x, startU_[k / nv], startV_[k % nv]);
    return std::abs(cold.distance) < std::abs(warm.distance) ? cold : warm;
}

SurfaceFoot SurfaceProjection::descend(const Vec3& x, double u, double v) const {
    const double u0 = surface_.knotsU().domainStart(), u1 = surface_.knotsU().domainEnd();
    const double v0 = surface_.knotsV().domainStart(), v1 = surface_.knotsV().domainEnd();
    u = std::clamp(u, u0, u1), v = std::clamp(v, v0, v1);
    SurfaceDerivatives d = surface_.evaluate(u, v, 2);
    double f = (d.s - x).squaredNorm();
    // Newton on f(u, v) = |S - x|^2 / 2 with the domain's bounds as an active set; a step that
    // does not lower f is halved, so f never rises.
    for (int it = 0; it < kMaxIterations; ++it) {
        const Vec3 r = d.s - x;
        const Eigen::Vector2d g(d.su.dot(r), d.sv.dot(r));
        Eigen::Matrix2d H;
        H << d.su.dot(d.su) + d.suu.dot(r), d.su.dot(d.sv) + d.suv.dot(r), d.su.dot(d.sv) + d.suv.dot(r),
            d.sv.dot(d.sv) + d.svv.dot(r);
        if (!(H.determinant() > 0) || !(H(0, 0) > 0))  // not convex here: Gauss-Newton
            H << d.su.dot(d.su), d.su.dot(d.sv), d.su.dot(d.sv), d.sv.dot(d.sv);
        // Bounds the step would cross stay put (their gradient points out of the domain).
        const bool fixU = (u <= u0 && g[0] > 0) || (u >= u1 && g[0] < 0);
        const bool fixV = (v <= v0 && g[1] > 0) || (v >= v1 && g[1] < 0);
        Eigen::Vector2d step(0, 0);
        if (!fixU && !fixV && H.determinant() > 0) step = -H.inverse() * g;
        else if (!fixU && H(0, 0) > 0) step[0] = -g[0] / H(0, 0);
        else if (!fixV && H(1, 1) > 0) step[1] = -g[1] / H(1, 1);
        if (fixU) step[0] = 0;
        if (fixV) step[1] = 0;
        bool moved = false;
        for (double scale = 1; scale > 1e-6; scale *= 0.5) {
            const double nu = std::clamp(u + scale * step[0], u0, u1), nvv = std::clamp(v + scale * step[1], v0, v1);
            const SurfaceDerivatives nd = surface_.evaluate(nu, nvv, 2);
            const double nf = (nd.s - x).squaredNorm();
            if (nf <= f) {
                moved = nu != u || nvv != v;
                const double travel = (nd.s - d.s).squaredNorm();
                u = nu, v = nvv, d = nd, f = nf;
                if (travel <= 1e-24 * (1 + x.squaredNorm())) moved = false;  // converged to rounding
                break;
            }
        }
        if (!moved) break;
    }
    SurfaceFoot foot;
    foot.u = u, foot.v = v, foot.point = d.s;
    const Vec3 n = d.su.cross(d.sv);
    const double len = n.norm();
    if (len > 0) foot.normal = n / len;
    const Vec3 r = x - d.s;
    const double dist = r.norm();
    foot.distance = r.dot(foot.normal) < 0 ? -dist : dist;
    // Beyond an edge: the offset leaves the normal line by more than 1e-4 of itself (Newton
    // leaves 1e-6 of it at most inside the domain).
    const bool onEdge = u <= u0 || u >= u1 || v <= v0 || v >= v1;
    const double along = (r - r.dot(foot.normal) * foot.normal).norm();
    foot.beyondEdge = onEdge && along > 1e-4 * dist + 1e-12 * (1 + x.norm());
    return foot;
}

}  // namespace hs
