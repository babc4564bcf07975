// The pull toward a scan: data springs, as D-NURBS fit a surface to points (Terzopoulos & Qin
// 1994). Each mesh point hangs on a zero-rest spring to the plane through the nearest point of the
// target cloud, across the mesh's normal there as it was when the point was sought (fixed until it
// is sought again, so the spring is conservative in between; a normal taken afresh each step is a
// follower force, and it fluttered), with a damper that makes it critically damped.
// Acting along the normal only, it lets the mesh slide along the scan: pulled toward the nearest
// point itself, a plate half over a scan crawled sideways onto it. The stiffness goes with the
// point's mass (the pull is a frequency, the same on any mesh). A spring is dropped where its scan
// point is beyond reach (an outlier, another part of the scan) or lies off to the side, past the
// scan's edge or across a hole: there the surface's own stiffness bridges. Springs re-seek their
// scan point a fraction of the mesh at a time, so the cost per step stays small.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "common/types.hpp"
#include "dynamics/material_map.hpp"
#include "geometry/point_tree.hpp"

namespace hs {

class DataSprings {
public:
    /// The pull's natural frequency at strength 1 (rad/s): a mesh point pulled by its spring alone
    /// settles on the scan in about 1/40 s, and the pull outweighs the sheet's stiffness over a
    /// feature a few mesh cells wide.
    static constexpr double kOmega = 200.0;
    /// Anchors re-sought per step (rolling over the mesh), a 128th of it within these bounds: a
    /// 64 x 64 mesh is sought again every 128 ms at 1 kHz, a 256 x 256 one every 256 ms. (A query
    /// on a million-point scan costs about 4 us, its tree being far larger than the caches; the
    /// plane a spring pulls toward stays good while its point slides along the scan.)
    static constexpr Eigen::Index kMinRefresh = 32, kMaxRefresh = 256;
    /// A point that found no scan point twice running is sought again one sweep in this many.
    static constexpr std::uint64_t kMissedEvery = 8;

    /// For a g x h mesh.
    DataSprings(int g, int h);

    /// The target cloud (shared, read-only: queried on the simulation thread) and the reach (> 0)
    /// beyond which a scan point does not pull; a null tree removes the target.
    void setTarget(std::shared_ptr<const PointTree> tree, double reach);
    const std::shared_ptr<const PointTree>& target() const { return tree_; }
    double reach() const { return reach_; }
    /// On/off and strength (0..1e6; the spring's stiffness is strength x map x mass x kOmega^2).
    void setEnabled(bool enabled);
    void setStrength(double strength);
    bool enabled() const { return enabled_; }
    double strength() const { return strength_; }
    /// Whether it pulls at all: a target, switched on, strength above zero.
    bool active() const { return tree_ && enabled_ && strength_ > 0; }
    /// Where the pull acts, and how much (0: nowhere, 1: fully), painted over the unit (u, v) square.
    MaterialMap map;

    /// Re-seeks the next anchors of the rolling refresh on mesh d (g x h, mean spacings su, sv).
    /// Allocates nothing.
    void refresh(const Points& d, double su, double sv);
    /// Forgets every anchor (a new target or mesh): the next refreshes seek them afresh.
    void forget();
    /// The pull at mesh d moving at dd into `out` (overwritten) for point masses m and a step of
    /// dt, its frequency held to omega dt <= 0.5 (explicit: stable, the damper too).
    void forces(const Points& d, const Points& dd, const Eigen::VectorXd& m, double dt, Points& out);
    /// Largest omega^2 the pull adds to a mesh point (for the explicit bound; 0 when inactive).
    double maxOmegaSq() const;
    /// Takes `other`'s anchors where it has the same target (an edit continuing a live surface).
    void takeAnchors(const DataSprings& other);
    /// Anchors held now (a measure for tests and the session status).
    Eigen::Index anchored() const;

private:
    Vec3 normalAt(const Points& d, int a, int b) const;
    void refreshWeights();

    int g_, h_;
    std::shared_ptr<const PointTree> tree_;
    double reach_ = 0, strength_ = 1.0;
    bool enabled_ = true;
    Points anchor_, normal_;      // per mesh point: its scan point, and the normal it pulls along
    std::vector<std::uint8_t> held_;    // whether it has an anchor
    std::vector<std::uint8_t> misses_;  // sweeps in a row it found none
    Eigen::VectorXd weight_;      // the map at each mesh point
    std::uint64_t mapVersion_ = ~0ull;
    Eigen::Index next_ = 0;      // the next point to seek
    std::uint64_t sweeps_ = 0;   // sweeps over the mesh so far
};

}  // namespace hs
