// Local/global's explicit branch: velocity Verlet where it is provably stable (integrator_verlet.cpp).
#pragma once
#include <vector>

#include "solvers/step_model.hpp"
#include "solvers/verlet_stability_bound.hpp"

namespace hs {

class VerletIntegrator {
public:
    explicit VerletIntegrator(Eigen::Index poles);
    /// Whether a Verlet step of dt is stable in the current configuration (the bound, lazily).
    bool stable(StepModel& m, double dt);
    /// The longest step it is stable for (0 where it is never taken: switched off, non-linear laws,
    /// curvature constraints, a tool of unknown slope).
    double stepLimit(StepModel& m);
    StepReport step(StepModel& m, double dt);
    /// The internal forces' acceleration carried over no longer belongs to the state.
    void invalidate() { valid_ = false; }
    /// The potential energy at the last step's end, for the energy guard (-1: none this step).
    double stepPotential() const { return stepPotential_; }
    void clearStepPotential() { stepPotential_ = -1; }

private:
    /// The tool's and the pull's share of the omega^2 bound; infinite where Verlet is never taken.
    double toolTerm(const StepModel& m) const;
    /// Largest damping rate (explicit here too): the material's and the pull's.
    static double dampingRate(const StepModel& m);
    /// scratch.poleStep = (A^T M A)^-1 A^T (external + tool forces), over the poles they reach only.
    void solveApplied(StepModel& m);

    Points a_;                       // the internal forces' acceleration at the step's start (first same as last)
    std::vector<int> appliedPoles_;  // the poles the applied forces reach (reserved)
    std::vector<char> poleMark_;
    bool valid_ = false;             // a_ belongs to the current state
    double stepPotential_ = -1;
    VerletStabilityBound bound_;
};

}  // namespace hs
