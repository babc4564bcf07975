// Fairing (the Fair operation): the poles that balance the shape's curvature variation, weighted
// per mesh point, against staying where they are, with every hard constraint kept:
//   min_p  (p - p0)^T A^T M A (p - p0) + tau p^T A^T C^T W C A p
// with C the third differences of the mesh (x_uuu, x_uuv, x_uvv, x_vvv: the gradient of the
// curvature, |grad^3 x|^2 = |x_uuu|^2 + 3 |x_uuv|^2 + 3 |x_uvv|^2 + |x_vvv|^2), whose null space
// is the quadratic shapes: a sphere, a cylinder or a plane stays what it is, waves and tents relax.
// Solved in the free poles (P = T z, held_poles.hpp) for the increment, then put through setPoles
// (linked poles onto their masters, the mirror projection). tau = strength x trace(A^T M A) /
// trace(A^T C^T C A): strength 1 weighs the curvature variation of the control net's own modes as
// much as their displacement.
#include <cmath>
#include <stdexcept>
#include <vector>

#include "solvers/curvature_variation.hpp"
#include "solvers/dynamic_surface.hpp"

namespace hs {


void DynamicSurface::fair(const Eigen::VectorXd& weights, double strength) {
    if (weights.size() != state_.d.rows()) throw std::invalid_argument("weights: one per mesh point (g x h)");
    if (!weights.allFinite() || weights.minCoeff() < 0 || weights.maxCoeff() > 1)
        throw std::invalid_argument("weights: must be in [0, 1]");
    requireInRange(strength, "strength", 0.0, 1e12);
    if (strength == 0 || weights.maxCoeff() == 0) return;
    refreshMaterials();
    std::vector<int> centre;
    const Eigen::SparseMatrix<double> C = curvatureVariation(g(), h(), state_.spacingU, state_.spacingV, centre);
    Eigen::VectorXd w(C.rows());
    for (Eigen::Index r = 0; r < C.rows(); ++r) w[r] = weights[centre[static_cast<std::size_t>(r)]];
    const Eigen::SparseMatrix<double> A = state_.A.matrix().toEigen();
    const Eigen::SparseMatrix<double> CA = C * A;
    const Eigen::SparseMatrix<double> M = A.transpose() * material_.masses().asDiagonal() * A;
    const Eigen::SparseMatrix<double> K = CA.transpose() * w.asDiagonal() * CA;
    const double scale = M.diagonal().sum() / CA.squaredNorm();  // trace(A^T C^T C A) = |C A|_F^2
    const double tau = strength * scale;
    Eigen::SparseMatrix<double> sys = M + tau * K;
    held_.restrict(sys, true);
    Points rhs = -tau * (K * state_.poles());
    held_.reduce(rhs);
    PrefactoredSolver solver;
    solver.factor(sys, "fairing system A^T (M + tau C^T W C) A");
    Points step(rhs.rows(), 3);
    solver.solve(rhs, step);
    held_.expand(step);
    setPoles(state_.poles() + step);
}

}  // namespace hs
