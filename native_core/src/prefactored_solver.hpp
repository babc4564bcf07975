// Sparse LDL^T factorisation done once, with a three-column solve that never allocates.
#pragma once
#include <Eigen/SparseCholesky>

#include "bspline_surface.hpp"

namespace hs {

class PrefactoredSolver {
public:
    /// Factors the symmetric positive definite matrix m; throws std::runtime_error naming `what` if it is not.
    void factor(const Eigen::SparseMatrix<double>& m, const char* what);
    bool ready() const { return ready_; }
    int size() const { return n_; }
    /// x = M^-1 b for the three columns at once; x and b may not alias.
    void solve(const Points& b, Points& x) const;

private:
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt_;
    Eigen::SparseMatrix<double> L_;  // unit lower factor, CSC (strictly lower part stored)
    Eigen::VectorXd invD_;
    Eigen::VectorXi perm_;           // (P b)[perm_[i]] = b[i]
    mutable Points work_;
    int n_ = 0;
    bool ready_ = false;
};

}  // namespace hs
