// The forces on the mesh: the applied ones (persistent point forces, the pull toward a scan, the
// tool's pull toward the cursor) and the internal ones (springs, bending, penalty constraints, damping), summed into one
// buffer the integrators read.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "common/types.hpp"
#include "dynamics/data_springs.hpp"
#include "dynamics/material.hpp"
#include "dynamics/mirror_symmetry.hpp"
#include "tools_and_constraints/constraints.hpp"
#include "tools_and_constraints/tool.hpp"

namespace hs {

class SurfaceForces {
public:
    /// For a g x h mesh.
    SurfaceForces(int g, int h);

    // --- applied forces --------------------------------------------------------------------
    /// Persistent external force on a mesh point, clamped to maxPointForce (and mirrored).
    void setPointForce(int index, const Vec3& force, const MirrorSymmetry& mirror);
    void clearExternal();
    /// The persistent applied forces: the point forces plus the pull toward the target, taken
    /// explicitly (held over a step, as the integrators hold the point forces).
    const Points& external() const { return external_; }
    bool hasExternal() const { return hasPointForces_ || pullOn_; }

    // --- the pull toward a scan (data_springs.hpp) ---------------------------------------------
    DataSprings& pull() { return pull_; }
    const DataSprings& pull() const { return pull_; }
    /// At a step's start: re-seeks some anchors on mesh d (mean spacings su, sv) and puts the pull
    /// at d moving at dd, for point masses m and step dt, into external(); once it stops,
    /// external() is the point forces alone again.
    void applyPull(const Points& d, const Points& dd, double su, double sv, const Eigen::VectorXd& m, double dt);
    /// The tool's force on the mesh as last applied (plus, after an implicit step, its linear part).
    const Points& fromTool() const { return fromTool_; }
    Points& fromTool() { return fromTool_; }
    bool toolActive() const { return toolActive_; }
    bool anyApplied() const { return hasExternal() || toolActive_; }
    /// The work of the applied forces, held constant, over the mesh's motion from `before` to `d`.
    double appliedWork(const Points& d, const Points& before, const GridRect& window) const;

    // --- the tool ---------------------------------------------------------------------------
    void setTool(const std::string& name);  ///< a tool of the catalogue (toolNames())
    Tool& tool() { return *tool_; }
    const Tool& tool() const { return *tool_; }
    void swapTool(SurfaceForces& other) {
        std::swap(tool_, other.tool_);
        fromTool_.setZero();  // (its rows are cleared by the tool's last points: not this tool's)
        other.fromTool_.setZero();
    }
    Cursor cursor;
    /// The tool's force on the mesh `at` (reaction into `reaction`), mirrored; returns whether the
    /// applied forces changed (a held tool's change every step, a released one's once).
    bool applyTool(const Points& at, int g, int h, double su, double sv, const MirrorSymmetry& mirror, double dt,
                   Reaction& reaction, double phase = 1.0);

    // --- constraints ------------------------------------------------------------------------
    ConstraintSet& constraints() { return constraints_; }
    const ConstraintSet& constraints() const { return constraints_; }
    std::vector<ConstraintTerm>& terms() { return terms_; }

    // --- the sum ----------------------------------------------------------------------------
    /// All forces (external, tool, springs, bending, constraints, damping at mesh velocity dd) at
    /// mesh d into total(); returns the elastic energy. Records the springs' tangent stiffness.
    double all(Material& material, const Points& d, const Points& dd);
    /// The internal forces of linear laws (springs, bending, constraints, linear damping at dd)
    /// into total(), for Verlet; returns the potential energy.
    double internalLinear(Material& material, const Points& d, const Points& dd);
    /// Springs, bending and constraints at d into total(), the potential energy returned.
    double potential(Material& material, const Points& d);
    /// The potential energy (total() is its scratch).
    double potentialEnergy(const Material& material, const Points& d);
    const Points& total() const { return total_; }
    Points& total() { return total_; }

    double maxPointForce = 1e6;
    /// Default penalty stiffness: this factor times the mean material stiffness.
    double constraintStiffnessFactor = 1e3;

private:
    Points pointForces_, external_, fromTool_, total_;  // external_: pointForces_ plus the pull
    Eigen::VectorXd dampingFactor_;  // the non-linear damping law's factor per mesh point
    DataSprings pull_;
    bool hasPointForces_ = false, pullOn_ = false, toolActive_ = false;
    std::unique_ptr<Tool> tool_;
    ConstraintSet constraints_;
    std::vector<ConstraintTerm> terms_;
};

}  // namespace hs
