// Fitting the surface to target points (a scan, issue 30): the poles that bring the surface
// nearest the points at given parameters, with the curvature variation of the mesh (as Fair,
// curvature_variation.hpp) to bridge where there are no points:
//   min_p  sum_k w_k r_k^T (n_k n_k^T + a (I - n_k n_k^T)) r_k + tau p^T A^T C^T C A p,
//   r_k = S(u_k, v_k; p) - t_k,
// the distance along the surface's normal n_k at the point's foot weighed fully and the slide
// along the surface by a (tangential < 1): the feet then follow the points in a few rounds where
// plain least squares (a = 1) creeps (Wang, Pottmann and Liu's squared distance minimisation,
// without its curvature term). tau = smoothing x trace(data) / (3 trace(A^T C^T C A)), A the
// sampling of a grid at least 3 points per span. With inPlane > 0, each pole's move within the
// tangent plane at its Greville point is weighed too, by inPlane x trace(data) / (3 poles): the
// points hold a pole mostly across the surface, and on a slope a move along it serves them as well
// as one across, so poles slid far in the plane and a refined net folded (a cell turned over).
// Solved for the increment in the free poles (P = T z, held_poles.hpp), T applied to each
// coordinate: held poles stay, linked ones follow, the mirror symmetry is put back exactly. The
// normal matrix is summed into a band of 3 x 3 blocks, (2p+1)(2q+1) per pole, so millions of
// points cost no triplet list.
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "geometry/sampling_operator.hpp"
#include "solvers/curvature_variation.hpp"
#include "solvers/dynamic_surface.hpp"

namespace hs {

namespace {

// T (poles x free poles) of the held and linked poles, and T (x) I3 on (x, y, z) per pole.
Eigen::SparseMatrix<double> coordinatewise(const HeldPoles& held, int poles) {
    std::vector<int> column(poles, -1);
    int free = 0;
    for (int i = 0; i < poles; ++i)
        if (!held.constrained(i)) column[i] = free++;
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < poles; ++i)
        if (column[i] >= 0)
            for (int c = 0; c < 3; ++c) t.emplace_back(3 * i + c, 3 * column[i] + c, 1.0);
    for (const PoleLink& l : held.links())
        for (const auto& [master, weight] : l.masters)
            if (column[master] >= 0)  // (a held master's increment is zero)
                for (int c = 0; c < 3; ++c) t.emplace_back(3 * l.pole + c, 3 * column[master] + c, weight);
    Eigen::SparseMatrix<double> T(3 * poles, 3 * free);
    T.setFromTriplets(t.begin(), t.end());
    return T;
}

}  // namespace

Points DynamicSurface::fitPoles(const Points& targets, const Eigen::MatrixX2d& uv, const Points& normals,
                                const Eigen::VectorXd& weights, double tangential, double smoothing, double inPlane) {
    const Eigen::Index count = targets.rows();
    if (uv.rows() != count || normals.rows() != count || weights.size() != count)
        throw std::invalid_argument("targets: uv, normals and weights need one row per target point");
    if (!withinRange(targets)) throw std::invalid_argument("targets: must be finite and within +-1e9");
    if (!uv.allFinite()) throw std::invalid_argument("uv: must be finite");
    if (!normals.allFinite()) throw std::invalid_argument("normals: must be finite");
    if (!weights.allFinite() || (count > 0 && weights.minCoeff() < 0))
        throw std::invalid_argument("weights: must be finite and >= 0");
    requireInRange(tangential, "tangential", 1e-6, 1.0);
    requireInRange(smoothing, "smoothing", 0.0, 1e6);
    requireInRange(inPlane, "in_plane", 0.0, 1e6);
    const BSplineSurface& S = surface();
    const int nv = S.nv(), poles = S.nu() * nv, p = S.knotsU().degree(), q = S.knotsV().degree();
    const int bw = 2 * p + 1, bh = 2 * q + 1;
    using Block = Eigen::Matrix3d;
    std::vector<Block, Eigen::aligned_allocator<Block>> band(static_cast<std::size_t>(poles) * bw * bh, Block::Zero());
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(3 * poles);
    int index[(kMaxDegree + 1) * (kMaxDegree + 1)];
    double value[(kMaxDegree + 1) * (kMaxDegree + 1)];
    for (Eigen::Index k = 0; k < count; ++k) {
        const double w = weights[k];
        if (w == 0) continue;
        Vec3 n = normals.row(k).transpose();
        const double len = n.norm();
        n = len > 0 ? Vec3(n / len) : Vec3::Zero();
        const Block W = w * (n * n.transpose() + tangential * (Block::Identity() - n * n.transpose()));
        const Vec3 Wt = W * targets.row(k).transpose();
        int m = 0;
        S.visitBasis(uv(k, 0), uv(k, 1), 1, [&](int i, double R, double, double, double, double, double) {
            index[m] = i, value[m] = R, ++m;
        });
        for (int a = 0; a < m; ++a) {
            const int ia = index[a], ra = ia / nv, ca = ia % nv;
            rhs.segment<3>(3 * ia) += value[a] * Wt;
            for (int b = 0; b < m; ++b) {
                const int ib = index[b];
                band[(static_cast<std::size_t>(ia) * bw + (ib / nv - ra + p)) * bh + (ib % nv - ca + q)] +=
                    (value[a] * value[b]) * W;
            }
        }
    }
    std::vector<Eigen::Triplet<double>> entries;
    double trace = 0;
    for (int ia = 0; ia < poles; ++ia)
        for (int di = 0; di < bw; ++di)
            for (int dj = 0; dj < bh; ++dj) {
                const Block& x = band[(static_cast<std::size_t>(ia) * bw + di) * bh + dj];
                if (x.isZero(0)) continue;
                const int ib = (ia / nv + di - p) * nv + (ia % nv + dj - q);
                for (int r = 0; r < 3; ++r)
                    for (int c = 0; c < 3; ++c)
                        if (x(r, c) != 0) entries.emplace_back(3 * ia + r, 3 * ib + c, x(r, c));
                if (ib == ia) trace += x.trace();
            }
    if (!(trace > 0)) throw std::invalid_argument("targets: no point with a weight > 0");
    // The curvature variation acts on each coordinate alike, measured on a grid of 3 samples per
    // span at least (the sculpt's own mesh may see a finely refined net too coarsely to bridge a
    // hole); poles neither it nor a point reaches stay where they are (and the system factors).
    std::vector<int> centre;
    const int gu = std::max(g(), 3 * S.nu()), gv = std::max(h(), 3 * S.nv());
    const Eigen::SparseMatrix<double> A = SamplingOperator(S, gu, gv).matrix().toEigen();
    const double su = state_.spacingU * (g() - 1) / (gu - 1), sv = state_.spacingV * (h() - 1) / (gv - 1);
    const Eigen::SparseMatrix<double> CA = curvatureVariation(gu, gv, su, sv, centre) * A;
    const Eigen::SparseMatrix<double> F = CA.transpose() * CA;
    const double variation = CA.squaredNorm();
    const double tau = smoothing > 0 && variation > 0 ? smoothing * trace / (3 * variation) : 0.0;
    for (int k = 0; k < F.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(F, k); it; ++it)
            for (int c = 0; c < 3; ++c) entries.emplace_back(3 * it.row() + c, 3 * it.col() + c, tau * it.value());
    for (int i = 0; i < 3 * poles; ++i) entries.emplace_back(i, i, 1e-8 * trace / (3 * poles));
    const Points& P = state_.poles();
    Points inPlaneBack = Points::Zero(poles, 3);  // (the in-plane term weighs the move, not the place)
    if (inPlane > 0) {
        const double k = inPlane * trace / (3 * poles);
        const std::vector<double>& tu = S.knotsU().knots();
        const std::vector<double>& tv = S.knotsV().knots();
        for (int i = 0; i < poles; ++i) {
            const int a = i / nv, b = i % nv;
            double greU = 0, greV = 0;
            for (int j = 1; j <= p; ++j) greU += tu[a + j] / p;
            for (int j = 1; j <= q; ++j) greV += tv[b + j] / q;
            const Vec3 n = S.normal(greU, greV);
            if (!n.allFinite() || n.squaredNorm() < 0.5) continue;  // (a degenerate corner: no plane)
            const Block K = k * (Block::Identity() - n * n.transpose());
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 3; ++c) entries.emplace_back(3 * i + r, 3 * i + c, K(r, c));
            inPlaneBack.row(i) = (K * P.row(i).transpose()).transpose();
        }
    }
    Eigen::SparseMatrix<double> sys(3 * poles, 3 * poles);
    sys.setFromTriplets(entries.begin(), entries.end());

    const Eigen::Map<const Eigen::VectorXd> flat(P.data(), 3 * poles);  // (x, y, z) per pole, row-major
    rhs -= sys * flat;  // for the increment
    rhs += Eigen::Map<const Eigen::VectorXd>(inPlaneBack.data(), 3 * poles);
    const Eigen::SparseMatrix<double> T = coordinatewise(held_, poles);
    Points fitted = P;
    if (T.cols() > 0) {
        const Eigen::SparseMatrix<double> reduced = T.transpose() * sys * T;
        Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(reduced);
        if (ldlt.info() != Eigen::Success) throw std::runtime_error("fit: the fitting system does not factor");
        const Eigen::VectorXd step = T * ldlt.solve(T.transpose() * rhs);
        Eigen::Map<Eigen::VectorXd>(fitted.data(), 3 * poles) += step;
    }
    if (!mirror_.empty()) {
        Points still = Points::Zero(poles, 3);
        mirror_.project(fitted, still);
    }
    if (!fitted.allFinite()) throw std::runtime_error("fit: the fitting system gave non-finite poles");
    return fitted;
}

}  // namespace hs
