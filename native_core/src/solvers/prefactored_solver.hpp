// Sparse LDL^T factorisation done once, with a three-column solve that never allocates. Small systems
// (up to kDenseLimit unknowns, e.g. 12x12 controls) keep the explicit inverse instead: one pass of
// contiguous, vectorised dot products beats a sparse triangular solve's dependent, indexed updates.
#pragma once
#include <vector>
#include <Eigen/SparseCholesky>

#include "geometry/bspline_surface.hpp"

namespace hs {

class PrefactoredSolver {
public:
    /// Factors the symmetric positive definite matrix m, keeping its inverse up to `denseLimit`
    /// unknowns; throws std::runtime_error naming `what` if it is not.
    void factor(const Eigen::SparseMatrix<double>& m, const char* what, int denseLimit = kDenseLimit);
    bool ready() const { return ready_; }
    int size() const { return n_; }
    /// x = M^-1 b for the three columns at once; x and b may not alias.
    void solve(const Points& b, Points& x) const;
    /// The same for a b that is zero outside `rows` (a force on a few mesh points): on the dense
    /// path only those columns of the inverse are read.
    void solveSparse(const Points& b, const std::vector<int>& rows, Points& x) const;

    static constexpr int kDenseLimit = 600;
    bool dense() const { return inverse_.size() != 0; }
    /// The matrix entries one solve reads: the inverse's n^2 on the dense path, else the strictly
    /// lower factor's (read twice, forward and back, with D between). What bench/roofline.py counts.
    Eigen::Index entriesRead() const { return dense() ? inverse_.size() : L_.nonZeros(); }

private:
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
    Eigen::SparseMatrix<double> L_;  // unit lower factor, CSC (strictly lower part stored)
    Eigen::VectorXd invD_;
    Eigen::VectorXi perm_;           // (P b)[perm_[i]] = b[i]
    mutable Points work_;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> inverse_;  // dense path only
    mutable Eigen::VectorXd bx_, by_, bz_;
    int n_ = 0;
    bool ready_ = false;
};

}  // namespace hs
