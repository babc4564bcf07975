// The factored control-space matrices and the versions of what they were built from: the mass
// matrix A^T M A, and the system matrix A^T (M + dt D + dt^2 L) A for the two step lengths used
// last (a session steps at its dt, and at twice it while catching up with real time), and the
// system of a few regions of the net (regional steps, active_region.hpp): the principal submatrix
// of a system matrix on the region's poles, factored on its own.
#pragma once
#include <Eigen/SparseCore>
#include <array>
#include <cstdint>
#include <vector>

#include "common/grid_rect.hpp"
#include "solvers/prefactored_solver.hpp"

namespace hs {

class SystemCache {
public:
    /// What a system matrix depends on: the mass, damping, stiffness and bending maps' versions and
    /// the constraints' and held poles' structure.
    using Key = std::array<std::uint64_t, 5>;

    /// One system matrix: its factors (if factored) and Jacobi diagonal.
    struct Slot {
        PrefactoredSolver solver;
        Eigen::SparseMatrix<double> matrix;  ///< the system matrix, restricted to the free poles
        Eigen::VectorXd invDiag;
        Key key = {~0ull, ~0ull, ~0ull, ~0ull, ~0ull};
        double dt = -1;
        bool factored = false;
        std::uint64_t used = 0, built = 0;  // (the build's serial number: what was solved for it is stale after a rebuild)
    };

    /// Whether the mass matrix is factored for the masses and held set of `version`.
    bool massCurrent(std::uint64_t version) const { return massSolver_.ready() && massVersion_ == version; }
    /// Stores and factors the (restricted) mass matrix for `version`.
    void setMass(Eigen::SparseMatrix<double> m, std::uint64_t version);
    const PrefactoredSolver& mass() const { return massSolver_; }
    const Eigen::SparseMatrix<double>& massMatrix() const { return massMatrix_; }

    /// Makes a slot built for (dt, key), factored if `factor`, the current one; false if none is.
    bool use(double dt, bool factor, const Key& key);
    /// Makes the slot used least recently the current one, to be rebuilt (then built()).
    Slot& replace();
    /// The current slot now holds the system for (dt, key).
    void built(double dt, bool factored, const Key& key);
    const Slot& current() const { return slots_[current_]; }

    /// The current slot's system on the poles of `poles` (the others held where they are),
    /// factored on first use and kept for the last few regions; with its work buffers.
    struct RegionSlot {
        GridRect poles;
        std::uint64_t system = 0;  ///< the build of the full system it was cut from
        std::uint64_t built = 0, used = 0;
        PrefactoredSolver solver;
        Points b, x;  ///< the right-hand side and solution on the region's poles, in its order
    };
    RegionSlot& region(const GridRect& poles);
    static constexpr int kRegionDenseLimit = 150;

private:
    std::array<RegionSlot, 4> regions_;
    PrefactoredSolver massSolver_;
    Eigen::SparseMatrix<double> massMatrix_;  // A^T M A, restricted to the free poles, as last factored
    std::uint64_t massVersion_ = ~0ull;
    std::array<Slot, 2> slots_;
    std::size_t current_ = 0;
    std::uint64_t uses_ = 0, builds_ = 0;
};

}  // namespace hs
