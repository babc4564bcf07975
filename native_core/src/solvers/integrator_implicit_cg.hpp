// Linearised backward Euler solved by a fixed number of conjugate-gradient iterations
// (integrator_implicit_cg.cpp).
#pragma once
#include "solvers/step_model.hpp"

namespace hs {

class ImplicitCgIntegrator {
public:
    explicit ImplicitCgIntegrator(Eigen::Index poles);
    StepReport step(StepModel& m, double dt);

private:
    Points r_, z_, p_, q_;  // the conjugate-gradient vectors (the preconditioner is the system's)
    Points dv_;             // the velocity change being solved for
};

}  // namespace hs
