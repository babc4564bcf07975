// Closest points on a B-spline surface (a scan's deviation, the foot of a data spring): an even
// grid of the surface in a k-d tree gives each query its start, Newton steps on |S(u, v) - x|^2
// inside the parameter domain refine it.
#pragma once
#include <vector>

#include "geometry/bspline_surface.hpp"
#include "geometry/point_tree.hpp"

namespace hs {

/// Where a point's perpendicular meets the surface.
struct SurfaceFoot {
    double u = 0, v = 0;
    Vec3 point = Vec3::Zero();   ///< the closest point on the surface
    Vec3 normal = Vec3::UnitZ(); ///< unit normal there (du x dv)
    double distance = 0;         ///< |x - point|, negative where x lies behind the normal
    /// The foot is on the domain's edge and x lies beyond it (not over the surface).
    bool beyondEdge = false;
};

class SurfaceProjection {
public:
    /// Samples per knot span in each direction for the starts (4 finds the right basin on any
    /// shape a stroke makes of a span; more costs build time only).
    static constexpr int kDefaultSamples = 4;
    /// Copies the surface and samples it (std::invalid_argument unless 1 <= samplesPerSpan <= 64).
    explicit SurfaceProjection(BSplineSurface surface, int samplesPerSpan = kDefaultSamples);

    /// The closest point to x (allocates nothing).
    SurfaceFoot project(const Vec3& x) const;
    /// The same, starting from (u, v) (a foot from before the surface moved a little): kept when it
    /// is no farther than the nearest sample, else searched from that sample as above.
    SurfaceFoot project(const Vec3& x, double u, double v) const;
    const BSplineSurface& surface() const { return surface_; }

private:
    SurfaceFoot descend(const Vec3& x, double u, double v) const;  // Newton from (u, v)

    BSplineSurface surface_;
    std::vector<double> startU_, startV_;  // the parameters of each sample, row-major (u slow)
    PointTree samples_;
};

}  // namespace hs
