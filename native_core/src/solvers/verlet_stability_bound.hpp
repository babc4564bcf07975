// A bound on omega_max^2 of the springs and penalty terms in control space, the stability limit of
// local/global's Verlet branch (verlet_stability_bound.cpp).
#pragma once
#include <Eigen/Core>
#include <cstdint>
#include <limits>

#include "solvers/step_model.hpp"

namespace hs {

class VerletStabilityBound {
public:
    /// Whether omega_max^2 is provably below `limit` for the current masses, stiffnesses and
    /// constraints; `tight` makes upper() the computed bound. Allocates when it recomputes (a new
    /// configuration).
    bool below(StepModel& m, double limit, bool tight = false);
    double upper() const { return upper_; }

private:
    void rescale(const StepModel& m);
    void compute(StepModel& m, double limit);

    // The bounds for the configuration `key_` (upper infinite where unknown; tight: the upper bound
    // from Lanczos for exactly this configuration).
    std::uint64_t key_[4] = {~0ull, ~0ull, ~0ull, ~0ull};
    double upper_ = std::numeric_limits<double>::infinity(), lower_ = 0;
    bool tight_ = false;
    // The snapshot they were computed at, which map changes rescale: stiffnesses, masses, the
    // bending energy's row weights, the constraint structure, the bounds.
    Eigen::VectorXd snapK_, snapM_, snapBending_;
    std::uint64_t snapStructure_ = 0;
    double snapUpper_ = 0, snapLower_ = 0;
};

}  // namespace hs
