#include "geometry/sampling_operator.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

void CsrMatrix::multiply(const Points& x, Points& y) const {
    for (int r = 0; r < rows; ++r) {
        double sx = 0, sy = 0, sz = 0;
        for (int e = rowStart[r]; e < rowStart[r + 1]; ++e) {
            const double w = value[e];
            const double* px = x.data() + 3 * col[e];
            sx += w * px[0]; sy += w * px[1]; sz += w * px[2];
        }
        double* py = y.data() + 3 * r;
        py[0] = sx; py[1] = sy; py[2] = sz;
    }
}

void CsrMatrix::multiplyTransposed(const Points& x, Points& y) const {
    y.setZero();
    for (int r = 0; r < rows; ++r) {
        const double* px = x.data() + 3 * r;
        for (int e = rowStart[r]; e < rowStart[r + 1]; ++e) {
            double* py = y.data() + 3 * col[e];
            const double w = value[e];
            py[0] += w * px[0]; py[1] += w * px[1]; py[2] += w * px[2];
        }
    }
}

Eigen::SparseMatrix<double> CsrMatrix::toEigen() const {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(value.size());
    // A basis function vanishes at the ends of its support, so a sample on a knot evaluates it to 0
    // (or 1e-16 off the knot by rounding). Kept, such entries widen the pattern of A^T S A: degree-1
    // poles sampled at their knots gave a 25-point instead of a 9-point stencil and 3x the solve time.
    for (int r = 0; r < rows; ++r)
        for (int e = rowStart[r]; e < rowStart[r + 1]; ++e)
            if (std::abs(value[e]) > 1e-14) t.emplace_back(r, col[e], value[e]);
    Eigen::SparseMatrix<double> m(rows, cols);
    m.setFromTriplets(t.begin(), t.end());
    return m;
}

namespace {
std::vector<double> uniformParams(const KnotVector& k, int n) {
    std::vector<double> t(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) t[i] = k.domainStart() + (k.domainEnd() - k.domainStart()) * i / (n - 1);
    return t;
}

// One CSR matrix per requested basis component (0 = value, 1 = d/du, ...).
std::vector<CsrMatrix> basisMatrices(const BSplineSurface& s, const std::vector<double>& us,
                                     const std::vector<double>& vs, const std::vector<int>& components) {
    const int order = components.size() > 1 ? 2 : 0;
    std::vector<CsrMatrix> out(components.size());
    for (auto& m : out) {
        m.rows = static_cast<int>(us.size() * vs.size());
        m.cols = s.nu() * s.nv();
        m.rowStart.assign(1, 0);
    }
    for (double u : us)
        for (double v : vs) {
            s.visitBasis(u, v, order, [&](int idx, double R, double Ru, double Rv, double Ruu, double Ruv, double Rvv) {
                const double c[6] = {R, Ru, Rv, Ruu, Ruv, Rvv};
                for (size_t m = 0; m < components.size(); ++m) {
                    out[m].col.push_back(idx);
                    out[m].value.push_back(c[components[m]]);
                }
            });
            for (auto& m : out) m.rowStart.push_back(static_cast<int>(m.col.size()));
        }
    return out;
}
}  // namespace

SamplingOperator::SamplingOperator(const BSplineSurface& s, int g, int h)
    : g_(g), h_(h), nu_(s.nu()), nv_(s.nv()), p_(s.knotsU().degree()), q_(s.knotsV().degree()) {
    if (g < s.nu() || h < s.nv())
        throw std::invalid_argument("mesh: sampling " + std::to_string(g) + "x" + std::to_string(h) +
                                    " is coarser than the control net " + std::to_string(s.nu()) + "x" +
                                    std::to_string(s.nv()));
    u_ = uniformParams(s.knotsU(), g);
    v_ = uniformParams(s.knotsV(), h);
    A_ = std::move(basisMatrices(s, u_, v_, {0})[0]);
    separable_ = !s.rational();
    if (separable_) {
        Eigen::Matrix<double, 3, kMaxDegree + 1> b;
        for (double u : u_) {
            uStart_.push_back(s.knotsU().basis(u, 0, b) - p_);
            for (int t = 0; t <= p_; ++t) uBasis_.push_back(b(0, t));
        }
        for (double v : v_) {
            vStart_.push_back(s.knotsV().basis(v, 0, b) - q_);
            for (int t = 0; t <= q_; ++t) vBasis_.push_back(b(0, t));
        }
        tmp_.resize(static_cast<Eigen::Index>(nu_) * h_, 3);
    }
}

void SamplingOperator::apply(const Points& p, Points& d) const {
    if (!separable_) return A_.multiply(p, d);
    // tmp(i, b) = sum_j P(i, j) Av(b, j);  d(a, b) = sum_i Au(a, i) tmp(i, b)
    for (int i = 0; i < nu_; ++i)
        for (int b = 0; b < h_; ++b) {
            const double* w = &vBasis_[static_cast<size_t>(b) * (q_ + 1)];
            const double* pp = p.data() + 3 * (i * nv_ + vStart_[b]);
            double x = 0, y = 0, z = 0;
            for (int t = 0; t <= q_; ++t) { x += w[t] * pp[3 * t]; y += w[t] * pp[3 * t + 1]; z += w[t] * pp[3 * t + 2]; }
            double* o = tmp_.data() + 3 * (i * h_ + b);
            o[0] = x; o[1] = y; o[2] = z;
        }
    for (int a = 0; a < g_; ++a) {
        const double* w = &uBasis_[static_cast<size_t>(a) * (p_ + 1)];
        double* o = d.data() + 3 * a * h_;
        const double* t0 = tmp_.data() + 3 * uStart_[a] * h_;
        for (int k = 0; k < 3 * h_; ++k) o[k] = w[0] * t0[k];
        for (int t = 1; t <= p_; ++t) {
            const double* tt = t0 + 3 * t * h_;
            for (int k = 0; k < 3 * h_; ++k) o[k] += w[t] * tt[k];
        }
    }
}

void SamplingOperator::applyTransposed(const Points& f, Points& fp) const {
    if (!separable_) return A_.multiplyTransposed(f, fp);
    // tmp(i, b) = sum_a Au(a, i) f(a, b);  fp(i, j) = sum_b Av(b, j) tmp(i, b)
    tmp_.setZero();
    for (int a = 0; a < g_; ++a) {
        const double* w = &uBasis_[static_cast<size_t>(a) * (p_ + 1)];
        const double* src = f.data() + 3 * a * h_;
        for (int t = 0; t <= p_; ++t) {
            double* o = tmp_.data() + 3 * (uStart_[a] + t) * h_;
            for (int k = 0; k < 3 * h_; ++k) o[k] += w[t] * src[k];
        }
    }
    fp.setZero();
    for (int i = 0; i < nu_; ++i)
        for (int b = 0; b < h_; ++b) {
            const double* w = &vBasis_[static_cast<size_t>(b) * (q_ + 1)];
            const double* src = tmp_.data() + 3 * (i * h_ + b);
            double* o = fp.data() + 3 * (i * nv_ + vStart_[b]);
            for (int t = 0; t <= q_; ++t) { o[3 * t] += w[t] * src[0]; o[3 * t + 1] += w[t] * src[1]; o[3 * t + 2] += w[t] * src[2]; }
        }
}

GridRect SamplingOperator::meshOf(const GridRect& poles) const {
    // (uStart_ and vStart_ grow with the sample: the samples a pole reaches are a contiguous range)
    const auto range = [](const std::vector<int>& start, int degree, int first, int last, int& lo, int& hi) {
        lo = static_cast<int>(start.size());
        hi = 0;
        for (int a = 0; a < static_cast<int>(start.size()); ++a)
            if (start[a] <= last - 1 && start[a] + degree >= first) {
                lo = std::min(lo, a);
                hi = a + 1;
            }
    };
    GridRect m;
    m.stride = h_;
    range(uStart_, p_, poles.r0, poles.r1, m.r0, m.r1);
    range(vStart_, q_, poles.c0, poles.c1, m.c0, m.c1);
    return m;
}

GridRect SamplingOperator::polesOf(const GridRect& mesh) const {
    if (mesh.empty()) return {0, 0, 0, 0, nv_};
    return {uStart_[mesh.r0], uStart_[mesh.r1 - 1] + p_ + 1, vStart_[mesh.c0], vStart_[mesh.c1 - 1] + q_ + 1, nv_};
}

void SamplingOperator::applyTo(const Points& p, Points& d, const GridRect& mesh) const {
    if (mesh.empty()) return;
    // tmp(i, b) for the net rows i the mesh rows reach and the columns b of the rectangle
    const int iFirst = uStart_[mesh.r0], iLast = uStart_[mesh.r1 - 1] + p_;
    const int width = 3 * (mesh.c1 - mesh.c0);
    for (int i = iFirst; i <= iLast; ++i)
        for (int b = mesh.c0; b < mesh.c1; ++b) {
            const double* w = &vBasis_[static_cast<size_t>(b) * (q_ + 1)];
            const double* pp = p.data() + 3 * (i * nv_ + vStart_[b]);
            double x = 0, y = 0, z = 0;
            for (int t = 0; t <= q_; ++t) { x += w[t] * pp[3 * t]; y += w[t] * pp[3 * t + 1]; z += w[t] * pp[3 * t + 2]; }
            double* o = tmp_.data() + 3 * (i * h_ + b);
            o[0] = x; o[1] = y; o[2] = z;
        }
    for (int a = mesh.r0; a < mesh.r1; ++a) {
        const double* w = &uBasis_[static_cast<size_t>(a) * (p_ + 1)];
        double* o = d.data() + 3 * (a * h_ + mesh.c0);
        const double* t0 = tmp_.data() + 3 * (uStart_[a] * h_ + mesh.c0);
        for (int k = 0; k < width; ++k) o[k] = w[0] * t0[k];
        for (int t = 1; t <= p_; ++t) {
            const double* tt = t0 + 3 * t * h_;
            for (int k = 0; k < width; ++k) o[k] += w[t] * tt[k];
        }
    }
}

void SamplingOperator::applyTransposedTo(const Points& f, Points& fp, const GridRect& poles, const GridRect& mesh) const {
    if (poles.empty() || mesh.empty()) return;
    // tmp(i, b) = sum over the rectangle's rows a of Au(a, i) f(a, b), for the net rows i of `poles`
    const int width = 3 * (mesh.c1 - mesh.c0);
    for (int i = poles.r0; i < poles.r1; ++i) std::fill_n(tmp_.data() + 3 * (i * h_ + mesh.c0), width, 0.0);
    for (int a = mesh.r0; a < mesh.r1; ++a) {
        const double* w = &uBasis_[static_cast<size_t>(a) * (p_ + 1)];
        const double* src = f.data() + 3 * (a * h_ + mesh.c0);
        for (int t = 0; t <= p_; ++t) {
            const int i = uStart_[a] + t;
            if (i < poles.r0 || i >= poles.r1) continue;
            double* o = tmp_.data() + 3 * (i * h_ + mesh.c0);
            for (int k = 0; k < width; ++k) o[k] += w[t] * src[k];
        }
    }
    for (int i = poles.r0; i < poles.r1; ++i) {
        double* row = fp.data() + 3 * (i * nv_);
        std::fill(row + 3 * poles.c0, row + 3 * poles.c1, 0.0);
        for (int b = mesh.c0; b < mesh.c1; ++b) {
            const double* w = &vBasis_[static_cast<size_t>(b) * (q_ + 1)];
            const double* src = tmp_.data() + 3 * (i * h_ + b);
            for (int t = 0; t <= q_; ++t) {
                const int j = vStart_[b] + t;
                if (j < poles.c0 || j >= poles.c1) continue;
                double* o = row + 3 * j;
                o[0] += w[t] * src[0]; o[1] += w[t] * src[1]; o[2] += w[t] * src[2];
            }
        }
    }
}

const std::vector<CsrMatrix>& SamplingOperator::derivativeOperators(const BSplineSurface& s) const {
    if (derivatives_.empty()) derivatives_ = basisMatrices(s, u_, v_, {1, 2, 3, 4, 5});
    return derivatives_;
}

}  // namespace hs
