// Hard constraints on the control net: poles held exactly where they are, and poles linked to
// others. A face sculpted in place keeps its boundary (G0: the poles on it) and its tangent planes
// there (G1: the next row too), so its neighbours still meet it to the last bit, which no penalty
// achieves. Faces sculpted as one surface keep their tangent planes across their seam: each pole
// on the seam stays an affine combination of its neighbours across it (P_s = sum w_k P_k). A surface
// that must pass through a curve keeps exact linear conditions A P = B on its poles: some poles
// follow the others plus a constant (P_s = o + sum w_k P_k).
#pragma once
#include <Eigen/Sparse>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/types.hpp"

namespace hs {

/// A pole that follows others: P_pole = offset + sum of weight * P_master.
struct PoleLink {
    int pole = -1;
    std::vector<std::pair<int, double>> masters;
    Vec3 offset = Vec3::Zero();
};

/// The control-space systems are solved in the free poles z, with P = T z (+ the held positions):
/// T is the identity on free poles, zero on held ones, and a linked pole's row holds its weights
/// on its free masters. Matrices become T^T m T (held and linked rows and columns cut out, their
/// diagonal kept so the matrix still factors), right-hand sides T^T b (a linked pole's row added
/// onto its masters', held and linked rows zeroed), solutions T z (the linked rows filled in).
/// After a step the held poles are put back and the linked ones onto their masters exactly (solves
/// that extrapolate, BDF2's x^ = (4 p_n - p_n-1) / 3, move a still pole by rounding).
class HeldPoles {
public:
    bool empty() const { return indices_.empty() && links_.empty(); }
    const std::vector<int>& indices() const { return indices_; }
    const std::vector<PoleLink>& links() const { return links_; }
    /// Changes with every set() (so the factored systems that depend on the held set are redone).
    std::uint64_t version() const { return version_; }
    /// Holds the poles at `indices` (any order, repeats allowed; each in 0..poles-1, else
    /// std::invalid_argument naming "indices") at their positions in `poles`, and links `links`
    /// (std::invalid_argument naming "links" for a pole out of range, held, linked twice, or a
    /// master that is itself linked, no masters, a weight or offset not finite); empty lists free all. The
    /// linked poles are put onto their masters at once (`poles` is updated).
    void set(const std::vector<int>& indices, const std::vector<PoleLink>& links, Points& poles);
    /// Takes the held poles' positions from `poles` again (after the whole net was replaced: undo,
    /// an edit that continues a live surface).
    void capture(const Points& poles);
    bool held(Eigen::Index pole) const { return !mask_.empty() && mask_[static_cast<std::size_t>(pole)] == 1; }
    /// Held or linked: not a free pole.
    bool constrained(Eigen::Index pole) const { return !mask_.empty() && mask_[static_cast<std::size_t>(pole)] != 0; }
    /// Zeroes the held and linked rows of x (a vector in the free poles' space).
    void zeroRows(Points& x) const;
    /// x <- T^T x: a right-hand side (forces on all poles) to the free poles.
    void reduce(Points& x) const;
    /// x <- T x: a solution in the free poles (an increment, an acceleration, a velocity) to all
    /// poles (held ones do not move, linked ones follow their masters).
    void expand(Points& x) const;
    /// m <- T^T m T for the square matrix m, keeping (keepDiagonal) or zeroing the held and linked
    /// poles' diagonal entries.
    void restrict(Eigen::SparseMatrix<double>& m, bool keepDiagonal) const;
    /// Puts the held poles back where they are held and the linked ones onto their masters, with
    /// the velocities to match; returns whether any had moved (then the mesh is out of date).
    bool snap(Points& poles, Points& velocities) const;
    /// Linked poles and the free masters they add to, for a sparse right-hand side: appends the
    /// masters of the linked poles in `rows` (marked in `mark`) to `rows`.
    void addMasters(std::vector<int>& rows, std::vector<char>& mark) const;

private:
    std::vector<int> indices_;
    std::vector<PoleLink> links_;
    std::vector<char> mask_;  // 0 free, 1 held, 2 linked
    Points at_;
    Eigen::SparseMatrix<double> t_;  // T, when there are links
    std::uint64_t version_ = 0;
};

}  // namespace hs
