// The moving surface's plain state: the control net, the mesh d = A p it is sampled on, the
// velocities, and the initial shape's measures that scale tolerances and tools.
#pragma once
#include <array>

#include "common/types.hpp"
#include "geometry/bspline_surface.hpp"
#include "geometry/sampling_operator.hpp"

namespace hs {

struct SurfaceState {
    /// Samples `surface` on a g x h mesh and measures it (size, mean spacings).
    SurfaceState(BSplineSurface surface, int g, int h);

    int g() const { return A.g(); }
    int h() const { return A.h(); }
    const Points& poles() const { return surface.poles(); }
    Points& mutablePoles() { return surface.mutablePoles(); }
    /// d = A p after the poles moved.
    void sampleMesh() { A.apply(surface.poles(), d); }
    /// Size (bounding-box diagonal) and mean mesh spacing along u and v.
    std::array<double, 3> reference() const { return {size, spacingU, spacingV}; }

    BSplineSurface surface;
    SamplingOperator A;
    Points d;      ///< the mesh, A p
    Points v;      ///< control-point velocities
    Points av;     ///< A v, where avValid (local/global and Verlet keep it)
    /// Where the step being taken started: poles and velocities (a refused step goes back to
    /// them) and the mesh (for the work of the applied forces and local/global's A v).
    Points polesAtStart, velocitiesAtStart, meshAtStart;
    bool avValid = false;
    double size = 1, spacingU = 1, spacingV = 1;
};

}  // namespace hs
