#include "solvers/prefactored_solver.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

namespace {
/// The largest row - column among m's entries (its lower bandwidth in its own order).
int lowerBandwidth(const Eigen::SparseMatrix<double>& m) {
    int bw = 0;
    for (int c = 0; c < m.outerSize(); ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(m, c); it; ++it) bw = std::max(bw, static_cast<int>(it.row()) - c);
    return bw;
}
}  // namespace

void PrefactoredSolver::checkPivots(const Eigen::VectorXd& D, const char* what) {
    // A singular or indefinite system (e.g. a sampling too sparse for the knots) shows as D <= 0.
    const double scale = D.cwiseAbs().maxCoeff();
    if (!(D.minCoeff() > 1e-14 * scale) || !D.allFinite())
        throw std::runtime_error(std::string(what) +
                                 ": matrix is singular; the mesh sampling must see every control point "
                                 "(use a finer mesh)");
}

void PrefactoredSolver::factor(const Eigen::SparseMatrix<double>& m, const char* what, int denseLimit) {
    ready_ = false;
    n_ = static_cast<int>(m.rows());
    work_.resize(n_, 3);
    bx_.resize(n_);
    by_.resize(n_);
    bz_.resize(n_);
    inverse_.resize(0, 0);
    band_.resize(0, 0);
    L_ = Eigen::SparseMatrix<double>();
    if (n_ > denseLimit) {
        const int bw = lowerBandwidth(m);
        const Eigen::Index sparseEntries = ldlt_.analysedEntries(m);
        if (static_cast<double>(n_) * bw <= kBandShare * static_cast<double>(sparseEntries)) {
            factorBand(m, bw, what);
            kind_ = Kind::Band;
            ready_ = true;
            return;
        }
        ldlt_.factorize(m);  // (on the ordering analysedEntries made)
    } else {
        ldlt_.compute(m);
    }
    if (ldlt_.info() != Eigen::Success)
        throw std::runtime_error(std::string(what) + ": factorisation failed (matrix not positive definite)");
    const Eigen::VectorXd D = ldlt_.vectorD();
    checkPivots(D, what);
    kind_ = Kind::Sparse;
    if (n_ <= denseLimit) {
        inverse_ = ldlt_.solve(Eigen::MatrixXd::Identity(n_, n_));
        inverse_ = 0.5 * (inverse_ + inverse_.transpose()).eval();  // exactly symmetric
        kind_ = Kind::Dense;
    } else {
        L_ = ldlt_.matrixL().nestedExpression();
        invD_ = D.cwiseInverse();
        perm_ = ldlt_.permutationP().indices();
    }
    ready_ = true;
}

void PrefactoredSolver::factorBand(const Eigen::SparseMatrix<double>& m, int bandwidth, const char* what) {
    // Row by row (Doolittle on the band): with u_k = L(i, k) D(k) for the row's earlier entries,
    //   u_j = A(i, j) - sum_k u_k L(j, k),  L(i, j) = u_j / D(j),  D(i) = A(i, i) - sum_k u_k L(i, k),
    // every sum a dot product of contiguous stretches of two rows.
    const int bw = bandwidth_ = bandwidth;
    band_.setZero(n_, bw + 1);
    for (int c = 0; c < m.outerSize(); ++c)
        for (Eigen::SparseMatrix<double>::InnerIterator it(m, c); it; ++it)
            if (it.row() >= c) band_(it.row(), bw - (it.row() - c)) = it.value();  // (the lower half)
    Eigen::VectorXd u(bw);
    for (int i = 0; i < n_; ++i) {
        const int j0 = std::max(0, i - bw);
        double* row = band_.row(i).data() + (bw - (i - j0));  // L(i, j0 ..), then D(i)
        for (int j = j0; j < i; ++j) {
            // k runs over [max(j0, j - bw), j): row j holds L(j, k) at k - (j - bw)
            const int k0 = std::max(j0, j - bw);
            const double* rowJ = band_.row(j).data() + (bw - (j - k0));
            double s = row[j - j0];
            for (int k = k0; k < j; ++k) s -= u[k - j0] * rowJ[k - k0];
            u[j - j0] = s;
            row[j - j0] = s / band_(j, bw);
        }
        double d = band_(i, bw);
        for (int k = j0; k < i; ++k) d -= u[k - j0] * row[k - j0];
        band_(i, bw) = d;
        if (!(d > 0) || !std::isfinite(d))
            throw std::runtime_error(std::string(what) + ": factorisation failed (matrix not positive definite)");
    }
    checkPivots(band_.col(bw), what);
}

void PrefactoredSolver::solveBand(const Points& b, Points& x) const {
    // The three columns apart (contiguous), each row of the factor read once a sweep for all three.
    const int bw = bandwidth_;
    bx_ = b.col(0);
    by_ = b.col(1);
    bz_ = b.col(2);
    double *y0 = bx_.data(), *y1 = by_.data(), *y2 = bz_.data();
    // Forward L y = b, a dot product per row; then y / D.
    for (int i = 0; i < n_; ++i) {
        const int len = std::min(i, bw), k0 = i - len;
        const double* row = band_.row(i).data() + (bw - len);
        double s0 = 0, s1 = 0, s2 = 0;
        for (int k = 0; k < len; ++k) {
            s0 += row[k] * y0[k0 + k];
            s1 += row[k] * y1[k0 + k];
            s2 += row[k] * y2[k0 + k];
        }
        y0[i] -= s0;
        y1[i] -= s1;
        y2[i] -= s2;
    }
    for (int i = 0; i < n_; ++i) {
        const double invD = 1.0 / band_(i, bw);
        y0[i] *= invD;
        y1[i] *= invD;
        y2[i] *= invD;
    }
    // Backward L^T z = (y / D): each row, once final, taken off the rows it reaches.
    for (int i = n_ - 1; i > 0; --i) {
        const int len = std::min(i, bw), k0 = i - len;
        const double* row = band_.row(i).data() + (bw - len);
        const double z0 = y0[i], z1 = y1[i], z2 = y2[i];
        for (int k = 0; k < len; ++k) {
            y0[k0 + k] -= row[k] * z0;
            y1[k0 + k] -= row[k] * z1;
            y2[k0 + k] -= row[k] * z2;
        }
    }
    x.col(0) = bx_;
    x.col(1) = by_;
    x.col(2) = bz_;
}

void PrefactoredSolver::solveSparse(const Points& b, const std::vector<int>& rows, Points& x) const {
    if (!dense() || 4 * rows.size() > static_cast<size_t>(n_)) return solve(b, x);
    x.setZero();
    for (int j : rows) {  // the inverse is symmetric: its row j is its column j
        const double* r = inverse_.data() + static_cast<Eigen::Index>(j) * n_;
        const double b0 = b(j, 0), b1 = b(j, 1), b2 = b(j, 2);
        double* o = x.data();
        for (int i = 0; i < n_; ++i) {
            o[3 * i] += r[i] * b0;
            o[3 * i + 1] += r[i] * b1;
            o[3 * i + 2] += r[i] * b2;
        }
    }
}

void PrefactoredSolver::solve(const Points& b, Points& x) const {
    if (kind_ == Kind::Band) return solveBand(b, x);
    if (dense()) {
        bx_ = b.col(0);
        by_ = b.col(1);
        bz_ = b.col(2);
        for (int i = 0; i < n_; ++i) {
            const auto row = inverse_.row(i);
            x(i, 0) = row.dot(bx_);
            x(i, 1) = row.dot(by_);
            x(i, 2) = row.dot(bz_);
        }
        return;
    }
    double* w = work_.data();
    for (int i = 0; i < n_; ++i) {
        const int t = perm_[i];
        w[3 * t] = b(i, 0); w[3 * t + 1] = b(i, 1); w[3 * t + 2] = b(i, 2);
    }
    const int* outer = L_.outerIndexPtr();
    const int* inner = L_.innerIndexPtr();
    const double* val = L_.valuePtr();
    // Forward: L y = w (unit diagonal; column-oriented).
    for (int c = 0; c < n_; ++c) {
        const double x0 = w[3 * c], x1 = w[3 * c + 1], x2 = w[3 * c + 2];
        for (int e = outer[c]; e < outer[c + 1]; ++e) {
            const int r = inner[e];
            if (r == c) continue;
            w[3 * r] -= val[e] * x0; w[3 * r + 1] -= val[e] * x1; w[3 * r + 2] -= val[e] * x2;
        }
    }
    for (int c = 0; c < n_; ++c) { w[3 * c] *= invD_[c]; w[3 * c + 1] *= invD_[c]; w[3 * c + 2] *= invD_[c]; }
    // Backward: L^T z = y.
    for (int c = n_ - 1; c >= 0; --c) {
        double s0 = w[3 * c], s1 = w[3 * c + 1], s2 = w[3 * c + 2];
        for (int e = outer[c]; e < outer[c + 1]; ++e) {
            const int r = inner[e];
            if (r == c) continue;
            s0 -= val[e] * w[3 * r]; s1 -= val[e] * w[3 * r + 1]; s2 -= val[e] * w[3 * r + 2];
        }
        w[3 * c] = s0; w[3 * c + 1] = s1; w[3 * c + 2] = s2;
    }
    for (int i = 0; i < n_; ++i) {
        const int t = perm_[i];
        x(i, 0) = w[3 * t]; x(i, 1) = w[3 * t + 1]; x(i, 2) = w[3 * t + 2];
    }
}

}  // namespace hs
