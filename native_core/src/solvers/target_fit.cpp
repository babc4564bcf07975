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
// Beyond the scan (grid samples the points do not reach, joined to the parameter domain's border)
// the change's slope is weighed too, a membrane on d = p - p0 by beyond x trace(data) / (3
// trace((G A)^T G A)), G the grid's first differences: there the curvature variation alone
// continued the fitted curvature outward (its null space holds the quadratics), and a patch wider
// than its scan rose 10 mm at its corners over a 2 mm bump. A hole inside the scan is not beyond it:
// the curvature variation bridges it, as the surface there is expected to go on curving.
// Solved for the increment in the free poles (P = T z, held_poles.hpp), T applied to each
// coordinate: held poles stay, linked ones follow, the mirror symmetry is put back exactly. The
// normal matrix is summed into a band of 3 x 3 blocks, (2p+1)(2q+1) per pole, so millions of
// points cost no triplet list.
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <utility>
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

// How far each grid sample (us x vs, row-major) lies beyond the points of weight > 0, in [0, 1]:
// 0 within them and in a hole inside them, rising to 1 one `span` (a share of the domain) past
// them. Measured in bins of about 16 points each where there are points; a bin beyond holds none
// and joins the border through such bins. (A sheet that overhangs its scan by a bin, as a fitted
// sheet does on a curved scan, keeps the curvature's continuation there: 4 nets to 93.99 % within
// 0.1 mm on the bench's 100k row, 3 to 92.9 % with the membrane at full weight right past the points.)
std::vector<double> beyondThePoints(const Eigen::MatrixX2d& uv, const Eigen::VectorXd& weights,
                                    const std::vector<double>& us, const std::vector<double>& vs, double span) {
    const int gu = static_cast<int>(us.size()), gv = static_cast<int>(vs.size());
    const double used = static_cast<double>((weights.array() > 0).count());
    const int side = std::max(1, static_cast<int>(std::sqrt(used / 16)));
    const int bu = std::min(gu, side), bv = std::min(gv, side);
    auto bin = [](double x, double lo, double hi, int n) {
        return std::clamp(static_cast<int>((x - lo) / (hi - lo) * n), 0, n - 1);
    };
    const auto neighbours = {std::pair{-1, 0}, std::pair{1, 0}, std::pair{0, -1}, std::pair{0, 1}};
    // Distance in bins from the nearest bin with a point (breadth first from all of them).
    std::vector<int> distance(static_cast<std::size_t>(bu) * bv, -1), queue;
    for (Eigen::Index k = 0; k < uv.rows(); ++k)
        if (weights[k] > 0) {
            const int i = bin(uv(k, 0), us.front(), us.back(), bu) * bv + bin(uv(k, 1), vs.front(), vs.back(), bv);
            if (distance[i] < 0) distance[i] = 0, queue.push_back(i);
        }
    for (std::size_t next = 0; next < queue.size(); ++next) {
        const int i = queue[next], a = i / bv, b = i % bv;
        for (const auto& [da, db] : neighbours) {
            const int na = a + da, nb = b + db;
            if (na >= 0 && na < bu && nb >= 0 && nb < bv && distance[na * bv + nb] < 0)
                distance[na * bv + nb] = distance[i] + 1, queue.push_back(na * bv + nb);
        }
    }
    // Beyond: the empty bins joined to the border through empty bins.
    std::vector<char> beyond(distance.size(), 0);
    std::vector<int> stack;
    for (int a = 0; a < bu; ++a)
        for (int b = 0; b < bv; ++b)
            if ((a == 0 || b == 0 || a == bu - 1 || b == bv - 1) && distance[a * bv + b] != 0) stack.push_back(a * bv + b);
    while (!stack.empty()) {
        const int i = stack.back(), a = i / bv, b = i % bv;
        stack.pop_back();
        if (beyond[i]) continue;
        beyond[i] = 1;
        for (const auto& [da, db] : neighbours) {
            const int na = a + da, nb = b + db;
            if (na >= 0 && na < bu && nb >= 0 && nb < bv && distance[na * bv + nb] != 0 && !beyond[na * bv + nb])
                stack.push_back(na * bv + nb);
        }
    }
    std::vector<double> samples(static_cast<std::size_t>(gu) * gv, 0.0);
    const double binsPerSpan = span * std::max(bu, bv);
    for (int a = 0; a < gu; ++a)
        for (int b = 0; b < gv; ++b) {
            const int i = bin(us[a], us.front(), us.back(), bu) * bv + bin(vs[b], vs.front(), vs.back(), bv);
            if (beyond[i])  // (no point at all: everything is beyond, at full weight)
                samples[a * gv + b] = distance[i] < 0 ? 1.0 : std::min(1.0, distance[i] / binsPerSpan);
        }
    return samples;
}

}  // namespace

Points DynamicSurface::fitPoles(const Points& targets, const Eigen::MatrixX2d& uv, const Points& normals,
                                const Eigen::VectorXd& weights, double tangential, double smoothing, double inPlane,
                                double beyond) {
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
    requireInRange(beyond, "beyond", 0.0, 1e6);
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
    const SamplingOperator sampling(S, gu, gv);
    const Eigen::SparseMatrix<double> A = sampling.matrix().toEigen();
    const double su = state_.spacingU * (g() - 1) / (gu - 1), sv = state_.spacingV * (h() - 1) / (gv - 1);
    const Eigen::SparseMatrix<double> CA = curvatureVariation(gu, gv, su, sv, centre) * A;
    const Eigen::SparseMatrix<double> F = CA.transpose() * CA;
    const double variation = CA.squaredNorm();
    const double tau = smoothing > 0 && variation > 0 ? smoothing * trace / (3 * variation) : 0.0;
    for (int k = 0; k < F.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(F, k); it; ++it)
            for (int c = 0; c < 3; ++c) entries.emplace_back(3 * it.row() + c, 3 * it.col() + c, tau * it.value());
    // The membrane beyond the points: first differences along u and v, the rows that touch a
    // sample beyond them, each coordinate alike.
    Eigen::SparseMatrix<double> M;
    double mu = 0;
    if (beyond > 0) {
        const int spans = std::max(S.nu() - p, S.nv() - q);  // (the finer direction's mean span)
        const std::vector<double> far = beyondThePoints(uv, weights, sampling.us(), sampling.vs(), 1.0 / spans);
        std::vector<Eigen::Triplet<double>> d, dFar;
        int row = 0, rowFar = 0;
        auto difference = [&](int i, int j, double step) {
            d.emplace_back(row, i, -1 / step), d.emplace_back(row++, j, 1 / step);
            const double ramp = std::max(far[i], far[j]);
            if (ramp > 0) dFar.emplace_back(rowFar, i, -ramp / step), dFar.emplace_back(rowFar++, j, ramp / step);
        };
        for (int a = 0; a < gu; ++a)
            for (int b = 0; b < gv; ++b) {
                if (a + 1 < gu) difference(a * gv + b, (a + 1) * gv + b, su);
                if (b + 1 < gv) difference(a * gv + b, a * gv + b + 1, sv);
            }
        if (rowFar > 0) {
            Eigen::SparseMatrix<double> G(row, gu * gv), GFar(rowFar, gu * gv);
            G.setFromTriplets(d.begin(), d.end());
            GFar.setFromTriplets(dFar.begin(), dFar.end());
            const double slope = (G * A).squaredNorm();
            const Eigen::SparseMatrix<double> GA = GFar * A;
            M = GA.transpose() * GA;
            mu = slope > 0 ? beyond * trace / (3 * slope) : 0.0;
            for (int k = 0; k < M.outerSize(); ++k)
                for (Eigen::SparseMatrix<double>::InnerIterator it(M, k); it; ++it)
                    for (int c = 0; c < 3; ++c) entries.emplace_back(3 * it.row() + c, 3 * it.col() + c, mu * it.value());
        }
    }
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
    rhs -= sys * flat;  // for the increment; the in-plane and membrane terms weigh the move, not the place
    rhs += Eigen::Map<const Eigen::VectorXd>(inPlaneBack.data(), 3 * poles);
    if (mu > 0)
        for (int c = 0; c < 3; ++c) {
            const Eigen::VectorXd back = mu * (M * P.col(c));
            for (int i = 0; i < poles; ++i) rhs[3 * i + c] += back[i];
        }
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
