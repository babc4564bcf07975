// Regional steps: a stroke moves a part of a large net, and only that part is stepped. The active
// region is a rectangle of poles: those the tool reaches and those still moving, with a margin of
// quiet poles around them, snapped out to whole tiles so that it changes seldom (each change costs
// a factorisation, kept for the next time in SystemCache). The poles outside it are held exactly
// where they are, at rest, as if asleep; the step reads and writes only the mesh points the
// region's poles move (and, for their forces, two points around them), so its cost grows with the
// region, not the net. The region grows when the motion reaches its margin and never shrinks while
// the surface is awake. After an edit it is chosen afresh: around the poles out of balance.
#pragma once
#include <cstdint>

#include "common/grid_rect.hpp"
#include "common/types.hpp"
#include "geometry/sampling_operator.hpp"
#include "solvers/solver_settings.hpp"

namespace hs {

struct ActiveRegion {
    bool whole = true;  ///< the whole net (then the rectangles are the whole grids)
    GridRect poles;     ///< the poles that move
    GridRect mesh;      ///< the mesh points they move
    GridRect halo;      ///< mesh grown by two points: where the forces on it are read
    std::uint64_t serial = 0;  ///< changes with every new region
};

class RegionChooser {
public:
    const ActiveRegion& region() const { return region_; }
    /// The region is chosen afresh, from the poles' forces too (an edit).
    void wholeNext() { wholeNext_ = true; }
    /// Whether the next choice wants the poles' forces (after an edit).
    bool wantsForces() const { return wholeNext_; }
    /// The surface fell asleep: the next region is chosen afresh.
    void forget() { grown_ = false; }
    /// Chooses the region of the next step: `toolMesh` the mesh points the tool may push (empty
    /// with no tool held; `toolKnown` false where the tool cannot say), `v` the pole velocities,
    /// `floorSpeed` the speed below which nothing counts as moving; where wantsForces(), `force`
    /// the net force on each pole (the held ones' zeroed) and `floorForce` the force below which a
    /// pole is in balance. With `allowed` false the step is whole. Returns whether the region changed.
    bool choose(const SamplingOperator& A, const RegionSettings& settings, bool allowed, bool toolKnown,
                const GridRect& toolMesh, const Points& v, double floorSpeed, const Points* force = nullptr,
                double floorForce = 0);

private:
    void setWhole(const SamplingOperator& A);
    ActiveRegion region_;
    bool wholeNext_ = true, grown_ = false;
};

}  // namespace hs
