// How the surface is stepped: the integrators, their settings, and what a step reports.
#pragma once
#include <array>

#include "common/names.hpp"
#include "tools_and_constraints/tool.hpp"

namespace hs {

/// Shortest step: below it rounding in the positions (1e-16 of the size) turns into velocities
/// above 1e-7 of the size per second, and backward Euler's velocity (x' - x) / dt into noise.
constexpr double kMinDt = 1e-9;

enum class IntegratorKind {
    Explicit,     ///< paper eq. 8-9 with recursive step halving
    ImplicitCG,   ///< linearised backward Euler, a fixed number of conjugate-gradient iterations
    LocalGlobal,  ///< BDF2 (or backward Euler) by prefactored local/global iterations in control space,
                  ///< velocity Verlet where that is provably stable (default)
};

inline constexpr std::array<Named<IntegratorKind>, 3> kIntegratorNames{{
    {"explicit", IntegratorKind::Explicit}, {"implicit", IntegratorKind::ImplicitCG},
    {"local_global", IntegratorKind::LocalGlobal}}};

/// Local/global takes an explicit velocity Verlet step instead where that is provably stable
/// (integrator_verlet.cpp): omega_max dt below this, omega_max bounded by the springs' and penalty
/// terms' Laplacian (which bounds their Hessian for linear laws) and the tool's slope.
constexpr double kVerletStability = 1.8;

/// Regional steps (active_region.hpp): whether they are taken and how the region is chosen.
struct RegionSettings {
    bool enabled = false;  ///< take regional steps where the scene allows them
    int margin = 4;        ///< quiet poles kept free around the moving ones
    /// A pole moves when its speed exceeds this fraction of the fastest pole's (or the sleep
    /// tolerance, whichever is larger): slower motion the region does not chase.
    double wake = 1e-2;
    static constexpr int kTile = 4;  ///< the region's sides fall on multiples of this many poles
    /// A region of more than this fraction of the net is stepped as the whole net.
    static constexpr double kWholeFraction = 0.6;
    void validate() const {
        requireInRange(margin, "region_margin", 1, 1000);
        requireInRange(wake, "region_wake", 0.0, 1.0);
    }
};

struct SolverSettings {
    IntegratorKind kind = IntegratorKind::LocalGlobal;
    int iterations = 1;              ///< local/global iterations per step
    int timeOrder = 2;               ///< local/global: 1 = backward Euler, 2 = BDF2 (same cost, second order)
    /// local/global: take an explicit velocity Verlet step where it is stable (cheaper, second order,
    /// no numerical damping); the implicit step otherwise
    bool explicitWhenStable = true;
    int cgIterations = 5;            ///< implicit: CG iterations per step
    /// explicit: halve the step while any control-point acceleration exceeds this;
    /// 0 = automatic, 0.1 * size / h^2 for a substep h (no point may be flung a tenth of the surface in one substep)
    double accelerationLimit = 0;
    int maxHalvings = 10;            ///< explicit: deepest recursion (at most 2^10 substeps a step)
    /// explicit: also halve while a substep gains more than this fraction of its energy beyond the work put in
    double energyTolerance = 0.01;
    RegionSettings region;           ///< local/global: step only the region a stroke moves
    /// Throws std::invalid_argument naming the first bad field.
    void validate() const;
};

/// What one call to DynamicSurface::step() did.
struct StepReport {
    int substeps = 0;     ///< explicit: accepted substeps (1 without halving)
    int iterations = 0;   ///< local/global or CG iterations in total
    double residual = 0;  ///< CG: relative residual; local/global: last update / size; explicit: 0
    bool slept = false;   ///< the surface was at rest and was not stepped
    bool verlet = false;  ///< local/global took an explicit velocity Verlet step (stable for this dt)
    bool refused = false; ///< the step would have produced NaN/Inf or created energy; the state was kept
    bool energyLimited = false;  ///< the energy guard stepped in (velocities scaled down or step refused)
    const char* reason = "";
    Reaction reaction;  ///< on the cursor
};

}  // namespace hs
