// The dynamic B-spline surface of paper section 4: control points p driven through the mesh d = A p
// by  p'' = (A^T M A)^-1 (A^T f_d - A^T D d' - A^T f_springs(d))  (eq. 7).
// It owns the parts (state, material, forces, hard constraints, factored systems, integrators),
// guards each step (NaN/Inf, energy, sleep) and chooses the integrator; the integrators step the
// state through the narrow interface of step_model.hpp.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

#include "dynamics/energy_guard.hpp"
#include "dynamics/held_poles.hpp"
#include "dynamics/material.hpp"
#include "dynamics/mirror_symmetry.hpp"
#include "dynamics/pole_walls.hpp"
#include "dynamics/sleep_monitor.hpp"
#include "dynamics/surface_state.hpp"
#include "solvers/active_region.hpp"
#include "solvers/integrator_explicit.hpp"
#include "solvers/integrator_implicit_cg.hpp"
#include "solvers/integrator_local_global.hpp"
#include "solvers/integrator_verlet.hpp"
#include "solvers/solver_settings.hpp"
#include "solvers/step_model.hpp"
#include "solvers/surface_forces.hpp"
#include "solvers/system_cache.hpp"

namespace hs {

/// The energy guard (energy_guard.hpp) runs only where local/global's descent guarantee does not
/// hold: the explicit and linearised implicit schemes, non-linear spring laws, curvature
/// constraints (projections onto arcs, a non-convex set; point, tangent and normal constraints
/// project onto convex sets), and steps so long for the stiffness and mass that rounding in the
/// solve is no longer negligible. A step past its ceiling has its velocities scaled back to it; one
/// whose potential energy alone is past it is refused (positions kept, motion stopped).

class DynamicSurface {
public:
    /// Samples `surface` on a g x h mesh; rest lengths come from the initial shape.
    DynamicSurface(BSplineSurface surface, int g, int h);

    // --- geometry --------------------------------------------------------------------------
    const BSplineSurface& surface() const { return state_.surface; }
    const SamplingOperator& sampling() const { return state_.A; }
    int g() const { return state_.g(); }
    int h() const { return state_.h(); }
    const Points& poles() const { return state_.poles(); }
    const Points& velocities() const { return state_.v; }
    const Points& mesh() const { return state_.d; }
    const Points& meshVelocities();  ///< A p', computed on request
    double size() const { return state_.size; }
    /// The initial shape's measures that scale tolerances and tools: size (bounding-box diagonal) and
    /// mean mesh spacing along u and v. Restoring a saved surface sets them back exactly.
    std::array<double, 3> reference() const { return state_.reference(); }
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
    /// Walls (pole_walls.hpp): half-spaces the listed poles stay in; a step that carries a free
    /// pole out puts it back onto the wall. Replaces them all (empty: none); throws
    /// std::invalid_argument naming "walls". Poles outside their walls now are put back at once.
    void setWalls(const std::vector<PoleWall>& walls);
    const std::vector<PoleWall>& walls() const { return walls_.walls(); }
    /// Mesh index nearest to parameter (u, v), and the parameters of a mesh index.
    int meshIndexAt(double u, double v) const;
    std::pair<double, double> meshParameters(int index) const;
    int nearestMeshIndex(const Vec3& x) const { return nearestPoint(state_.d, x); }

    // --- material ----------------------------------------------------------------------------
    // Changes to the maps and constraints are seen through their version counters: they wake the
    // surface and trigger refactoring at the next step, and nothing else.
    MaterialMap& massMap() { return material_.massMap; }
    MaterialMap& dampingMap() { return material_.dampingMap; }
    MaterialMap& stiffnessMap() { return material_.stiffnessMap; }
    /// Bending (thin-plate) weight per mesh cell as a ratio to the stiffness there (bending_energy.hpp); 0: off.
    MaterialMap& bendingMap() { return material_.bendingMap; }
    const MaterialMap& bendingMap() const { return material_.bendingMap; }
    /// The bending energy; its reference is the shape the bending measures from: the initial mesh;
    /// with plasticity the shape a stroke leaves at its release, and between strokes it follows
    /// the shape at the plastic rate.
    const BendingEnergy& bending() const { return material_.bending; }
    void setBendingReference(const Points& reference) { material_.bending.setReference(reference); wake(); }
    /// Makes the current shape the rest shape: rest lengths and the bending reference from the mesh.
    void relax() { material_.springs.resetRest(state_.d); material_.bending.setReference(state_.d); wake(); }
    const MaterialMap& massMap() const { return material_.massMap; }
    const MaterialMap& dampingMap() const { return material_.dampingMap; }
    const MaterialMap& stiffnessMap() const { return material_.stiffnessMap; }
    SpringMesh& springs() { wake(); return material_.springs; }
    const SpringMesh& springs() const { return material_.springs; }
    /// Non-linear damping: multiplier g(F)/F of each point's spring-force magnitude F.
    const ResponseLaw& dampingLaw() const { return material_.dampingLaw; }
    const Eigen::VectorXd& pointMasses() { refreshMaterials(); return material_.masses(); }

    // --- forces, tools and constraints -------------------------------------------------------
    /// Persistent external force on a mesh point (clamped to maxPointForce()).
    void setPointForce(int index, const Vec3& force);
    void clearForces();
    /// The point forces plus the pull toward the target, as the last step applied them.
    const Points& externalForces() const { return forces_.external(); }
    double maxPointForce() const { return forces_.maxPointForce; }
    void setMaxPointForce(double f);  ///< > 0 (std::invalid_argument naming max_point_force)

    void setTool(const std::string& name);  ///< a tool of the catalogue (toolNames(): rope, magnet, ...)
    Tool& tool() { return forces_.tool(); }
    const Tool& tool() const { return forces_.tool(); }
    /// Latest cursor; a rising grab edge grabs, a falling one releases.
    void setCursor(const Cursor& cursor);
    const Cursor& cursor() const { return forces_.cursor; }
    /// The active tool's local model for the haptic loop (see haptic_estimate.hpp).
    void describeTool(const Reaction& last, HapticEstimate& e) const { forces_.tool().describe(meshView(), last, e); }

    /// The pull toward a scan (data_springs.hpp): data springs from the mesh to the nearest points
    /// of `tree` within `reach` (a null tree: none), on or off, at `strength` (0..1e6), painted by
    /// pullMap(). Each change wakes the surface; a new target seeks every anchor afresh.
    void setPullTarget(std::shared_ptr<const PointTree> tree, double reach);
    void setPull(bool enabled, double strength);
    const DataSprings& pull() const { return forces_.pull(); }
    MaterialMap& pullMap() { return forces_.pull().map; }
    const MaterialMap& pullMap() const { return forces_.pull().map; }

    ConstraintSet& constraints() { return forces_.constraints(); }
    const ConstraintSet& constraints() const { return forces_.constraints(); }
    /// Default penalty stiffness: this factor times the mean material stiffness.
    double constraintStiffnessFactor() const { return forces_.constraintStiffnessFactor; }
    void setConstraintStiffnessFactor(double f);  ///< > 0 (std::invalid_argument naming constraint_stiffness_factor)
    double defaultConstraintStiffness() const { return forces_.constraintStiffnessFactor * material_.stiffnessMap.mean(); }

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
    /// Something outside a step changed the state or the energy: the surface wakes, the carried
    /// accelerations are dropped and the energy guard starts a new ceiling.
    void wake() { touch(); guard_.reset(); region_.wholeNext(); }
    std::uint64_t stepCount() const { return steps_; }
    /// The system matrix the last implicit step solved by: (its unknowns, the entries one solve
    /// reads, whether it keeps the dense inverse); unknowns 0 before such a step.
    /// (unknowns, matrix entries one solve reads, "dense" | "band" | "sparse"), or (0, 0, "") before a solve.
    std::tuple<int, Eigen::Index, std::string> systemSolveSize() const {
        const PrefactoredSolver& s = systems_.current().solver;
        if (!s.ready()) return {0, 0, ""};
        using Kind = PrefactoredSolver::Kind;
        return {s.size(), s.entriesRead(), s.kind() == Kind::Dense ? "dense" : s.kind() == Kind::Band ? "band" : "sparse"};
    }
    double time() const { return time_; }
    double workDone() const { return work_; }  ///< work of external and tool forces so far
    /// The energy guard's current ceiling (0 while the guard is not running for this scene).
    double energyCeiling() const { return guard_.ceiling(); }
    /// Longest step local/global takes by its explicit Verlet branch in the current configuration
    /// (0 where it never does: switched off, non-linear laws, curvature constraints, smooth tool).
    double verletStepLimit();
    /// What the last step moved: the whole net, or a region of it (active_region.hpp).
    const ActiveRegion& activeRegion() const { return region_.region(); }

    /// Fair (fairing.cpp): relaxes the curvature variation where `weights` (one per mesh point, in
    /// [0, 1]) ask for it, by `strength` (>= 0) against staying put; held and linked poles and
    /// the mirror symmetry hold exactly. Zeroes velocities (as setPoles). Allocates (an edit).
    void fair(const Eigen::VectorXd& weights, double strength);
    /// Fit (target_fit.cpp): the poles nearest the `targets` at parameters `uv` (one row each,
    /// with the surface's `normals` there), weighted by `weights` (>= 0), the slide along the
    /// surface by `tangential` (1e-6..1; 1 is plain least squares), with the mesh's curvature
    /// variation at `smoothing` (0..1e6, relative to the points' weight) bridging where there are
    /// no points, each pole's move in the surface's own plane weighed by `inPlane` (0..1e6,
    /// relative to a pole's share of the points' weight), and the change's slope weighed by `beyond`
    /// (0..1e6, relative to the points' weight) where the points do not reach; held and linked poles
    /// and the mirror symmetry hold exactly. Returns them; the surface is unchanged. Allocates.
    Points fitPoles(const Points& targets, const Eigen::MatrixX2d& uv, const Points& normals,
                    const Eigen::VectorXd& weights, double tangential, double smoothing, double inPlane = 0.0,
                    double beyond = 0.0);

    // --- measures -----------------------------------------------------------------------------
    double kineticEnergy();
    double potentialEnergy();
    /// Its bending part, 1/2 (d - r)^T K_b (d - r).
    double bendingEnergy() { refreshMaterials(); return material_.bending.energy(state_.d); }
    /// Gradient of potentialEnergy() with respect to the poles, -A^T f(d) (springs and constraints).
    const Points& potentialGradient();
    /// Curvature of the circle through interior mesh point `index` and its two neighbours along
    /// u (direction 0) or v (1); throws std::invalid_argument for a boundary point.
    double meshCurvature(int index, int direction) const;
    /// Per mesh point: u and v normal curvature, min and max principal, mean, Gaussian (g*h x 6).
    Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> curvatureGrid() const;

private:
    /// The surface wakes and the accelerations the integrators carry between steps are dropped.
    void touch() {
        sleep_.wake();
        explicit_.invalidate();
        verlet_.invalidate();
    }
    /// The settings setters: check `value` (std::invalid_argument naming the field), store it in
    /// `slot`, wake the surface.
    template <class Settings>
    void configure(Settings& slot, const Settings& value) {
        value.validate();
        slot = value;
        wake();
    }
    StepModel model() {
        return {state_, material_, forces_, held_, mirror_, systems_, scratch_, solver_, region_.region()};
    }
    /// Whether a step of this scene may be regional: what it holds acts only where it is (no
    /// symmetry, linked poles, penalty constraints or persistent forces, linear laws).
    bool regionalScene() const;
    /// Chooses the next step's region; where it changed, stops what falls outside it.
    void chooseRegion(bool allowed);
    /// The mesh from the poles, where the last step could have moved it.
    void sampleRegion();
    /// Puts the poles exactly symmetric and the held and linked ones back; whether any moved.
    bool snapToConstraints();
    bool guardsEnergy(double dt, bool verlet) const;
    /// Back to the state step() started from (refused steps); velocities kept or zeroed.
    void restoreStepStart(bool keepVelocity);
    /// Applies the energy guard after a finite step that did `work`; returns false if it refused the step.
    bool limitEnergy(double work, StepReport& r);
    void refreshMaterials();
    void checkSleep();
    MeshView meshView() const { return {state_.d, g(), h(), state_.spacingU, state_.spacingV, &material_.bendingMap}; }

    SurfaceState state_;
    Material material_;
    SurfaceForces forces_;
    HeldPoles held_;
    MirrorSymmetry mirror_;
    PoleWalls walls_;
    SolverSettings solver_;
    SystemCache systems_;
    Scratch scratch_;
    ExplicitIntegrator explicit_;
    ImplicitCgIntegrator cg_;
    LocalGlobalIntegrator localGlobal_;
    VerletIntegrator verlet_;
    EnergyGuard guard_;
    SleepMonitor sleep_;
    RegionChooser region_;
    std::uint64_t wakeKey_[6] = {0, 0, 0, 0, 0, 0};  // the maps' and constraints' versions the last step saw
    double time_ = 0, work_ = 0;  // the clock, and the work of the applied forces
    std::uint64_t steps_ = 0;
};

}  // namespace hs
