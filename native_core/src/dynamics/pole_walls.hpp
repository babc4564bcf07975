// Walls a sculpted face stays behind: half-spaces its poles may not leave. A face sculpted in place
// meets its neighbours at creases (a box's top and its sides); pushed sideways it would fold over
// them and close a self-intersecting solid. Each wall is the plane a neighbour face has at the
// shared edge, facing out of the solid; a face whose poles stay behind it stays behind it too (a
// B-spline surface lies in the convex hull of its poles). After each step a pole that crossed a
// wall is put back onto the nearest point behind all of its walls and loses the velocity that
// carried it out, like a mass meeting a wall.
#pragma once
#include <array>
#include <vector>

#include "common/types.hpp"

namespace hs {

/// A plane through `point` with outward `normal`; the poles listed stay on the side it faces away from.
struct PoleWall {
    Vec3 point = Vec3::Zero();
    Vec3 normal = Vec3::UnitZ();
    std::vector<int> poles;
};

class PoleWalls {
public:
    /// Walls one pole may be behind (a face's corner pole has two, one per edge it is near).
    static constexpr int kMaxPerPole = 8;

    bool empty() const { return walls_.empty(); }
    const std::vector<PoleWall>& walls() const { return walls_; }
    /// Replaces the walls (normals made unit). Throws std::invalid_argument naming "walls" for a
    /// point or normal that is not finite or beyond +-1e9, a zero normal, a pole outside
    /// 0..poleCount-1, or a pole behind more than kMaxPerPole walls.
    void set(const std::vector<PoleWall>& walls, Eigen::Index poleCount);
    /// Puts every listed pole that is not `fixed` onto the nearest point behind all of its walls,
    /// removing the outward part of its velocity there; returns whether any moved.
    template <class Fixed>
    bool project(Points& poles, Points& velocities, const Fixed& fixed) const {
        bool moved = false;
        for (std::size_t k = 0; k + 1 < offsets_.size(); ++k) {
            const int pole = poleOf_[k];
            if (!fixed(pole)) moved |= projectPole(poles, velocities, pole, offsets_[k], offsets_[k + 1]);
        }
        return moved;
    }

private:
    /// One pole against its walls wallOf_[begin..end).
    bool projectPole(Points& poles, Points& velocities, int pole, int begin, int end) const;

    std::vector<PoleWall> walls_;
    // The walls by pole, flat for the per-step loop: pole poleOf_[k] is behind walls
    // wallOf_[offsets_[k] .. offsets_[k + 1]).
    std::vector<int> poleOf_, offsets_, wallOf_;
};

}  // namespace hs
