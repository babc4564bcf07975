// The paper's explicit scheme (eq. 8-9) with its adaptive step (integrator_explicit.cpp).
#pragma once
#include "solvers/step_model.hpp"

namespace hs {

class ExplicitIntegrator {
public:
    explicit ExplicitIntegrator(Eigen::Index poles);
    StepReport step(StepModel& m, double dt);
    /// The acceleration carried from the last substep no longer belongs to the state.
    void invalidate() { valid_ = false; }

private:
    void substep(StepModel& m, double dt, int depth, StepReport& r);
    void accelerate(StepModel& m) { energy_ = m.acceleration(a_); valid_ = true; }

    Points a_;               // the acceleration at the current state, where valid_
    Points p0_, v0_, a0_;    // the substep's start (a rejected trial restarts from it)
    double energy_ = 0;      // the energy where a_ was computed
    bool valid_ = false;
};

}  // namespace hs
