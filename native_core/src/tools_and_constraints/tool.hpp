// A sculpting tool: it adds forces on the mesh points and returns the exact reaction on the cursor.
// Each tool is one file in tools/ that declares everything about itself once (ToolInfo: its name,
// its parameters with their defaults, ranges and meanings, whether it takes a falloff); the
// catalogue (tool_catalog.cpp), the bindings and Python read that, and nothing is copied.
#pragma once
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "common/grid_rect.hpp"
#include "geometry/bspline_surface.hpp"
#include "geometry/falloff.hpp"
#include "tools_and_constraints/haptic_estimate.hpp"

namespace hs {

/// The device's cursor: position, orientation and whether the grab button is held.
struct Cursor {
    Vec3 position = Vec3::Zero();
    Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
    bool grab = false;
};

/// Force and torque the tool exerts on the cursor (minus what it exerts on the surface).
struct Reaction {
    Vec3 force = Vec3::Zero();
    Vec3 torque = Vec3::Zero();
};

class MaterialMap;

/// What a tool may read of the mesh.
struct MeshView {
    const Points& d;
    int g, h;
    double spacingU, spacingV;  ///< mean rest distance between neighbours along u and v
    const MaterialMap* bending = nullptr;  ///< the plate's map (a ratio to the springs), if any
};

/// How much stronger the rope pulls per unit of the plate's bending ratio where it is tied: a point
/// load on a plate moves it far less than on springs alone (a 100 mm clamped patch pulled 20 mm:
/// 7.6 mm with the default ratio 10 against 14.5 without); 1 + 0.3 x 10 = 4 gives back 90 % of the
/// springs' reach with the plate's fair shape (bench/time_vs_error.py --fairness, lift per pull).
inline constexpr double kRopePlateGain = 0.3;

/// One setting of a tool: finite and > 0 (or >= 0 where zero is allowed).
struct ParameterInfo {
    const char* name = nullptr;
    double value = 0;  ///< the default
    bool allowZero = false;
    const char* doc = "";
    const char* label = "";  ///< a slider's few words, with the unit (the name where empty)
    bool length = false;     ///< a length in mm: its default is for a 100 mm part (a smaller one scales it)
};

/// A value a tool reports about its grab (read-only).
struct ReadoutInfo {
    const char* name = nullptr;
    const char* doc = "";
};

/// Everything about a tool outside its force law, declared once in its file.
struct ToolInfo {
    static constexpr int kMaxParameters = 6, kMaxReadouts = 2;
    const char* name;  ///< as scripts and documents spell it; also its file's name in tools/
    const char* title;  ///< the GUI's command and icon name
    const char* tip;    ///< one sentence for the GUI
    int order;          ///< place in lists and menus
    bool falloff;       ///< whether it weights its points by a falloff
    std::array<ParameterInfo, kMaxParameters> parameters;
    std::array<ReadoutInfo, kMaxReadouts> readouts{};
    int parameterCount() const;
    int readoutCount() const;
};

/// The settings every tool has (ToolLimits), as scripts and documents name them.
inline constexpr std::array<ParameterInfo, 2> kToolLimitParameters{{
    {"max_force", 1e3, false, "clamp on the tool's total force"},
    {"ramp_time", 0.05, true, "seconds for the force to ramp in after a grab"}}};

/// Settings shared by every tool: force ramp on grab and clamp.
struct ToolLimits {
    double maxForce = kToolLimitParameters[0].value;  ///< clamp on the total force, in force units
    double rampTime = kToolLimitParameters[1].value;  ///< seconds for the force to ramp in after a grab
};

class Tool {
public:
    explicit Tool(const ToolInfo& info);
    virtual ~Tool() = default;
    const ToolInfo& info() const { return info_; }
    const char* name() const { return info_.name; }

    /// Parameter `i` of info().parameters, and its setter (range-checked, throws std::invalid_argument).
    double parameter(int i) const { return parameters_[i]; }
    void setParameter(int i, double value);
    /// The same by name, the limits (max_force, ramp_time) included; unknown names throw std::invalid_argument.
    double get(const std::string& name) const;
    void set(const std::string& name, double value);
    /// Readout `i` of info().readouts (0 where the tool has none).
    virtual double readout(int) const { return 0.0; }
    double read(const std::string& name) const;  ///< the readout named `name` (throws std::invalid_argument)
    Falloff falloff() const { return falloff_; }
    void setFalloff(Falloff f);  ///< throws std::invalid_argument for a tool without one
    ToolLimits limits;

    /// Starts a grab at the current cursor (selects mass points, records rest state).
    virtual void grab(const MeshView& mesh, const Cursor& cursor) = 0;
    virtual void release() { grabbed_ = false; }
    /// Takes `other`'s settings (a tool of the same kind) and keeps its own grab: an edit made
    /// while the tool is held changes the tool's settings without letting go.
    void copySettings(const Tool& other);
    bool grabbed() const { return grabbed_; }
    /// Advances the tool's clock by dt and adds its forces to f; returns the reaction on the cursor.
    /// The forces are those at `phase` of the way through the step on the clock (ramp, reel): 1 its
    /// end, as the implicit steps take them; 0.5 its middle, for Verlet's midpoint rule.
    Reaction apply(const MeshView& mesh, const Cursor& cursor, double dt, Points& f, double phase = 1.0);
    /// The mesh points the tool may push until it is released, as a rectangle of the g x h mesh
    /// (empty when it is not held); false where it cannot say (it may push anywhere).
    virtual bool reach(int g, int h, GridRect& mesh) const {
        (void)g;
        mesh = {0, 0, 0, 0, h};
        return !grabbed_;
    }
    /// The mesh points the last apply() pushed.
    const std::vector<int>& pushed() const { return index_; }
    /// Mass point the tool is attached to (nearest point for the rope), -1 if none.
    virtual int anchor() const { return -1; }
    /// Steepest force per unit displacement on one mass point (infinite when unknown): how stiff
    /// the tool is as an explicit force, for the local/global step's prediction.
    virtual double slope() const { return std::numeric_limits<double>::infinity(); }
    /// The force's slope on anchor() as last applied (0 when it pulled nothing): the local/global
    /// step takes a one-point tool implicitly with it.
    virtual double anchorSlope() const { return 0.0; }
    /// Whether the local/global step takes this tool implicitly on its anchor (with anchorSlope);
    /// the others' forces are explicit there.
    virtual bool implicitOnAnchor() const { return false; }
    /// Fills the local model the haptic loop renders between steps (positions, law, parameters;
    /// velocities are left to the caller). The default holds the last reaction.
    void describe(const MeshView& mesh, const Reaction& last, HapticEstimate& e) const;
    /// Reserves room for n points so that stepping never allocates.
    virtual void reserve(size_t n);

protected:
    double p(int i) const { return parameters_[i]; }
    /// Tool-specific part of describe(); returns false to hold the last reaction instead.
    virtual bool describeLaw(const MeshView&, HapticEstimate&) const { return false; }
    /// Writes the unclamped forces on the selected points into the tool's own buffer via emit().
    virtual void computeForces(const MeshView& mesh, const Cursor& cursor) = 0;
    void emit(int index, const Vec3& force);
    bool grabbed_ = false;
    double gain_ = 1;  ///< the tool's forces and clamp over its settings, on what it grabbed
    double appliedScale_ = 0;  ///< the ramp and clamp's factor on the forces last applied
    double time_ = 0;  ///< seconds since grab
    double forceTime_ = 0;  ///< the clock the current forces are taken at (apply's phase)

private:
    const ToolInfo& info_;
    std::array<double, ToolInfo::kMaxParameters> parameters_{};
    Falloff falloff_ = Falloff::Spherical;
    std::vector<int> index_;
    std::vector<Vec3> force_;
};

/// The smallest rectangle of a mesh with h columns holding the points `points`.
GridRect boundingRect(const std::vector<int>& points, int h);

/// Index of the mesh point nearest to x.
int nearestPoint(const Points& d, const Vec3& x);

/// The points within `radius` of `centre` with their falloff weights (cylindrical: distance to the
/// line through `centre` along `axis`), for the tools that select a region at grab.
void selectWithin(const MeshView& mesh, const Vec3& centre, const Vec3& axis, double radius, Falloff falloff,
                  std::vector<int>& points, std::vector<double>& weights);

/// The tool named `name` (tool_catalog.cpp); throws std::invalid_argument for an unknown name.
std::unique_ptr<Tool> makeTool(const std::string& name);
/// Every tool's name, in ToolInfo::order.
std::vector<std::string> toolNames();

}  // namespace hs
