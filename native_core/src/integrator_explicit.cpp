// The paper's explicit scheme (eq. 8-9): p' += dt p'';  p += dt p' (forward Euler on the control
// points), with the step recursively halved while the acceleration after a trial step exceeds
// SolverSettings::accelerationLimit.
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
    p += dt * v_;
    v_ += dt * acc_;
    A_.apply(p, d_);
    computeAcceleration();
    const double amax = acc_.cwiseAbs().maxCoeff();
    const bool ok = std::isfinite(amax) && amax <= solver.accelerationLimit;
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
