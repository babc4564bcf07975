// The dynamic B-spline surface of paper section 4: control points p driven through the mesh d = A p
// by  p'' = (A^T M A)^-1 (A^T f_d - A^T D d' - A^T f_springs(d))  (eq. 7).
#pragma once
#include "common/names.hpp"
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "dynamics/bending_energy.hpp"
#include "geometry/bspline_surface.hpp"
#include "tools_and_constraints/constraints.hpp"
#include "dynamics/energy_guard.hpp"
#include "dynamics/held_poles.hpp"
#include "dynamics/integrator_state.hpp"
#include "dynamics/material_map.hpp"
#include "dynamics/mirror_symmetry.hpp"
#include "solvers/prefactored_solver.hpp"
#include "geometry/sampling_operator.hpp"
#include "dynamics/sleep_monitor.hpp"
#include "dynamics/spring_mesh.hpp"
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

/// The bending map's default: off (springs alone, as before it existed). 10 (beta per mesh cell 10 x
/// the stiffness there, api.FAIR_BENDING) makes rope strokes fair (tests/test_fairness.py).
constexpr double kDefaultBending = 0.0;

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
    /// Throws std::invalid_argument naming the first bad field.
    void validate() const;
};

/// The energy guard (energy_guard.hpp) runs only where local/global's descent guarantee does not
/// hold: the explicit and linearised implicit schemes, non-linear spring laws, curvature
/// constraints (projections onto arcs, a non-convex set; point, tangent and normal constraints
/// project onto convex sets), and steps so long for the stiffness and mass that rounding in the
/// solve is no longer negligible. A step past its ceiling has its velocities scaled back to it; one
/// whose potential energy alone is past it is refused (positions kept, motion stopped).

/// What one call to step() did.
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

class DynamicSurface {
public:
    /// Samples `surface` on a g x h mesh; rest lengths come from the initial shape.
    DynamicSurface(BSplineSurface surface, int g, int h);

    // --- geometry --------------------------------------------------------------------------
    const BSplineSurface& surface() const { return surface_; }
    const SamplingOperator& sampling() const { return A_; }
    int g() const { return A_.g(); }
    int h() const { return A_.h(); }
    const Points& poles() const { return surface_.poles(); }
    const Points& velocities() const { return v_; }
    const Points& mesh() const { return d_; }
    const Points& meshVelocities();  ///< A p', computed on request
    double size() const { return size_; }
    /// The initial shape's measures that scale tolerances and tools: size (bounding-box diagonal) and
    /// mean mesh spacing along u and v. Restoring a saved surface sets them back exactly.
    std::array<double, 3> reference() const { return {size_, spacingU_, spacingV_}; }
    void setReference(const std::array<double, 3>& r);
    /// Replaces the poles (e.g. after undo) and zeroes velocities; rest lengths are kept.
    void setPoles(const Points& poles);
    void setVelocities(const Points& v);
    /// Hard constraints (held_poles.hpp): the poles at `indices` stay exactly where they are now
    /// (also through setPoles, which holds them where the new net puts them), the others move as if
    /// they were walls; each of `links` stays the combination of its masters it gives (put there at
    /// once). Replaces both sets; empty lists free them all. Throws std::invalid_argument naming
    /// "indices" or "links" for what is not valid.
    void holdPoles(const std::vector<int>& indices, const std::vector<PoleLink>& links = {});
    const std::vector<int>& heldPoles() const { return held_.indices(); }
    /// Linked poles (held_poles.hpp): each stays the given combination of its masters, exactly.
    const std::vector<PoleLink>& linkedPoles() const { return held_.links(); }
    /// Mirror symmetry (mirror_symmetry.hpp): the surface is its own mirror image in the plane
    /// (point, normal) with parameter `direction` (0: u, 1: v) reversed, and stays so: strokes act
    /// mirrored too, and the poles are put exactly symmetric after every step. Validates (knots,
    /// weights, poles within 1e-6 of the size, the held poles a symmetric set) and then makes the
    /// net exactly symmetric; direction -1 removes it.
    void setSymmetry(int direction, const Vec3& point, const Vec3& normal);
    const MirrorSymmetry& symmetry() const { return mirror_; }
    /// Mesh index nearest to parameter (u, v), and the parameters of a mesh index.
    int meshIndexAt(double u, double v) const;
    std::pair<double, double> meshParameters(int index) const;
    int nearestMeshIndex(const Vec3& x) const { return nearestPoint(d_, x); }

    // --- material ----------------------------------------------------------------------------
    // Changes to the maps and constraints are seen through their version counters: they wake the
    // surface and trigger refactoring at the next step, and nothing else.
    MaterialMap& massMap() { return mass_; }
    MaterialMap& dampingMap() { return damping_; }
    MaterialMap& stiffnessMap() { return stiffness_; }
    /// Bending (thin-plate) weight per mesh cell as a ratio to the stiffness there (bending_energy.hpp); 0: off.
    MaterialMap& bendingMap() { return bendingMap_; }
    const MaterialMap& bendingMap() const { return bendingMap_; }
    /// The bending energy; its reference is the shape the bending measures from: the initial mesh;
    /// with plasticity the shape a stroke leaves at its release, and between strokes it follows
    /// the shape at the plastic rate.
    const BendingEnergy& bending() const { return bending_; }
    void setBendingReference(const Points& reference) { bending_.setReference(reference); wake(); }
    /// Makes the current shape the rest shape: rest lengths and the bending reference from the mesh.
    void relax() { springs_.resetRest(d_); bending_.setReference(d_); wake(); }
    const MaterialMap& massMap() const { return mass_; }
    const MaterialMap& dampingMap() const { return damping_; }
    const MaterialMap& stiffnessMap() const { return stiffness_; }
    SpringMesh& springs() { touch(); resetEnergyCeiling(); return springs_; }
    const SpringMesh& springs() const { return springs_; }
    /// Non-linear damping: multiplier g(F)/F of each point's spring-force magnitude F.
    const ResponseLaw& dampingLaw() const { return dampingLaw_; }
    const Eigen::VectorXd& pointMasses() { refreshMaterials(); return m_; }

    // --- forces, tools and constraints -------------------------------------------------------
    /// Persistent external force on a mesh point (clamped to maxPointForce).
    void setPointForce(int index, const Vec3& force);
    void clearForces();
    const Points& externalForces() const { return fext_; }
    double maxPointForce = 1e6;

    void setTool(const std::string& name);  ///< a tool of the catalogue (toolNames(): rope, magnet, ...)
    Tool& tool() { return *tool_; }
    const Tool& tool() const { return *tool_; }
    /// Latest cursor; a rising grab edge grabs, a falling one releases.
    void setCursor(const Cursor& cursor);
    const Cursor& cursor() const { return cursor_; }
    /// The active tool's local model for the haptic loop (see haptic_estimate.hpp).
    void describeTool(const Reaction& last, HapticEstimate& e) const { tool_->describe(meshView(), last, e); }

    ConstraintSet& constraints() { return constraints_; }
    const ConstraintSet& constraints() const { return constraints_; }
    /// Default penalty stiffness: this factor times the mean material stiffness.
    double constraintStiffnessFactor = 1e3;
    double defaultConstraintStiffness() const { return constraintStiffnessFactor * stiffness_.mean(); }

    // --- stepping -----------------------------------------------------------------------------
    // Settings: each setter checks its argument (std::invalid_argument naming the field) and wakes the surface.
    const SolverSettings& solver() const { return solver_; }
    void setSolver(const SolverSettings& s);
    const SleepSettings& sleep() const { return sleep_.settings; }
    void setSleep(const SleepSettings& s);
    const EnergyGuardSettings& energyGuard() const { return guard_.settings; }
    void setEnergyGuard(const EnergyGuardSettings& s);
    void setPlasticity(const Plasticity& p);
    void setStiffnessLaw(const ResponseLaw& law);
    void setDampingLaw(const ResponseLaw& law);
    /// Advances by dt seconds; never allocates after the first step with a given configuration.
    StepReport step(double dt);
    /// Does ahead what a first step at dt would (factorisations, Verlet's stability bound), so that
    /// a session's first real-time steps do not stall; throws what that step would.
    void prepare(double dt);
    /// Takes over from `live`, a surface of the same sampling that has been stepping: its poles,
    /// velocities and BDF2 history, rest lengths (plastic flow), clock and, if this surface has the
    /// same kind of tool, its tool with the grab (taking this one's settings), and with `keepMaps`
    /// its material maps. What stays is this surface's configuration: constraints, laws, tool
    /// settings, solver settings. An edit made during a session is a configured surface that
    /// continues from the live one (see HapticRuntime::postEdit).
    void continueFrom(DynamicSurface& live, bool keepMaps);
    bool asleep() const { return sleep_.asleep(); }
    void wake() { touch(); resetEnergyCeiling(); }
    std::uint64_t stepCount() const { return steps_; }
    double time() const { return time_; }
    double workDone() const { return work_; }  ///< work of external and tool forces so far
    /// The energy guard's current ceiling (0 while the guard is not running for this scene).
    double energyCeiling() const { return guard_.ceiling(); }
    /// Longest step local/global takes by its explicit Verlet branch in the current configuration
    /// (0 where it never does: switched off, non-linear laws, curvature constraints, smooth tool).
    double verletStepLimit();

    /// Fair (fairing.cpp): relaxes the curvature variation where `weights` (one per mesh point, in
    /// [0, 1]) ask for it, by `strength` (>= 0) against staying put; held and linked poles and
    /// the mirror symmetry hold exactly. Zeroes velocities (as setPoles). Allocates (an edit).
    void fair(const Eigen::VectorXd& weights, double strength);

    // --- measures -----------------------------------------------------------------------------
    double kineticEnergy();
    double potentialEnergy();
    /// Its bending part, 1/2 (d - r)^T K_b (d - r).
    double bendingEnergy() { refreshMaterials(); return bending_.energy(d_); }
    /// Gradient of potentialEnergy() with respect to the poles, -A^T f(d) (springs and constraints).
    const Points& potentialGradient();
    /// Curvature of the circle through interior mesh point `index` and its two neighbours along
    /// u (direction 0) or v (1); throws std::invalid_argument for a boundary point.
    double meshCurvature(int index, int direction) const;
    /// Per mesh point: u and v normal curvature, min and max principal, mean, Gaussian (g*h x 6).
    Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> curvatureGrid() const;

private:
    void touch() { sleep_.wake(); accelerationValid_ = false; verlet_.valid = false; }
    /// The settings setters: check `value` (std::invalid_argument naming the field), store it in
    /// `slot`, wake the surface.
    template <class Settings>
    void configure(Settings& slot, const Settings& value) {
        value.validate();
        slot = value;
        wake();
    }
    /// Something outside a step changed the energy (shape, velocities, springs, materials, constraints).
    void resetEnergyCeiling() { guard_.reset(); }
    bool guardsEnergy(double dt, bool verlet) const;
    /// Back to the state step() started from (refused steps); velocities kept or zeroed.
    void restoreStepStart(bool keepVelocity);
    /// Applies the energy guard after a finite step that did `work`; returns false if it refused the step.
    bool limitEnergy(double work, StepReport& r);
    void refreshMaterials();
    void ensureMassFactor();
    void ensureSystem(double dt, bool factor);
    /// Laplacian of the springs and penalty terms on the mesh (S x S, per coordinate).
    Eigen::SparseMatrix<double> laplacian() const;
    /// local/global's h: 2 dt / 3 for BDF2, dt for backward Euler.
    double localGlobalH(double dt) const { return solver_.timeOrder == 2 ? 2.0 * dt / 3.0 : dt; }
    /// Total mesh force (external, tool, springs, constraints, damping) into force_; returns the
    /// elastic energy. Needs dd_ (mesh velocity) current.
    double meshForces(const Points& d, const Points& dd, double dt);
    /// Verlet's internal forces (linear springs, constraints, linear damping at mesh velocity dd)
    /// into force_; returns the potential energy.
    double verletForces(const Points& d, const Points& dd);
    StepReport stepExplicit(double dt);
    StepReport stepImplicitCG(double dt);
    StepReport stepLocalGlobal(double dt);
    /// Whether local/global's explicit branch is stable at dt (omegaSquaredBelow(), lazily).
    bool verletStable(double dt);
    /// The tool's share of Verlet's omega^2 bound; infinite where Verlet is never taken.
    double verletToolTerm() const;
    /// The tool's slope on a mesh point; twice it with symmetry (the mirrored tool may hold the same point).
    double toolSlope() const { return (mirror_.empty() ? 1.0 : 2.0) * tool_->slope(); }
    /// Whether omega_max^2 of the springs and penalty terms in control space is provably below
    /// `limit` (verlet_stability_bound.cpp); `tight` makes omega_.upper the computed bound. Allocates
    /// when it recomputes (a new configuration).
    bool omegaSquaredBelow(double limit, bool tight = false);
    void rescaleOmegaBounds();
    void computeOmegaBounds(double limit);
    StepReport stepVerlet(double dt);
    /// acc_ = (A^T M A)^-1 A^T (external + tool forces), over the mesh points they act on only.
    void solveApplied();
    void explicitSubstep(double dt, int depth, StepReport& r);
    void computeAcceleration();  // acc_ from the current p, v
    /// The tool's force on the mesh `at` (the current mesh, or local/global's prediction of the step's end).
    void applyToolForces(double dt, StepReport& r, const Points& at, double phase = 1.0);
    /// Local/global BDF2: weight in [0, 1] of a second-order extrapolation over dt (the prediction
    /// of the step's end; with `fixedTargets`, point constraints count too: the history's start).
    double predictorWeight(double dt, bool fixedTargets) const;
    void checkSleep(double dt);
    MeshView meshView() const { return {d_, g(), h(), spacingU_, spacingV_, &bendingMap_}; }
    /// What the factored systems' structure depends on: the constraints' and the held poles'
    /// (both versions only grow, so the sum changes whenever either does).
    std::uint64_t structureKey() const { return constraints_.structureVersion() + held_.version(); }

    BSplineSurface surface_;
    SamplingOperator A_;
    SolverSettings solver_;
    // The mesh (d = A p, its velocity A p', the mesh before the step, A v kept by local/global) and
    // the forces on it; work buffers shared by the integrators.
    Points d_, dd_, dPrev_, av_, fext_, ftool_, force_, meshTmp_, meshTmp2_, base_, yMesh_;
    // Control space: velocities, A^T f, accelerations of the applied forces, local/global's iterate.
    Points v_, fp_, acc_, x_;
    bool avValid_ = false;  ///< av_ == A v_ (set by a local/global step, cleared by anything else touching v)
    bool accelerationValid_ = false;
    ExplicitState explicit_;
    CgState cg_;
    Bdf2History history_;
    VerletState verlet_;
    OmegaBounds omega_;
    StepBackup backup_;
    EnergyGuard guard_;
    SleepMonitor sleep_;
    HeldPoles held_;
    MirrorSymmetry mirror_;
    // Material: per mesh point masses and damping rates, the maps, springs, constraints, tool.
    Eigen::VectorXd m_, gamma_;
    Eigen::VectorXd bendingRatio_;  // the bending map at each mesh point (curvature constraints' scale)
    MaterialMap mass_, damping_, stiffness_, bendingMap_;
    SpringMesh springs_;
    BendingEnergy bending_;
    ResponseLaw dampingLaw_;
    ConstraintSet constraints_;
    std::vector<ConstraintTerm> terms_;
    std::unique_ptr<Tool> tool_;
    Cursor cursor_;
    // Factorisations and the versions of what they were built from.
    PrefactoredSolver massSolver_;
    Eigen::SparseMatrix<double> massMatrix_;  // A^T M A, as last factored by ensureMassFactor()
    std::uint64_t massVersion_ = ~0ull, materialKey_[4] = {~0ull, ~0ull, ~0ull, ~0ull};
    std::uint64_t wakeKey_[5] = {0, 0, 0, 0, 0};
    // The system matrix for the two step lengths used last (a session steps at its dt, and at
    // twice it while catching up with real time), each with its factors and Jacobi diagonal.
    struct SystemSlot {
        PrefactoredSolver solver;
        Eigen::VectorXd invDiag;
        std::uint64_t key[5] = {~0ull, ~0ull, ~0ull, ~0ull, ~0ull};
        double dt = -1;
        bool factored = false;
        std::uint64_t used = 0, built = 0;
    };
    std::array<SystemSlot, 2> systems_;
    std::size_t system_ = 0;  // the slot in use
    std::uint64_t systemUses_ = 0, systemBuilds_ = 0;
    // A one-point tool taken implicitly in the local/global step: its anchor and, mirrored, the
    // anchor's partner (Woodbury on S + c sum_k a_k a_k^T, a_k = A^T e_anchor_k), with z_k =
    // S^-1 a_k and gram(k, l) = a_k^T z_l for the system they were solved for.
    struct ImplicitTool {
        int anchors[2] = {-1, -1};
        int count = 0;
        Points z[2];
        Eigen::Matrix2d gram = Eigen::Matrix2d::Zero();
        std::uint64_t system = 0;
        Vec3 at[2] = {Vec3::Zero(), Vec3::Zero()};  // where the force on each was taken this step
    };
    ImplicitTool implicitTool_;
    void ensureImplicitTool(int anchor);
    // Measures of the material and the initial shape; the clock.
    double minMass_ = 0, maxStiffness_ = 0, maxDampingRate_ = 0, size_ = 1, spacingU_ = 1, spacingV_ = 1;
    double time_ = 0, work_ = 0;
    bool hasExternal_ = false, toolForces_ = false;
    std::uint64_t steps_ = 0;
};

}  // namespace hs
