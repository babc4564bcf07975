// The matrix A of d = A p: the (rational) basis of the poles at the g x h mesh parameters.
#pragma once
#include <Eigen/Sparse>
#include <vector>

#include "common/grid_rect.hpp"
#include "geometry/bspline_surface.hpp"

namespace hs {

/// Row-compressed sparse matrix with 3-column (x, y, z) products that never allocate.
struct CsrMatrix {
    int rows = 0, cols = 0;
    std::vector<int> rowStart, col;
    std::vector<double> value;
    void multiply(const Points& x, Points& y) const;            ///< y = M x
    void multiplyTransposed(const Points& x, Points& y) const;  ///< y = M^T x
    Eigen::SparseMatrix<double> toEigen() const;
};

/// Basis of the poles at the sample parameters; mesh point a*h + b sits at (u_a, v_b),
/// parameters uniform over the knot domain. Non-rational surfaces use the tensor-product
/// structure A = Au (x) Av, which makes A p and A^T f about three times cheaper.
class SamplingOperator {
public:
    SamplingOperator() = default;
    SamplingOperator(const BSplineSurface& surface, int g, int h);

    int g() const { return g_; }
    int h() const { return h_; }
    int rows() const { return g_ * h_; }
    int cols() const { return nu_ * nv_; }
    int nu() const { return nu_; }
    int nv() const { return nv_; }
    double u(int a) const { return u_[a]; }
    double v(int b) const { return v_[b]; }
    const std::vector<double>& us() const { return u_; }
    const std::vector<double>& vs() const { return v_; }
    const CsrMatrix& matrix() const { return A_; }

    void apply(const Points& p, Points& d) const;           ///< d = A p
    void applyTransposed(const Points& f, Points& fp) const;  ///< fp = A^T f

    // --- rectangles (regional steps; non-rational surfaces only, where A = Au (x) Av) ---------
    bool separable() const { return separable_; }
    /// The mesh points whose basis reaches a pole of the rectangle `poles` (a rectangle of the
    /// nu x nv net): all that move when only those poles do.
    GridRect meshOf(const GridRect& poles) const;
    /// The poles whose basis reaches a point of the rectangle `mesh`.
    GridRect polesOf(const GridRect& mesh) const;
    /// The rows `mesh` (a rectangle of the g x h mesh) of d = A p; the other rows are not written.
    void applyTo(const Points& p, Points& d, const GridRect& mesh) const;
    /// The rows `poles` of fp = A^T f with f read on `mesh` only (meshOf(poles) or more); the other
    /// rows of fp are not written.
    void applyTransposedTo(const Points& f, Points& fp, const GridRect& poles, const GridRect& mesh) const;

    /// Derivative operators (d/du, d/dv, d2/du2, d2/dudv, d2/dv2 of the basis at the samples),
    /// built on the first call only: curvature is paid for only when requested.
    const std::vector<CsrMatrix>& derivativeOperators(const BSplineSurface& surface) const;

private:
    int g_ = 0, h_ = 0, nu_ = 0, nv_ = 0, p_ = 0, q_ = 0;
    std::vector<double> u_, v_;
    CsrMatrix A_;
    bool separable_ = false;
    std::vector<int> uStart_, vStart_;     // first pole index of each sample row/column
    std::vector<double> uBasis_, vBasis_;  // (p+1) values per u sample, (q+1) per v sample
    mutable Points tmp_;                   // nu*h intermediate for the separable path
    mutable std::vector<CsrMatrix> derivatives_;
};

}  // namespace hs
