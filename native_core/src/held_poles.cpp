#include "held_poles.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hs {

void HeldPoles::set(const std::vector<int>& indices, const Points& poles) {
    const auto n = static_cast<int>(poles.rows());
    for (int i : indices)
        if (i < 0 || i >= n)
            throw std::invalid_argument("indices: pole index " + std::to_string(i) + " outside 0.." + std::to_string(n - 1));
    std::vector<int> sorted = indices;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    indices_ = std::move(sorted);
    mask_.assign(indices_.empty() ? 0 : static_cast<std::size_t>(n), 0);
    for (int i : indices_) mask_[static_cast<std::size_t>(i)] = 1;
    capture(poles);
    ++version_;
}

void HeldPoles::capture(const Points& poles) {
    at_.resize(static_cast<Eigen::Index>(indices_.size()), 3);
    for (std::size_t k = 0; k < indices_.size(); ++k) at_.row(static_cast<Eigen::Index>(k)) = poles.row(indices_[k]);
}

void HeldPoles::zeroRows(Points& x) const {
    for (int i : indices_) x.row(i).setZero();
}

void HeldPoles::restrict(Eigen::SparseMatrix<double>& m, bool keepDiagonal) const {
    if (indices_.empty()) return;
    m.prune([&](Eigen::Index r, Eigen::Index c, double) {
        if (!held(r) && !held(c)) return true;
        return keepDiagonal && r == c;
    });
}

bool HeldPoles::snap(Points& poles, Points& velocities) const {
    bool moved = false;
    for (std::size_t k = 0; k < indices_.size(); ++k) {
        const int i = indices_[k];
        if (poles.row(i) != at_.row(static_cast<Eigen::Index>(k))) {
            poles.row(i) = at_.row(static_cast<Eigen::Index>(k));
            moved = true;
        }
        velocities.row(i).setZero();
    }
    return moved;
}

}  // namespace hs
