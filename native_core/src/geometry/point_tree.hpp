// Nearest-point queries over a fixed cloud of 3D points (a scan, a surface's samples): a k-d tree
// balanced at the median, queried without allocation, so the haptic loop can ask it.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "common/types.hpp"

namespace hs {

class PointTree {
public:
    /// Largest cloud taken (a 2-million-point scan fits with room).
    static constexpr Eigen::Index kMaxPoints = 50'000'000;
    /// Takes the points (at least one, each finite and within +-1e9; std::invalid_argument naming
    /// `name` otherwise) and builds the tree in O(n log n).
    explicit PointTree(const Points& points, const char* name = "points");

    Eigen::Index size() const { return order_.size(); }
    /// The i-th point as given.
    Vec3 point(Eigen::Index i) const { return sorted_.row(rank_[i]).transpose(); }

    /// The index (as given) of the point nearest x, and its squared distance in `distanceSq`.
    /// Allocates nothing; ties go to the point met first (deterministic for one cloud). With a
    /// `bound` (a squared distance some point is known to be within: the last answer, for a
    /// point that moved a little) only points nearer than it are sought, and -1 is returned
    /// where there is none.
    Eigen::Index nearest(const Vec3& x, double& distanceSq,
                         double bound = std::numeric_limits<double>::infinity()) const;

private:
    static constexpr int kLeaf = 8;
    // A cell: the points at tree positions [lo, hi) and their bounding box (rounded outwards to
    // float); an inner cell's median point at (lo + hi) / 2 splits the rest into two children.
    struct Cell {
        Eigen::Index lo, hi;
        std::int32_t below = -1, above = -1;  // children (cells), -1 for a leaf
        std::int8_t axis = 0;
        float low[3], high[3];
    };
    std::int32_t build(Eigen::Index lo, Eigen::Index hi);
    double outsideSq(const Cell& c, const Vec3& x) const;

    Points sorted_;                      // the points in tree order (subtrees contiguous)
    std::vector<Eigen::Index> order_;    // tree position -> index as given
    std::vector<Eigen::Index> rank_;     // index as given -> tree position
    std::vector<Cell> cells_;            // cells_[0] is the root
};

}  // namespace hs
