// Mirror symmetry of a sculpt: a surface that is its own mirror image in a plane, with one
// parameter direction reversed, stays exactly so. A stroke acts as if a mirrored copy of the tool
// made it too (the mesh forces get their mirror images added), the dynamics of a symmetric
// surface under symmetric forces are symmetric, and after each step the poles are put exactly
// symmetric again (rounding, and what is not symmetric: penalty constraints, painted maps).
#pragma once
#include <vector>

#include "geometry/bspline_surface.hpp"
#include "common/types.hpp"

namespace hs {

class MirrorSymmetry {
public:
    bool empty() const { return direction_ < 0; }
    /// 0: the mirror image reverses u, 1: v, -1: no symmetry.
    int direction() const { return direction_; }
    const Vec3& point() const { return point_; }
    const Vec3& normal() const { return normal_; }
    /// Makes `surface` (sampled on a g x h mesh) symmetric in the plane through `point` with normal
    /// `normal`, parameter `direction` reversed. Throws std::invalid_argument naming "symmetry"
    /// unless the knots and weights are symmetric and each pole's mirror image is within 1e-6 of
    /// the surface's size of its partner; naming "held poles" unless `held` is a symmetric set.
    void set(int direction, const Vec3& point, const Vec3& normal, const BSplineSurface& surface, int g, int h,
             const std::vector<int>& held);
    void clear() { direction_ = -1; }
    /// The mirror partner of pole i (itself on the plane's row).
    int mirrorPole(int i) const { return mirror(i, nu_, nv_); }
    /// The mirror partner of mesh point i, and the mirror image of a point.
    int mirrorPoint(int i) const { return mirror(i, g_, h_); }
    Vec3 reflectPoint(const Vec3& x) const { return reflect(x); }
    /// Throws std::invalid_argument naming "indices" unless the held set is symmetric.
    void requireSymmetric(const std::vector<int>& held) const;
    /// f_i += M f_mirror(i) on the mesh (M the reflection): the forces of a mirrored tool added.
    void addMirrored(Points& meshForces) const;
    /// A point force at mesh point i and its mirror image at the partner (both when i is its own).
    void pointForce(Points& meshForces, int i, const Vec3& f) const;
    /// Puts the poles exactly symmetric (each pair at the mean of one and the other's mirror image,
    /// poles on the plane's row onto the plane) and the velocities too; whether a pole moved.
    bool project(Points& poles, Points& velocities) const;

private:
    int mirror(int i, int rows, int cols) const {
        const int a = i / cols, b = i % cols;
        return direction_ == 0 ? (rows - 1 - a) * cols + b : a * cols + (cols - 1 - b);
    }
    Vec3 reflect(const Vec3& x) const { return x - 2.0 * (x - point_).dot(normal_) * normal_; }
    Vec3 reflectVector(const Vec3& x) const { return x - 2.0 * x.dot(normal_) * normal_; }

    int direction_ = -1, nu_ = 0, nv_ = 0, g_ = 0, h_ = 0;
    Vec3 point_ = Vec3::Zero(), normal_ = Vec3::UnitX();
};

}  // namespace hs
