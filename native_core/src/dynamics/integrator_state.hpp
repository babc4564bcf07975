// What each integrator keeps between and within steps (DynamicSurface owns one of each; all are
// sized once, so stepping never allocates).
#pragma once
#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <vector>

#include "common/types.hpp"

namespace hs {

/// Explicit (paper eq. 8-9): the substep's start, and the energy where the acceleration was computed.
struct ExplicitState {
    Points p0, v0, a0;
    double energy = 0;
};

/// Linearised backward Euler: the conjugate-gradient vectors (the Jacobi preconditioner is the
/// system's, DynamicSurface::SystemSlot).
struct CgState {
    Points r, z, p, q;
};

/// Local/global BDF2: the state one step back (poles, velocities, mesh, A v) taken at step `dt`,
/// and x^ = (4 x_n - x_n-1) / 3 on the poles and the mesh.
/// `valid`: the history is the previous step's (cleared where the applied forces jump: external
/// forces set or cleared, a grab or a release). BDF2 extrapolates the acceleration from its
/// history, so across a jump it overshoots: a force held for one step from rest and then removed
/// left 16/9 of the kinetic energy it put in. Restarting (the history synthesised from the new
/// forces) is the textbook cure for multistep methods.
struct Bdf2History {
    Points p, v, d, av, xHat, dHat;
    double dt = 0;
    bool valid = false;
};

/// Velocity Verlet (local/global's explicit branch): the internal forces' acceleration at the
/// step's start (first same as last), the poles the applied forces reach, and the potential
/// energy at the step's end for the energy guard (-1: none).
struct VerletState {
    Points a;
    std::vector<int> appliedPoles;  // (reserved)
    std::vector<char> poleMark;
    bool valid = false;  // `a` belongs to the current state (cleared by anything moving it)
    double stepPotential = -1;
};

/// Bounds on omega_max^2 of the springs and penalty terms in control space for the configuration
/// `key` (upper infinite where unknown; `tight`: the upper bound from Lanczos for exactly this
/// configuration), and the snapshot they were computed at (stiffnesses, masses, constraint
/// structure, bounds), which map changes rescale (verlet_stability_bound.cpp).
struct OmegaBounds {
    std::uint64_t key[4] = {~0ull, ~0ull, ~0ull, ~0ull};
    double upper = std::numeric_limits<double>::infinity(), lower = 0;
    bool tight = false;
    Eigen::VectorXd snapK, snapM, snapBending;  // (bending: the bending energy's row weights)
    std::uint64_t snapStructure = 0;
    double snapUpper = 0, snapLower = 0;
};

/// The state a step started from, for a refused step.
struct StepBackup {
    Points p, v;
};

}  // namespace hs
