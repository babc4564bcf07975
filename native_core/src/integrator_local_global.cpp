// Backward Euler by local/global iterations (Liu et al. 2013, "Fast Simulation of Mass-Spring
// Systems") carried into the reduced control-point space. Springs and penalty constraints are all
// terms 1/2 k |x_a - x_b - t|^2, so one step solves
//   A^T (M + dt D + dt^2 L) A p' = A^T [ M (d + dt d') + dt D d + dt^2 (f_ext + J t) ]
// alternating the projection of t (local) with a solve by the prefactored system (global).
// The matrix depends only on dt, materials and which constraints exist: it is factored once.
#include <algorithm>
#include <cmath>

#include "dynamic_surface.hpp"

namespace hs {

StepReport DynamicSurface::stepLocalGlobal(double dt) {
    StepReport r;
    ensureSystem(dt, true);
    applyToolForces(dt, r);
    const Points& p = surface_.poles();
    x_ = p + dt * v_;
    if (avValid_) meshTmp_ = d_ + dt * av_;  // predicted mesh d + dt A v, without a product by A
    else A_.apply(x_, meshTmp_);
    base_ = m_.asDiagonal() * meshTmp_ + (dt * gamma_).asDiagonal() * d_;
    if (hasExternal_) base_ += (dt * dt) * fext_;
    if (toolForces_) base_ += (dt * dt) * ftool_;
    if (dampingLaw.kind != LawKind::Linear) {
        // Extra non-linear damping, explicit, limited to dt * extra / m <= 1 so it cannot destabilise.
        force_.setZero();
        springs_.addForces(d_, force_);
        for (Eigen::Index i = 0; i < d_.rows(); ++i) {
            const double extra = (dampingLaw.dampingFactor(force_.row(i).norm()) - 1.0) * gamma_[i];
            const double limited = std::min(extra, m_[i] / dt);
            base_.row(i) -= dt * limited * (meshTmp_.row(i) - d_.row(i));  // dt^2 * extra * d'
        }
    }
    double change = 0;
    for (int it = 0; it < solver.iterations; ++it) {
        if (it > 0) A_.apply(x_, meshTmp_);
        meshTmp2_ = base_;  // + dt^2 J t, added in place by the local steps
        springs_.addProjections(meshTmp_, meshTmp2_, 0.25 * minMass_ / (dt * dt), dt * dt);
        if (!constraints_.empty()) constraints_.addProjections(meshTmp_, meshTmp2_, terms_, dt * dt);
        A_.applyTransposed(meshTmp2_, fp_);
        systemSolver_.solve(fp_, acc_);
        change = (acc_ - x_).cwiseAbs().maxCoeff();
        x_ = acc_;
        ++r.iterations;
    }
    r.residual = change / size_;
    v_ = (x_ - p) / dt;
    surface_.mutablePoles() = x_;
    A_.apply(surface_.poles(), d_);
    av_ = (d_ - dPrev_) / dt;  // = A v up to rounding, since A is linear (dPrev_: step()'s copy of the old mesh)
    avValid_ = true;
    accelerationValid_ = false;
    return r;
}

}  // namespace hs
