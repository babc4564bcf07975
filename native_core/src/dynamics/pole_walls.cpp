#include "dynamics/pole_walls.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

namespace hs {

void PoleWalls::set(const std::vector<PoleWall>& walls, Eigen::Index poleCount) {
    std::vector<PoleWall> made = walls;
    std::map<int, std::vector<int>> byPole;
    for (std::size_t k = 0; k < made.size(); ++k) {
        PoleWall& w = made[k];
        const std::string which = "walls: wall " + std::to_string(k);
        if (!withinRange(w.point) || !w.normal.allFinite())
            throw std::invalid_argument(which + " is not finite or lies beyond +-1e9");
        const double n = w.normal.norm();
        if (!(n > 0)) throw std::invalid_argument(which + " has a zero normal");
        w.normal /= n;
        for (int p : w.poles) {
            if (p < 0 || p >= poleCount)
                throw std::invalid_argument(which + ": pole " + std::to_string(p) + " is not in 0.." + std::to_string(poleCount - 1));
            std::vector<int>& mine = byPole[p];
            if (std::find(mine.begin(), mine.end(), static_cast<int>(k)) == mine.end()) mine.push_back(static_cast<int>(k));
            if (mine.size() > static_cast<std::size_t>(kMaxPerPole))
                throw std::invalid_argument("walls: pole " + std::to_string(p) + " is behind more than " +
                                            std::to_string(kMaxPerPole) + " walls");
        }
    }
    std::vector<int> poleOf, offsets{0}, wallOf;
    for (const auto& [pole, mine] : byPole) {
        poleOf.push_back(pole);
        wallOf.insert(wallOf.end(), mine.begin(), mine.end());
        offsets.push_back(static_cast<int>(wallOf.size()));
    }
    walls_ = std::move(made);
    poleOf_ = std::move(poleOf);
    offsets_ = std::move(offsets);
    wallOf_ = std::move(wallOf);
}

bool PoleWalls::projectPole(Points& poles, Points& velocities, int pole, int begin, int end) const {
    const Vec3 p = poles.row(pole).transpose();
    const int m = end - begin;
    std::array<const PoleWall*, kMaxPerPole> w{};
    double scale = std::max(1.0, p.cwiseAbs().maxCoeff());
    bool outside = false;
    for (int k = 0; k < m; ++k) {
        w[k] = &walls_[wallOf_[begin + k]];
        scale = std::max(scale, w[k]->point.cwiseAbs().maxCoeff());
        outside |= (p - w[k]->point).dot(w[k]->normal) > 0;
    }
    if (!outside) return false;
    const double tol = 1e-12 * scale;
    auto behindAll = [&](const Vec3& x) {
        for (int k = 0; k < m; ++k)
            if ((x - w[k]->point).dot(w[k]->normal) > tol) return false;
        return true;
    };
    // The nearest point behind all walls lies on one, two or three of them (in 3D no more are
    // independent): try each such set, the projection onto its planes' intersection, keep the
    // nearest that is behind every wall.
    Vec3 best = p;
    double bestDistance = std::numeric_limits<double>::infinity();
    auto consider = [&](std::initializer_list<int> set) {
        const int n = static_cast<int>(set.size());
        Eigen::Matrix3d gram = Eigen::Matrix3d::Identity();
        Eigen::Vector3d gap = Eigen::Vector3d::Zero();
        std::array<const PoleWall*, 3> s{};
        int i = 0;
        for (int k : set) s[i++] = w[k];
        for (int a = 0; a < n; ++a) {
            gap[a] = (p - s[a]->point).dot(s[a]->normal);
            for (int b = 0; b < n; ++b) gram(a, b) = s[a]->normal.dot(s[b]->normal);
        }
        const auto lu = gram.topLeftCorner(n, n).fullPivLu();
        if (!lu.isInvertible() || std::abs(lu.determinant()) < 1e-12) return;  // (parallel planes: another set has it)
        const Eigen::VectorXd lambda = lu.solve(gap.head(n));
        Vec3 x = p;
        for (int a = 0; a < n; ++a) x -= lambda[a] * s[a]->normal;
        const double d = (x - p).squaredNorm();
        if (d < bestDistance && behindAll(x)) {
            best = x;
            bestDistance = d;
        }
    };
    for (int a = 0; a < m; ++a) consider({a});
    for (int a = 0; a < m; ++a)
        for (int b = a + 1; b < m; ++b) consider({a, b});
    for (int a = 0; a < m; ++a)
        for (int b = a + 1; b < m; ++b)
            for (int c = b + 1; c < m; ++c) consider({a, b, c});
    if (!std::isfinite(bestDistance)) {  // (rounding left no set behind all: one wall at a time)
        for (int round = 0; round < 8; ++round)
            for (int k = 0; k < m; ++k) {
                const double out = (best - w[k]->point).dot(w[k]->normal);
                if (out > 0) best -= out * w[k]->normal;
            }
    }
    poles.row(pole) = best.transpose();
    // The velocity keeps what runs along the walls it now touches.
    for (int round = 0; round < 2; ++round)
        for (int k = 0; k < m; ++k) {
            const PoleWall& wall = *w[k];
            if ((best - wall.point).dot(wall.normal) < -1e-9 * scale) continue;
            const double speed = velocities.row(pole).dot(wall.normal.transpose());
            if (speed > 0) velocities.row(pole) -= speed * wall.normal.transpose();
        }
    return true;
}

}  // namespace hs
