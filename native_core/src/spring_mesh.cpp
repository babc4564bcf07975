#include "spring_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hs {

namespace {
// Calls body(law) with a law whose kind is a compile-time constant, so the linear case
// compiles to plain Hooke springs with no branch on the law inside the loop.
template <LawKind K>
struct FixedLaw {
    double scale;
    double value(double x) const { return ResponseLaw{K, scale}.value(x); }
    double slope(double x) const { return ResponseLaw{K, scale}.slope(x); }
};
template <class Body>
auto withLaw(const ResponseLaw& law, Body&& body) {
    switch (law.kind) {
        case LawKind::CubicHardening: return body(FixedLaw<LawKind::CubicHardening>{law.scale});
        case LawKind::Saturating: return body(FixedLaw<LawKind::Saturating>{law.scale});
        case LawKind::Linear: break;
    }
    return body(FixedLaw<LawKind::Linear>{law.scale});
}
}  // namespace

SpringMesh::SpringMesh(int g, int h, const Points& d) : g_(g), h_(h) {
    auto add = [&](int a, int b) { a_.push_back(a); b_.push_back(b); };
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < h; ++j) {
            const int p = i * h + j;
            if (j + 1 < h) add(p, p + 1);                  // along v
            if (i + 1 < g) add(p, p + h);                  // along u
            if (i + 1 < g && j + 1 < h) add(p, p + h + 1); // diagonal
            if (i + 1 < g && j > 0) add(p, p + h - 1);     // anti-diagonal
        }
    const size_t n = a_.size();
    dirx_.assign(n, 0); diry_.assign(n, 0); dirz_.assign(n, 0); axial_.assign(n, 0); lateral_.assign(n, 0);
    resetRest(d);
    rest0_ = rest_;
}

void SpringMesh::resetRest(const Points& d) {
    rest_.resize(a_.size());
    for (size_t s = 0; s < a_.size(); ++s) rest_[s] = (d.row(a_[s]) - d.row(b_[s])).norm();
}

void SpringMesh::setRest(const std::vector<double>& rest) {
    if (rest.size() != a_.size()) throw std::invalid_argument("rest: expected one length per spring");
    for (double r : rest)
        if (!std::isfinite(r) || r < 0) throw std::invalid_argument("rest: lengths must be finite and >= 0");
    rest_ = rest;
}

void SpringMesh::setStiffness(const MaterialMap& map, const std::vector<double>& us, const std::vector<double>& vs) {
    if (map.uniform()) {
        k_.clear();
        kUniform_ = map.values()[0];
        return;
    }
    k_.resize(a_.size());
    const double u0 = us.front(), du = us.back() - us.front(), v0 = vs.front(), dv = vs.back() - vs.front();
    for (size_t s = 0; s < a_.size(); ++s) {
        const double u = 0.5 * (us[a_[s] / h_] + us[b_[s] / h_]), v = 0.5 * (vs[a_[s] % h_] + vs[b_[s] % h_]);
        k_[s] = map.at((u - u0) / du, (v - v0) / dv);
    }
}

double SpringMesh::addForces(const Points& d, Points& f) {
    return withLaw(law, [&](auto lw) {
        double energy = 0;
        const ResponseLaw full = law;
        for (size_t s = 0; s < a_.size(); ++s) {
            const double* pa = d.data() + 3 * a_[s];
            const double* pb = d.data() + 3 * b_[s];
            const double dx = pb[0] - pa[0], dy = pb[1] - pa[1], dz = pb[2] - pa[2];
            const double l = std::sqrt(dx * dx + dy * dy + dz * dz);
            const double k = stiffness(static_cast<int>(s));
            if (!(l > minLength)) { axial_[s] = 0; lateral_[s] = 0; continue; }
            const double e = l - rest_[s];
            const double tension = lw.value(k * e);  // > 0 pulls a toward b
            const double il = 1.0 / l;
            const double nx = dx * il, ny = dy * il, nz = dz * il;
            dirx_[s] = nx; diry_[s] = ny; dirz_[s] = nz;
            axial_[s] = k * lw.slope(k * e);
            lateral_[s] = std::max(0.0, tension * il);
            double* fa = f.data() + 3 * a_[s];
            double* fb = f.data() + 3 * b_[s];
            fa[0] += tension * nx; fa[1] += tension * ny; fa[2] += tension * nz;
            fb[0] -= tension * nx; fb[1] -= tension * ny; fb[2] -= tension * nz;
            energy += full.energy(k, e);
        }
        return energy;
    });
}

void SpringMesh::addTangentStiffness(const Points& y, Points& out) const {
    // K_s = axial n n^T + lateral (I - n n^T), applied to y_a - y_b.
    for (size_t s = 0; s < a_.size(); ++s) {
        const double* ya = y.data() + 3 * a_[s];
        const double* yb = y.data() + 3 * b_[s];
        const double dx = ya[0] - yb[0], dy = ya[1] - yb[1], dz = ya[2] - yb[2];
        const double nx = dirx_[s], ny = diry_[s], nz = dirz_[s];
        const double along = (axial_[s] - lateral_[s]) * (nx * dx + ny * dy + nz * dz);
        const double ox = lateral_[s] * dx + along * nx, oy = lateral_[s] * dy + along * ny,
                     oz = lateral_[s] * dz + along * nz;
        double* qa = out.data() + 3 * a_[s];
        double* qb = out.data() + 3 * b_[s];
        qa[0] += ox; qa[1] += oy; qa[2] += oz;
        qb[0] -= ox; qb[1] -= oy; qb[2] -= oz;
    }
}

void SpringMesh::addProjections(const Points& d, Points& out, double maxExtraStiffness) const {
    // Each spring's energy 1/2 k |x_a - x_b - t|^2 is minimised over |t| = target length;
    // a non-linear law changes the target length so that k (l - |t|) = g(k (l - r)).
    withLaw(law, [&](auto lw) {
        for (size_t s = 0; s < a_.size(); ++s) {
            const double* pa = d.data() + 3 * a_[s];
            const double* pb = d.data() + 3 * b_[s];
            const double dx = pa[0] - pb[0], dy = pa[1] - pb[1], dz = pa[2] - pb[2];
            const double l = std::sqrt(dx * dx + dy * dy + dz * dz);
            if (!(l > minLength)) continue;
            const double k = stiffness(static_cast<int>(s));
            const double e = l - rest_[s];
            double force = lw.value(k * e);
            const double cap = maxExtraStiffness * std::abs(e);
            force = std::clamp(force, k * e - cap, k * e + cap);
            const double target = l - force / k;
            const double c = k * target / l;
            double* oa = out.data() + 3 * a_[s];
            double* ob = out.data() + 3 * b_[s];
            oa[0] += c * dx; oa[1] += c * dy; oa[2] += c * dz;
            ob[0] -= c * dx; ob[1] -= c * dy; ob[2] -= c * dz;
        }
        return 0;
    });
}

void SpringMesh::applyPlasticity(const Points& d, double dt) {
    const double creep = std::min(1.0, plasticity.rate * dt);
    for (size_t s = 0; s < a_.size(); ++s) {
        const double l = (d.row(a_[s]) - d.row(b_[s])).norm();
        const double limit = plasticity.yieldStrain * rest0_[s];
        const double e = l - rest_[s];
        if (std::abs(e) > limit) rest_[s] += creep * (e - std::copysign(limit, e));
    }
}

void SpringMesh::addLaplacian(std::vector<Eigen::Triplet<double>>& t) const {
    for (size_t s = 0; s < a_.size(); ++s) {
        const double k = stiffness(static_cast<int>(s));
        t.emplace_back(a_[s], a_[s], k);
        t.emplace_back(b_[s], b_[s], k);
        t.emplace_back(a_[s], b_[s], -k);
        t.emplace_back(b_[s], a_[s], -k);
    }
}

double SpringMesh::energy(const Points& d) const {
    double e = 0;
    for (size_t s = 0; s < a_.size(); ++s)
        e += law.energy(stiffness(static_cast<int>(s)), (d.row(a_[s]) - d.row(b_[s])).norm() - rest_[s]);
    return e;
}

}  // namespace hs
