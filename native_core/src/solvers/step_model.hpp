// What an integrator sees of a dynamic surface: its state, material, forces, hard constraints,
// factored systems and shared work buffers, and the operations that need several of them. This is
// the narrow interface between DynamicSurface (which owns the parts, guards the step and decides
// which integrator runs) and the integrators (integrator_*.hpp), which step the state it gives them.
#pragma once
#include <Eigen/SparseCore>
#include <cstdint>

#include "dynamics/held_poles.hpp"
#include "dynamics/material.hpp"
#include "dynamics/mirror_symmetry.hpp"
#include "dynamics/surface_state.hpp"
#include "solvers/active_region.hpp"
#include "solvers/solver_settings.hpp"
#include "solvers/surface_forces.hpp"
#include "solvers/system_cache.hpp"

namespace hs {

/// Work buffers the integrators share (one runs at a time), sized once.
struct Scratch {
    Scratch(Eigen::Index meshPoints, Eigen::Index poles);
    Points meshVelocity;  ///< A v where a step needs it fresh
    Points mesh, mesh2;   ///< mesh-sized
    Points poleForce;     ///< A^T f
    Points poleStep;      ///< a solve's result: an acceleration or an increment
};

struct StepModel {
    SurfaceState& state;
    Material& material;
    SurfaceForces& forces;
    const HeldPoles& held;
    const MirrorSymmetry& mirror;
    SystemCache& systems;
    Scratch& scratch;
    const SolverSettings& settings;
    const ActiveRegion& region;  ///< what the step moves (the whole net, or a region of it)
    SystemCache::RegionSlot* regionSystem = nullptr;  ///< the region's system, once ensured

    /// What the factored systems' structure depends on: the constraints' and the held poles'
    /// (both versions only grow, so the sum changes whenever either does).
    std::uint64_t structureKey() const { return forces.constraints().structureVersion() + held.version(); }
    /// Laplacian of the springs and penalty terms, and the bending matrix, on the mesh (S x S, per coordinate).
    Eigen::SparseMatrix<double> laplacian() const;
    /// The mass matrix A^T M A, factored for the current masses and held set.
    void ensureMass();
    /// The system matrix A^T (M + dt D + dt^2 L) A for dt, its Jacobi diagonal and, with `factor`,
    /// its factors, as the current slot of the cache; throws std::invalid_argument naming dt where
    /// dt is too long to factor.
    void ensureSystem(double dt, bool factor);
    /// The system for dt, factored, as solveSystem() uses it: the whole net's (ensureSystem), or on
    /// a regional step the region's, cut from the whole one (built but not factored).
    void ensureStepSystem(double dt);
    /// x = S^-1 b on the free poles, by the system of ensureStepSystem(): on a regional step only
    /// the region's rows of b are read and of x written.
    void solveSystem(const Points& b, Points& x);
    /// Changes whenever the system solveSystem() uses is rebuilt.
    std::uint64_t systemBuild() const { return regionSystem ? regionSystem->built : systems.current().built; }
    /// The tool's force on the mesh `at` (the current mesh, or a prediction of the step's end);
    /// returns whether the applied forces changed.
    bool applyTool(double dt, StepReport& r, const Points& at, double phase = 1.0) {
        return forces.applyTool(at, state.g(), state.h(), state.spacingU, state.spacingV, mirror, dt, r.reaction, phase);
    }
    /// The tool's slope on a mesh point; twice it with symmetry (the mirrored tool may hold the same point).
    double toolSlope() const { return (mirror.empty() ? 1.0 : 2.0) * forces.tool().slope(); }
    /// acc = (A^T M A)^-1 A^T f of all forces at the current state (needs the mass factor); returns
    /// the elastic plus kinetic energy. Uses scratch.meshVelocity and scratch.poleForce.
    double acceleration(Points& acc);
};

}  // namespace hs
