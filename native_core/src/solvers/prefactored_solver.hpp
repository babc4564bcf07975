// LDL^T factorisation done once, with a three-column solve that never allocates. Small systems
// (up to kDenseLimit unknowns, e.g. 12x12 controls) keep the explicit inverse instead: one pass of
// contiguous, vectorised dot products beats a sparse triangular solve's dependent, indexed updates.
// Larger ones whose matrix is a band in its own order (a net's poles row by row: a bicubic net
// couples poles up to three rows apart) keep a band factor when it holds about as many entries as
// the sparse factor under AMD: its solve streams contiguous rows, 8 bytes an entry against 12, and
// vectorises. Others (curve links coupling distant poles) keep the sparse factor.
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
    /// A band factor is kept while it holds at most this many times the sparse factor's entries.
    static constexpr double kBandShare = 1.25;
    enum class Kind { Dense, Band, Sparse };
    Kind kind() const { return kind_; }
    bool dense() const { return kind_ == Kind::Dense; }
    /// The matrix entries one solve reads: the inverse's n^2 on the dense path, else the strictly
    /// lower factor's (read twice, forward and back, with D between). What bench/roofline.py counts.
    Eigen::Index entriesRead() const {
        return kind_ == Kind::Dense ? inverse_.size() : kind_ == Kind::Band ? band_.rows() * bandwidth_ : L_.nonZeros();
    }

private:
    /// Factors m as a band of `bandwidth` below the diagonal, in its own order.
    void factorBand(const Eigen::SparseMatrix<double>& m, int bandwidth, const char* what);
    void solveBand(const Points& b, Points& x) const;
    /// Throws unless every pivot in D is positive and finite (a singular or indefinite system).
    static void checkPivots(const Eigen::VectorXd& D, const char* what);

    /// Eigen's factor, which also says how many entries it will hold from the symbolic analysis
    /// alone (it sizes the factor then), so a band is chosen before any numeric work.
    struct CountedLdlt : Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> {
        Eigen::Index analysedEntries(const Eigen::SparseMatrix<double>& m) {
            analyzePattern(m);
            return this->m_matrix.nonZeros();
        }
    };

    Kind kind_ = Kind::Sparse;
    CountedLdlt ldlt_;
    Eigen::SparseMatrix<double> L_;  // unit lower factor, CSC (strictly lower part stored)
    Eigen::VectorXd invD_;
    Eigen::VectorXi perm_;           // (P b)[perm_[i]] = b[i]
    mutable Points work_;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> inverse_;  // dense path only
    // Band path: row i holds L(i, i - bw .. i - 1), then D(i); rows near the top start with zeros.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> band_;
    int bandwidth_ = 0;
    mutable Eigen::VectorXd bx_, by_, bz_;
    int n_ = 0;
    bool ready_ = false;
};

}  // namespace hs
