// A tensor-product B-spline surface, optionally rational with fixed weights.
#pragma once
#include "geometry/knot_vector.hpp"
#include "common/types.hpp"

namespace hs {

/// Position and partial derivatives of a surface at one (u, v).
struct SurfaceDerivatives {
    Vec3 s, su, sv, suu, suv, svv;
};

/// Normal curvatures along the u and v iso-directions, principal, mean and Gaussian curvature.
/// Signs follow the unit normal su x sv / |su x sv|.
struct Curvature {
    double ku = 0, kv = 0, kmin = 0, kmax = 0, mean = 0, gauss = 0;
};

/// Curvature from first and second derivatives (fundamental forms); zero where the surface is singular.
Curvature curvatureFrom(const SurfaceDerivatives& d);

/// Poles are stored row-major with index i*nv + j (i along u), the layout of Part.BSplineSurface.
class BSplineSurface {
public:
    /// Validates every argument and throws std::invalid_argument naming the faulty one.
    BSplineSurface(int nu, int nv, int degreeU, int degreeV, std::vector<double> knotsU, std::vector<double> knotsV,
                   Points poles, Eigen::VectorXd weights /* empty = non-rational */);

    /// Flat (z = 0) clamped-uniform patch of size (sx, sy) centred at the origin.
    static BSplineSurface plane(int nu, int nv, int degreeU, int degreeV, double sx, double sy);

    int nu() const { return ku_.count(); }
    int nv() const { return kv_.count(); }
    const KnotVector& knotsU() const { return ku_; }
    const KnotVector& knotsV() const { return kv_; }
    bool rational() const { return weights_.size() > 0; }
    const Eigen::VectorXd& weights() const { return weights_; }
    const Points& poles() const { return poles_; }
    Points& mutablePoles() { return poles_; }

    /// Point and derivatives (second ones only if order == 2) at (u, v); (u, v) is clamped to the domain.
    SurfaceDerivatives evaluate(double u, double v, int order = 2) const;
    Vec3 normal(double u, double v) const;
    Curvature curvature(double u, double v) const { return curvatureFrom(evaluate(u, v, 2)); }
    /// Largest grid side grid() takes; throws std::invalid_argument unless 2 <= nu, nv <= it.
    static constexpr int kMaxGrid = 4096;
    static void checkGridSize(int nu, int nv);
    /// Exact points and unit normals on an nu x nv grid evenly spaced over the domain, into
    /// (nu, nv, 3) row-major buffers (for displays that shade per pixel).
    void grid(int nu, int nv, double* points, double* normals) const;

    /// Basis (rational if weighted) of the poles at (u, v) and its derivatives: calls
    /// visit(poleIndex, R, Ru, Rv, Ruu, Ruv, Rvv) for each of the (p+1)(q+1) non-zero entries.
    template <class Visit>
    void visitBasis(double u, double v, int order, Visit&& visit) const;

private:
    KnotVector ku_, kv_;
    Points poles_;
    Eigen::VectorXd weights_;
};

template <class Visit>
void BSplineSurface::visitBasis(double u, double v, int order, Visit&& visit) const {
    Eigen::Matrix<double, 3, kMaxDegree + 1> bu, bv;
    const int su = ku_.basis(u, order, bu), sv = kv_.basis(v, order, bv);
    const int p = ku_.degree(), q = kv_.degree(), n = nv();
    if (!rational()) {
        for (int a = 0; a <= p; ++a)
            for (int b = 0; b <= q; ++b)
                visit((su - p + a) * n + (sv - q + b), bu(0, a) * bv(0, b), bu(1, a) * bv(0, b), bu(0, a) * bv(1, b),
                      bu(2, a) * bv(0, b), bu(1, a) * bv(1, b), bu(0, a) * bv(2, b));
        return;
    }
    // Quotient rule on R = N w / W with W = sum N w.
    double W = 0, Wu = 0, Wv = 0, Wuu = 0, Wuv = 0, Wvv = 0;
    for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= q; ++b) {
            const double w = weights_[(su - p + a) * n + (sv - q + b)];
            W += w * bu(0, a) * bv(0, b);
            Wu += w * bu(1, a) * bv(0, b);
            Wv += w * bu(0, a) * bv(1, b);
            Wuu += w * bu(2, a) * bv(0, b);
            Wuv += w * bu(1, a) * bv(1, b);
            Wvv += w * bu(0, a) * bv(2, b);
        }
    const double iw = 1.0 / W;
    for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= q; ++b) {
            const int idx = (su - p + a) * n + (sv - q + b);
            const double w = weights_[idx];
            const double N = w * bu(0, a) * bv(0, b), Nu = w * bu(1, a) * bv(0, b), Nv = w * bu(0, a) * bv(1, b);
            const double Nuu = w * bu(2, a) * bv(0, b), Nuv = w * bu(1, a) * bv(1, b), Nvv = w * bu(0, a) * bv(2, b);
            const double R = N * iw;
            const double Ru = (Nu - Wu * R) * iw, Rv = (Nv - Wv * R) * iw;
            const double Ruu = (Nuu - 2 * Wu * Ru - Wuu * R) * iw;
            const double Ruv = (Nuv - Wu * Rv - Wv * Ru - Wuv * R) * iw;
            const double Rvv = (Nvv - 2 * Wv * Rv - Wvv * R) * iw;
            visit(idx, R, Ru, Rv, Ruu, Ruv, Rvv);
        }
}

}  // namespace hs
