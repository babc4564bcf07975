// Implicit time stepping by local/global iterations (Liu et al. 2013, "Fast Simulation of Mass-
// Spring Systems") carried into the reduced control-point space. Springs and penalty constraints
// are all terms 1/2 k |x_a - x_b - t|^2, so one step solves
//   A^T (M + h D + h^2 L) A p' = A^T [ M y + h D x^ + h^2 (f_ext + J t) ]
// alternating the projection of t (local) with a solve by the prefactored system (global).
// Backward Euler (order 1) has x^ = x_n, y = x_n + dt v_n, h = dt. BDF2 (order 2, the default;
// beyond the paper and Liu et al.) has the same form with
//   x^ = (4 x_n - x_n-1) / 3,  v^ = (4 v_n - v_n-1) / 3,  y = x^ + h v^,  h = 2 dt / 3,
// and v_n+1 = (x_n+1 - x^) / h, so it costs the same per step: one matrix, factored once.
// Without history (first step, after an edit) BDF2 starts from x_n-1 = x_n - dt v_n, v_n-1 = v_n.
#include <algorithm>
#include <cmath>

#include "dynamic_surface.hpp"

namespace hs {

double DynamicSurface::predictorWeight(double dt) const {
    // The prediction d_n + dt A v_n + dt^2/2 A a_n (a_n from the BDF2 history) is O(dt^3) off the
    // step's end, where the inertial prediction y is O(dt^2) off: one iteration from it stays second
    // order (17x smaller error at 16 us in bench/time_vs_error.py). Extrapolation feeds the stiffest
    // modes back explicitly and is unstable past rho = dt^2 omega_max^2 ~ 2.7 (omega_max^2 <= 8 k /
    // m_min, k the stiffest spring or moving penalty term), so its weight falls as 1/rho^2 past
    // rho = 1. Non-linear laws can stiffen a spring by up to m / (4 h^2): no prediction there.
    if (springs_.law.kind != LawKind::Linear) return 0.0;
    const double k = std::max(maxStiffness_, constraints_.maxMovingStiffness());
    const double rho = dt * dt * 8 * k / minMass_;
    const double w = rho <= 1 ? 1.0 : 1.0 / (rho * rho);
    return w > 1e-6 ? w : 0.0;
}

StepReport DynamicSurface::stepLocalGlobal(double dt) {
    StepReport r;
    const bool bdf2 = solver.timeOrder == 2;
    const double h = bdf2 ? 2.0 * dt / 3.0 : dt;
    ensureSystem(h, true);
    applyToolForces(dt, r);
    const Points& p = surface_.poles();
    if (!avValid_) A_.apply(v_, av_);
    const Points* dBase = &d_;  // x^ on the mesh
    if (bdf2) {
        if (!histValid_ || histDt_ != dt) {
            pHist_ = p - dt * v_;
            vHist_ = v_;
            dHist_ = d_ - dt * av_;
            avHist_ = av_;
        }
        xHat_ = (4.0 / 3.0) * p - (1.0 / 3.0) * pHist_;
        x_ = xHat_ + h * ((4.0 / 3.0) * v_ - (1.0 / 3.0) * vHist_);
        dHat_ = (4.0 / 3.0) * d_ - (1.0 / 3.0) * dHist_;
        meshTmp_ = dHat_ + h * ((4.0 / 3.0) * av_ - (1.0 / 3.0) * avHist_);
        dBase = &dHat_;
    } else {
        x_ = p + dt * v_;
        meshTmp_ = d_ + dt * av_;  // predicted mesh d + dt A v, without a product by A
    }
    base_ = m_.asDiagonal() * meshTmp_ + (h * gamma_).asDiagonal() * *dBase;
    if (hasExternal_) base_ += (h * h) * fext_;
    if (toolForces_) base_ += (h * h) * ftool_;
    if (dampingLaw.kind != LawKind::Linear) {
        // Extra non-linear damping, explicit, limited to h * extra / m <= 1 so it cannot destabilise.
        force_.setZero();
        springs_.addForces(d_, force_);
        for (Eigen::Index i = 0; i < d_.rows(); ++i) {
            const double extra = (dampingLaw.dampingFactor(force_.row(i).norm()) - 1.0) * gamma_[i];
            const double limited = std::min(extra, m_[i] / h);
            base_.row(i) -= h * limited * (meshTmp_.row(i) - dBase->row(i));  // h^2 * extra * v^
        }
    }
    // The first local step projects at the end of the step predicted to O(dt^3) (predictorWeight).
    const double w = bdf2 ? predictorWeight(dt) : 0.0;
    if (w > 0) meshTmp_ += w * (d_ + dt * av_ + (0.5 * dt) * (av_ - avHist_) - meshTmp_);
    double change = 0;
    for (int it = 0; it < solver.iterations; ++it) {
        if (it > 0) A_.apply(x_, meshTmp_);
        meshTmp2_ = base_;  // + h^2 J t, added in place by the local steps
        springs_.addProjections(meshTmp_, meshTmp2_, 0.25 * minMass_ / (h * h), h * h);
        if (!constraints_.empty()) constraints_.addProjections(meshTmp_, meshTmp2_, terms_, h * h);
        A_.applyTransposed(meshTmp2_, fp_);
        systemSolver_.solve(fp_, acc_);
        change = (acc_ - x_).cwiseAbs().maxCoeff();
        x_ = acc_;
        ++r.iterations;
    }
    r.residual = change / size_;
    if (bdf2) {
        v_ = (x_ - xHat_) / h;
        // History for the next step: the state this step started from (step()'s backups).
        pHist_ = pStep_;
        vHist_ = vStep_;
        dHist_ = dPrev_;
        avHist_.swap(av_);
    } else {
        v_ = (x_ - p) / dt;
    }
    surface_.mutablePoles() = x_;
    A_.apply(surface_.poles(), d_);
    // A v up to rounding, since A is linear, without a product by A
    if (bdf2) av_ = (d_ - dHat_) / h;
    else av_ = (d_ - dPrev_) / dt;
    avValid_ = true;
    histValid_ = bdf2;
    histDt_ = dt;
    accelerationValid_ = false;
    return r;
}

}  // namespace hs
