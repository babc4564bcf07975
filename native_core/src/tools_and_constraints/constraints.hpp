// Constraints as penalty springs (paper section 4.4). Every constraint is a set of terms
// 1/2 k |x_a - x_b - t|^2 (or 1/2 k |x_a - t|^2 when b < 0) whose target t is either fixed
// or re-projected from the current shape, so all integrators, including the prefactored
// local/global one, treat them exactly like springs.
#pragma once
#include "common/names.hpp"
#include <algorithm>
#include <Eigen/Sparse>
#include <vector>

#include "geometry/bspline_surface.hpp"

namespace hs {

enum class ConstraintKind { Point, Tangent, Normal, Curvature };

inline constexpr std::array<Named<ConstraintKind>, 4> kConstraintNames{{
    {"point", ConstraintKind::Point}, {"tangent", ConstraintKind::Tangent}, {"normal", ConstraintKind::Normal},
    {"curvature", ConstraintKind::Curvature}}};

struct Constraint {
    int id = 0;
    ConstraintKind kind = ConstraintKind::Point;
    int point = 0;          ///< mesh point index a*h + b
    double stiffness = 1.0;
    Vec3 target = Vec3::Zero();  ///< point: position; normal and tangent: unit normal
    double curvatureU = 0, curvatureV = 0;  ///< curvature targets (magnitude; sign is not forced)
    Vec3 offsets[4] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};  ///< tangent/normal: neighbour offsets (+u, -u, +v, -v)
};

/// One penalty term; b < 0 means the term ties a single point to a fixed target.
struct ConstraintTerm {
    int a, b;
    double k;
    Vec3 t;
};

class ConstraintSet {
public:
    ConstraintSet() = default;
    ConstraintSet(int g, int h) : g_(g), h_(h) {}

    bool empty() const { return items_.empty(); }
    /// True if any constraint's projection is onto a non-convex set (curvature: arcs); point,
    /// tangent and normal project onto points, fixed offsets and planes.
    bool anyNonConvex() const {
        for (const Constraint& c : items_)
            if (c.kind == ConstraintKind::Curvature) return true;
        return false;
    }
    /// The stiffest constraint (with `movingOnly`: whose projection moves with the mesh, all but
    /// point constraints, whose targets are fixed); 0 if there is none.
    double maxStiffness(bool movingOnly) const {
        double k = 0;
        for (const Constraint& c : items_)
            if (!movingOnly || c.kind != ConstraintKind::Point) k = std::max(k, effectiveStiffness(c));
        return k;
    }
    /// The stiffness a constraint acts with: its own, and for a curvature constraint that times
    /// 1 + kCurvatureBendingGain x the bending ratio at its point (capped at kMaxCurvatureScale).
    /// A curvature constraint bends the plate; its penalty must beat the plate's bending rigidity
    /// as the default (1000 x the springs) beats the membrane, or the plate wins (a ratio of 10
    /// left 39 % of the target curvature unmet; with this gain 0.2 %, as without bending).
    double effectiveStiffness(const Constraint& c) const {
        if (c.kind != ConstraintKind::Curvature || curvatureScale_.empty()) return c.stiffness;
        return c.stiffness * curvatureScale_[static_cast<std::size_t>(c.point)];
    }
    /// Sets each mesh point's bending ratio (the bending map sampled on the mesh, g x h); the
    /// curvature constraints' stiffness follows it (effectiveStiffness). No allocation after the first call.
    void setBendingRatio(const Eigen::VectorXd& ratio);
    /// A curvature constraint's penalty grows by this much per unit of bending ratio.
    static constexpr double kCurvatureBendingGain = 30.0;
    static constexpr double kMaxCurvatureScale = 1e6;
    int size() const { return static_cast<int>(items_.size()); }
    const std::vector<Constraint>& items() const { return items_; }
    /// Increments when the term structure (which points, which stiffness) changes: the
    /// local/global solver refactors then, and only then.
    std::uint64_t structureVersion() const { return structureVersion_; }
    /// Increments on any change, targets included.
    std::uint64_t version() const { return version_; }

    /// Adds a constraint at mesh point `point` with targets from the current shape d unless given;
    /// points without the neighbours a constraint needs are moved to the nearest interior point.
    int add(ConstraintKind kind, int point, double stiffness, const Points& d, const Vec3* target,
            const double* curvatureU, const double* curvatureV);
    /// Re-inserts a saved constraint exactly (id, stored offsets and targets), e.g. from a document.
    void restore(const Constraint& c);
    void remove(int id);
    void clear();
    Constraint& get(int id);
    void setStiffness(int id, double k);
    void setTarget(int id, const Vec3& target);
    void setCurvature(int id, double ku, double kv);

    /// Current terms (targets re-projected from d where they depend on the shape).
    void terms(const Points& d, std::vector<ConstraintTerm>& out) const;
    /// Adds penalty forces to f; returns the penalty energy.
    double addForces(const Points& d, Points& f, std::vector<ConstraintTerm>& scratch) const;
    /// out += scale (J t - K d) for the local/global solver: the pull toward the projections t,
    /// relative to d (see SpringMesh::addProjections).
    void addProjections(const Points& d, Points& out, std::vector<ConstraintTerm>& scratch, double scale = 1.0) const;
    void addLaplacian(std::vector<Eigen::Triplet<double>>& t) const;
    /// out += K y with K the penalty springs' stiffness (targets held fixed).
    void addStiffness(const Points& y, Points& out) const;
    /// How far each constraint is from its target: position error, normal angle (rad) or the larger
    /// curvature error (relative; absolute for a flat target), measured on the mesh.
    double error(const Constraint& c, const Points& d) const;
    /// Discrete curvature of the circle through the three mesh points around `point` along u (dir 0) or v (1).
    double meshCurvature(const Points& d, int point, int dir) const;
    /// Unit normal of the mesh at an interior point from central differences.
    Vec3 meshNormal(const Points& d, int point) const;

private:
    int interior(int point) const;
    int g_ = 0, h_ = 0, nextId_ = 1;
    std::vector<Constraint> items_;
    std::vector<double> curvatureScale_;  // per mesh point: 1 + gain x bending ratio (empty: 1)
    std::uint64_t structureVersion_ = 0, version_ = 0;
};

/// Chord of a circle of curvature kappa through three points whose two half-chords are c1 and c2:
/// the spring length of the curvature constraint. Exact: the three points lie on such a circle
/// exactly when their outer distance equals this chord. Requires kappa * max(c1, c2) / 2 <= 1.
double curvatureChord(double kappa, double c1, double c2);

}  // namespace hs
