#include "solvers/prefactored_solver.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

void PrefactoredSolver::factor(const Eigen::SparseMatrix<double>& m, const char* what, int denseLimit) {
    ready_ = false;
    ldlt_.compute(m);
    if (ldlt_.info() != Eigen::Success)
        throw std::runtime_error(std::string(what) + ": factorisation failed (matrix not positive definite)");
    const Eigen::VectorXd D = ldlt_.vectorD();
    // A singular or indefinite system (e.g. a sampling too sparse for the knots) shows as D <= 0.
    const double scale = D.cwiseAbs().maxCoeff();
    if (!(D.minCoeff() > 1e-14 * scale) || !D.allFinite())
        throw std::runtime_error(std::string(what) +
                                 ": matrix is singular; the mesh sampling must see every control point "
                                 "(use a finer mesh)");
    L_ = ldlt_.matrixL().nestedExpression();
    invD_ = D.cwiseInverse();
    perm_ = ldlt_.permutationP().indices();
    n_ = static_cast<int>(m.rows());
    work_.resize(n_, 3);
    inverse_.resize(0, 0);
    if (n_ <= denseLimit) {
        inverse_ = ldlt_.solve(Eigen::MatrixXd::Identity(n_, n_));
        inverse_ = 0.5 * (inverse_ + inverse_.transpose()).eval();  // exactly symmetric
        bx_.resize(n_);
        by_.resize(n_);
        bz_.resize(n_);
    }
    ready_ = true;
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
