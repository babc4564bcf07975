// The paper's explicit scheme (eq. 8-9) with its adaptive step: the step is recursively halved while
// the acceleration after a trial step exceeds SolverSettings::accelerationLimit.
// Eq. 9 read literally (p += dt * old velocity) is forward Euler, which amplifies every undamped
// spring mode by 1 + (w dt)^2 per step whatever the step size; we update the position with the new
// velocity (semi-implicit Euler), which has the same cost, conserves energy for small steps and is
// stable for dt < 2 / w_max.
#include <cmath>

#include "dynamic_surface.hpp"

namespace hs {

void DynamicSurface::computeAcceleration() {
    A_.apply(v_, dd_);
    meshForces(d_, dd_, 0.0);
    A_.applyTransposed(force_, fp_);
    massSolver_.solve(fp_, acc_);
    accelerationValid_ = true;
}

StepReport DynamicSurface::stepExplicit(double dt) {
    StepReport r;
    ensureMassFactor();
    applyToolForces(dt, r);
    stepDt_ = dt;
    explicitSubstep(dt, 0, r);
    return r;
}

void DynamicSurface::explicitSubstep(double dt, int depth, StepReport& r) {
    if (!accelerationValid_) computeAcceleration();
    // One saved state suffices: a rejected trial always restarts from the current substep's start.
    p0_ = surface_.poles();
    v0_ = v_;
    a0_ = acc_;
    Points& p = surface_.mutablePoles();
    v_ += dt * acc_;
    p += dt * v_;
    A_.apply(p, d_);
    computeAcceleration();
    const double amax = acc_.cwiseAbs().maxCoeff();
    const double limit = solver.accelerationLimit > 0 ? solver.accelerationLimit : 0.1 * size_ / (stepDt_ * stepDt_);
    const bool ok = std::isfinite(amax) && amax <= limit;
    if (ok || depth >= solver.maxHalvings) {
        ++r.substeps;
        return;
    }
    p = p0_;
    v_ = v0_;
    acc_ = a0_;
    A_.apply(p, d_);
    explicitSubstep(0.5 * dt, depth + 1, r);
    explicitSubstep(0.5 * dt, depth + 1, r);
}

}  // namespace hs
