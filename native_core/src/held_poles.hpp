// Hard constraints on the control net: poles held exactly where they are. A face sculpted in place
// keeps its boundary (G0: the poles on it) and its tangent planes there (G1: the next row too), so
// its neighbours still meet it to the last bit, which no penalty achieves.
#pragma once
#include <Eigen/Sparse>
#include <cstdint>
#include <vector>

#include "types.hpp"

namespace hs {

/// Held poles leave every control-space system: their rows and columns are cut out (the diagonal
/// of a mass-like matrix kept, so it still factors), and the right-hand sides' rows are zeroed, so
/// the solves give them no motion and the free poles move as if the held ones were walls. After a
/// step they are put back exactly (solves that extrapolate, BDF2's x^ = (4 p_n - p_n-1) / 3, move
/// a still pole by rounding).
class HeldPoles {
public:
    bool empty() const { return indices_.empty(); }
    const std::vector<int>& indices() const { return indices_; }
    /// Changes with every set() (so the factored systems that depend on the held set are redone).
    std::uint64_t version() const { return version_; }
    /// Holds the poles at `indices` (any order, repeats allowed; each in 0..poles-1, else
    /// std::invalid_argument naming "indices") at their positions in `poles`; an empty list frees all.
    void set(const std::vector<int>& indices, const Points& poles);
    /// Takes the held poles' positions from `poles` again (after the whole net was replaced: undo,
    /// an edit that continues a live surface).
    void capture(const Points& poles);
    bool held(Eigen::Index pole) const { return !mask_.empty() && mask_[static_cast<std::size_t>(pole)]; }
    /// Zeroes the held rows of x (a right-hand side, a velocity).
    void zeroRows(Points& x) const;
    /// Cuts the held rows and columns out of the square matrix m, keeping (keepDiagonal) or zeroing
    /// their diagonal entries.
    void restrict(Eigen::SparseMatrix<double>& m, bool keepDiagonal) const;
    /// Puts the held poles back where they are held and zeroes their velocities; returns whether any
    /// had moved (then the mesh is out of date).
    bool snap(Points& poles, Points& velocities) const;

private:
    std::vector<int> indices_;
    std::vector<char> mask_;
    Points at_;
    std::uint64_t version_ = 0;
};

}  // namespace hs
