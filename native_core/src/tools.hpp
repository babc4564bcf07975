// Sculpting tools: each adds forces on the mesh points and returns the exact reaction on the cursor.
#pragma once
#include <algorithm>
#include <array>
#include <type_traits>
#include <limits>
#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "bspline_surface.hpp"
#include "falloff.hpp"
#include "haptic_estimate.hpp"

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

/// What a tool may read of the mesh.
class MaterialMap;

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

/// Settings shared by every tool: force ramp on grab and clamp.
struct ToolLimits {
    double maxForce = 1e3;   ///< clamp on the total force, in force units
    double rampTime = 0.05;  ///< seconds for the force to ramp in after a grab
};

class Tool {
public:
    virtual ~Tool() = default;
    virtual const char* name() const = 0;
    /// Starts a grab at the current cursor (selects mass points, records rest state).
    virtual void grab(const MeshView& mesh, const Cursor& cursor) = 0;
    virtual void release() { grabbed_ = false; }
    /// Takes `other`'s settings (a tool of the same kind) and keeps its own grab: an edit made
    /// while the tool is held changes the tool's settings without letting go.
    virtual void copySettings(const Tool& other) { limits = other.limits; }
    bool grabbed() const { return grabbed_; }
    /// Advances the tool's clock by dt and adds its forces to f; returns the reaction on the cursor.
    /// The forces are those at `phase` of the way through the step on the clock (ramp, reel): 1 its
    /// end, as the implicit steps take them; 0.5 its middle, for Verlet's midpoint rule.
    Reaction apply(const MeshView& mesh, const Cursor& cursor, double dt, Points& f, double phase = 1.0);
    /// Mass point the tool is attached to (nearest point for the rope), -1 if none.
    virtual int anchor() const { return -1; }
    /// Steepest force per unit displacement on one mass point (infinite when unknown): how stiff
    /// the tool is as an explicit force, for the local/global step's prediction.
    virtual double slope() const { return std::numeric_limits<double>::infinity(); }
    /// The force's slope on anchor() as last applied (0 when it pulled nothing): the local/global
    /// step takes a one-point tool implicitly with it.
    virtual double anchorSlope() const { return 0.0; }
    /// Fills the local model the haptic loop renders between steps (positions, law, parameters;
    /// velocities are left to the caller). The default holds the last reaction.
    void describe(const MeshView& mesh, const Reaction& last, HapticEstimate& e) const;
    ToolLimits limits;
    /// Reserves room for n points so that stepping never allocates.
    void reserve(size_t n) { index_.reserve(n); force_.reserve(n); }

protected:
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
    std::vector<int> index_;
    std::vector<Vec3> force_;
};

/// Index of the mesh point nearest to x.
int nearestPoint(const Points& d, const Vec3& x);

/// Attached to the nearest point by a rope: pulls, never pushes; stiff past `threshold`;
/// its rest length reels in from the grab distance to zero over `reelTime`.
class RopeTool final : public Tool {
public:
    const char* name() const override { return "rope"; }
    void grab(const MeshView& mesh, const Cursor& cursor) override;
    void copySettings(const Tool& other) override;
    int anchor() const override { return grabbed_ ? point_ : -1; }
    double slope() const override { return gain_ * std::max(stiffness, stiffStiffness); }
    double restLength() const { return restLengthAt(time_); }
    /// Its pull over its settings where it is tied: 1 + kRopePlateGain x the bending ratio there.
    double gain() const { return gain_; }
    double anchorSlope() const override { return appliedScale_ * slopeNow_; }
    double stiffness = 10.0;        ///< force per length while slack is below threshold
    double stiffStiffness = 200.0;  ///< past the threshold
    double threshold = 5.0;         ///< extension beyond rest where the rope turns stiff
    double reelTime = 1.0;

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override;
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override;

private:
    double restLengthAt(double t) const;
    double slopeNow_ = 0;  ///< d tension / d extension at the last forces (0 slack)
    int point_ = -1;
    double length0_ = 0;
};

/// All points within `radius` at grab time, each on a spring to its grab offset from the cursor,
/// weighted by the falloff (cylindrical: distance to the cursor's z axis).
class MagnetTool final : public Tool {
public:
    const char* name() const override { return "magnet"; }
    void grab(const MeshView& mesh, const Cursor& cursor) override;
    void copySettings(const Tool& other) override;
    int selected() const { return static_cast<int>(points_.size()); }
    double slope() const override { return stiffness; }  // stiffness * falloff weight <= stiffness per point
    double radius = 10.0;
    double stiffness = 10.0;
    Falloff falloff = Falloff::Spherical;

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override;
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override;

private:
    std::vector<int> points_;
    std::vector<double> weights_;
    std::vector<Vec3> offsets_;
};

/// Five springs: the nearest point to the cursor, and its four neighbours to the ends of the
/// cursor's x (along u) and y (along v) axes scaled to the mesh spacing.
class OrientationTool final : public Tool {
public:
    const char* name() const override { return "orientation"; }
    void grab(const MeshView& mesh, const Cursor& cursor) override;
    void copySettings(const Tool& other) override;
    int anchor() const override { return grabbed_ ? center_ : -1; }
    double slope() const override { return stiffness; }
    double stiffness = 10.0;

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override;
    bool describeLaw(const MeshView& mesh, HapticEstimate& e) const override;

private:
    int center_ = -1;
};

/// Fairing brush: points within `radius` of the cursor are pulled along U^3 x (U the umbrella
/// operator), the gradient flow of the discrete curvature variation, weighted by the falloff.
class SmoothTool final : public Tool {
public:
    const char* name() const override { return "smooth"; }
    void grab(const MeshView& mesh, const Cursor& cursor) override;
    void copySettings(const Tool& other) override;
    double radius = 10.0;
    double strength = 1.0;
    Falloff falloff = Falloff::Spherical;

protected:
    void computeForces(const MeshView& mesh, const Cursor& cursor) override;

private:
    Points u1_, u2_, u3_;
};

/// rope, magnet, orientation or smooth (names.hpp lists them); throws std::invalid_argument otherwise.
std::unique_ptr<Tool> makeTool(const std::string& name);

/// A tool setting and its range (finite and > 0, or >= 0 where zero is allowed): the one place
/// its name, range and meaning are written; set() is the check every caller goes through.
template <class T, class Owner = T>
struct ToolParameter {
    const char* name;
    double Owner::*member;
    bool allowZero;
    const char* doc;
    double get(const T& t) const { return owner(t).*member; }
    void set(T& t, double value) const { owner(t).*member = requirePositive(value, name, allowZero); }

private:
    template <class U>
    static auto& owner(U& t) {  // the tool itself, or its limits (ToolLimits, shared by every tool)
        if constexpr (std::is_same_v<T, Owner>) return t;
        else return t.limits;
    }
};

inline const std::array<ToolParameter<Tool, ToolLimits>, 2> kToolLimitParameters{{
    {"max_force", &ToolLimits::maxForce, false, "clamp on the tool's total force"},
    {"ramp_time", &ToolLimits::rampTime, true, "seconds for the force to ramp in after a grab"}}};
inline const std::array<ToolParameter<RopeTool>, 4> kRopeParameters{{
    {"stiffness", &RopeTool::stiffness, false, "force per length below the threshold"},
    {"stiff_stiffness", &RopeTool::stiffStiffness, false, "force per length past the threshold"},
    {"threshold", &RopeTool::threshold, true, "extension beyond rest length where the rope turns stiff"},
    {"reel_time", &RopeTool::reelTime, true, "seconds for the rest length to reel in to zero"}}};
inline const std::array<ToolParameter<MagnetTool>, 2> kMagnetParameters{{
    {"radius", &MagnetTool::radius, false, "selection radius"},
    {"stiffness", &MagnetTool::stiffness, false, "spring stiffness per point"}}};
inline const std::array<ToolParameter<OrientationTool>, 1> kOrientationParameters{{
    {"stiffness", &OrientationTool::stiffness, false, "stiffness of the five springs"}}};
inline const std::array<ToolParameter<SmoothTool>, 2> kSmoothParameters{{
    {"radius", &SmoothTool::radius, false, "brush radius"},
    {"strength", &SmoothTool::strength, false, "fairing force per unit of U^3 x"}}};

}  // namespace hs
