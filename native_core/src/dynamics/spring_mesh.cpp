#include "dynamics/spring_mesh.hpp"

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
// c_j (x_a - x_b) for one run; branch-free so that it vectorises (Uniform: one stiffness for all).
// With Energy, also k e^2 into ce (summed by the caller: a reduction here would not vectorise).
template <bool Uniform, bool Energy, class Law>
void projectRun(Law lw, int n, const double* __restrict xa, const double* __restrict ya, const double* __restrict za,
                const double* __restrict xb, const double* __restrict yb, const double* __restrict zb,
                const double* __restrict rest, const double* __restrict k, double kUniform, double maxExtra,
                double minL, double* __restrict cx, double* __restrict cy, double* __restrict cz,
                double* __restrict ce) {
    for (int j = 0; j < n; ++j) {
        const double kj = Uniform ? kUniform : k[j];
        const double dx = xa[j] - xb[j], dy = ya[j] - yb[j], dz = za[j] - zb[j];
        const double l = std::sqrt(dx * dx + dy * dy + dz * dz);
        const double e = l - rest[j];
        const double cap = maxExtra * std::abs(e);
        const double force = std::min(std::max(lw.value(kj * e), kj * e - cap), kj * e + cap);
        // k t - k (d_a - d_b) = c (d_a - d_b) with c = k target / l - k, target = l - force / k;
        // a zero-length spring has no direction (t = 0)
        const double live = l > minL ? 1.0 : 0.0;  // a select of constants keeps the loop branch-free
        const double c = live * ((kj * l - force) / std::max(l, minL)) - kj;
        cx[j] = c * dx;
        cy[j] = c * dy;
        cz[j] = c * dz;
        if (Energy) ce[j] = kj * e * e;
    }
}
}  // namespace

SpringMesh::SpringMesh(int g, int h, const Points& d) : g_(g), h_(h) {
    auto family = [&](int offset, int rows, int j0, int j1) {
        const int rowStep = offset == 1 ? 0 : 1, colStep = offset - rowStep * h;
        for (int i = 0; i < rows; ++i) {
            if (j1 <= j0) continue;
            runs_.push_back({static_cast<int>(a_.size()), i * h + j0, offset, j1 - j0, rowStep, colStep});
            for (int j = j0; j < j1; ++j) {
                a_.push_back(i * h + j);
                b_.push_back(i * h + j + offset);
            }
        }
    };
    family(1, g, 0, h - 1);          // along v
    family(h, g - 1, 0, h);          // along u
    family(h + 1, g - 1, 0, h - 1);  // diagonal
    family(h - 1, g - 1, 1, h);      // anti-diagonal
    const size_t n = a_.size();
    dirx_.assign(n, 0); diry_.assign(n, 0); dirz_.assign(n, 0); axial_.assign(n, 0); lateral_.assign(n, 0);
    const Eigen::Index points = static_cast<Eigen::Index>(g) * h;
    for (Eigen::VectorXd* v : {&x_, &y_, &z_, &fx_, &fy_, &fz_}) v->setZero(points);
    for (Eigen::VectorXd* v : {&cx_, &cy_, &cz_, &ce_}) v->setZero(std::max(g, h) + 1);
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

template <class F>
void SpringMesh::forRuns(const GridRect* window, F&& f) const {
    for (const Run& run : runs_) {
        if (!window) {
            f(run.first, run.a0, run.offset, run.length);
            continue;
        }
        const GridRect& w = *window;
        const int row = run.a0 / h_, col = run.a0 % h_;
        if (row < w.r0 || row + run.rowStep >= w.r1) continue;
        const int j0 = std::max({0, w.c0 - col, w.c0 - col - run.colStep});
        const int j1 = std::min({run.length, w.c1 - col, w.c1 - col - run.colStep});
        if (j1 > j0) f(run.first + j0, run.a0 + j0, run.offset, j1 - j0);
    }
}

double SpringMesh::addProjections(const Points& d, Points& out, double maxExtraStiffness, double scale, bool energy,
                                  const GridRect* window) const {
    // Each spring's energy 1/2 k |x_a - x_b - t|^2 is minimised over |t| = target length;
    // a non-linear law changes the target length so that k (l - |t|) = g(k (l - r)).
    // Runs of one family in one row have contiguous endpoints a and a + offset: in structure-of-
    // arrays form every loop below is a plain vectorisable stream.
    const GridRect all = GridRect::whole(g_, h_);
    const GridRect& points = window ? *window : all;
    points.forRuns([&](Eigen::Index i, Eigen::Index n) {
        x_.segment(i, n) = d.col(0).segment(i, n);
        y_.segment(i, n) = d.col(1).segment(i, n);
        z_.segment(i, n) = d.col(2).segment(i, n);
        fx_.segment(i, n).setZero();
        fy_.segment(i, n).setZero();
        fz_.segment(i, n).setZero();
    });
    const double* X = x_.data();
    const double* Y = y_.data();
    const double* Z = z_.data();
    double* cx = cx_.data();
    double* cy = cy_.data();
    double* cz = cz_.data();
    const double* rest = rest_.data();
    const bool uniform = k_.empty();
    const double* kv = uniform ? nullptr : k_.data();
    const double kU = kUniform_, minL = minLength;
    double* ce = ce_.data();
    double twiceEnergy = 0;
    withLaw(law, [&](auto lw) {
        forRuns(window, [&](int first, int a0, int offset, int length) {
            const double* xa = X + a0;
            const double* ya = Y + a0;
            const double* za = Z + a0;
            const double* xb = xa + offset;
            const double* yb = ya + offset;
            const double* zb = za + offset;
            const double* r = rest + first;
            const double* kr = uniform ? nullptr : kv + first;
            if (energy) {
                if (uniform) projectRun<true, true>(lw, length, xa, ya, za, xb, yb, zb, r, nullptr, kU, maxExtraStiffness, minL, cx, cy, cz, ce);
                else projectRun<false, true>(lw, length, xa, ya, za, xb, yb, zb, r, kr, kU, maxExtraStiffness, minL, cx, cy, cz, ce);
                twiceEnergy += Eigen::Map<const Eigen::VectorXd>(ce, length).sum();
            } else {
                if (uniform) projectRun<true, false>(lw, length, xa, ya, za, xb, yb, zb, r, nullptr, kU, maxExtraStiffness, minL, cx, cy, cz, ce);
                else projectRun<false, false>(lw, length, xa, ya, za, xb, yb, zb, r, kr, kU, maxExtraStiffness, minL, cx, cy, cz, ce);
            }
            double* fxa = fx_.data() + a0;
            double* fya = fy_.data() + a0;
            double* fza = fz_.data() + a0;
            for (int j = 0; j < length; ++j) { fxa[j] += cx[j]; fya[j] += cy[j]; fza[j] += cz[j]; }
            double* fxb = fxa + offset;
            double* fyb = fya + offset;
            double* fzb = fza + offset;
            for (int j = 0; j < length; ++j) { fxb[j] -= cx[j]; fyb[j] -= cy[j]; fzb[j] -= cz[j]; }
        });
        return 0;
    });
    points.forRuns([&](Eigen::Index i, Eigen::Index n) {
        out.col(0).segment(i, n) += scale * fx_.segment(i, n);
        out.col(1).segment(i, n) += scale * fy_.segment(i, n);
        out.col(2).segment(i, n) += scale * fz_.segment(i, n);
    });
    return energy && law.kind == LawKind::Linear ? 0.5 * twiceEnergy : 0.0;
}

void SpringMesh::applyPlasticity(const Points& d, double dt, const GridRect* window) {
    const double creep = std::min(1.0, plasticity.rate * dt);
    forRuns(window, [&](int first, int, int, int length) {
        for (int s = first; s < first + length; ++s) {
            const double l = (d.row(a_[s]) - d.row(b_[s])).norm();
            const double limit = plasticity.yieldStrain * rest0_[s];
            const double e = l - rest_[s];
            if (std::abs(e) > limit) rest_[s] += creep * (e - std::copysign(limit, e));
        }
    });
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
    if (law.kind != LawKind::Linear) {
        double e = 0;
        for (size_t s = 0; s < a_.size(); ++s)
            e += law.energy(stiffness(static_cast<int>(s)), (d.row(a_[s]) - d.row(b_[s])).norm() - rest_[s]);
        return e;
    }
    // Linear springs run by run (contiguous endpoints), branch-free, so the loop vectorises: the
    // energy guard calls this every step of the scenes it watches.
    const double* D = d.data();
    const bool uniform = k_.empty();
    double e = 0;
    for (const Run& run : runs_) {
        const double* pa = D + 3 * run.a0;
        const double* pb = pa + 3 * run.offset;
        const double* r = rest_.data() + run.first;
        const double* kr = uniform ? nullptr : k_.data() + run.first;
        double sum = 0;
        for (int j = 0; j < run.length; ++j) {
            const double dx = pb[3 * j] - pa[3 * j], dy = pb[3 * j + 1] - pa[3 * j + 1], dz = pb[3 * j + 2] - pa[3 * j + 2];
            const double x = std::sqrt(dx * dx + dy * dy + dz * dz) - r[j];
            sum += (uniform ? kUniform_ : kr[j]) * x * x;
        }
        e += sum;
    }
    return 0.5 * e;
}

}  // namespace hs
