#include "dynamics/held_poles.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

void HeldPoles::set(const std::vector<int>& indices, const std::vector<PoleLink>& links, Points& poles) {
    const auto n = static_cast<int>(poles.rows());
    for (int i : indices)
        if (i < 0 || i >= n)
            throw std::invalid_argument("indices: pole index " + std::to_string(i) + " outside 0.." + std::to_string(n - 1));
    std::vector<int> sorted = indices;
    std::sort(sorted.begin(), sorted.end());
    sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
    std::vector<char> mask(sorted.empty() && links.empty() ? 0 : static_cast<std::size_t>(n), 0);
    for (int i : sorted) mask[static_cast<std::size_t>(i)] = 1;
    const auto name = [](int pole) { return "links: pole " + std::to_string(pole); };
    for (const PoleLink& l : links) {
        if (l.pole < 0 || l.pole >= n) throw std::invalid_argument(name(l.pole) + " outside 0.." + std::to_string(n - 1));
        if (mask[static_cast<std::size_t>(l.pole)] == 1) throw std::invalid_argument(name(l.pole) + " is held");
        if (mask[static_cast<std::size_t>(l.pole)] == 2) throw std::invalid_argument(name(l.pole) + " is linked twice");
        if (l.masters.empty()) throw std::invalid_argument(name(l.pole) + " has no masters");
        if (!l.offset.allFinite()) throw std::invalid_argument(name(l.pole) + ": offset must be finite");
        mask[static_cast<std::size_t>(l.pole)] = 2;
    }
    for (const PoleLink& l : links)
        for (const auto& [m, w] : l.masters) {
            if (m < 0 || m >= n || m == l.pole) throw std::invalid_argument(name(l.pole) + ": master " + std::to_string(m) + " is not another pole");
            if (mask[static_cast<std::size_t>(m)] == 2) throw std::invalid_argument(name(l.pole) + ": master " + std::to_string(m) + " is linked itself");
            if (!std::isfinite(w)) throw std::invalid_argument(name(l.pole) + ": weights must be finite");
        }
    indices_ = std::move(sorted);
    links_ = links;
    mask_ = std::move(mask);
    t_.resize(0, 0);
    if (!links_.empty()) {
        std::vector<Eigen::Triplet<double>> t;
        for (int i = 0; i < n; ++i)
            if (mask_[static_cast<std::size_t>(i)] == 0) t.emplace_back(i, i, 1.0);
        for (const PoleLink& l : links_)
            for (const auto& [m, w] : l.masters)
                if (mask_[static_cast<std::size_t>(m)] == 0) t.emplace_back(l.pole, m, w);
        t_.resize(n, n);
        t_.setFromTriplets(t.begin(), t.end());
        for (const PoleLink& l : links_) {
            Vec3 p = l.offset;
            for (const auto& [m, w] : l.masters) p += w * poles.row(m).transpose();
            poles.row(l.pole) = p.transpose();
        }
    }
    capture(poles);
    ++version_;
}

void HeldPoles::capture(const Points& poles) {
    at_.resize(static_cast<Eigen::Index>(indices_.size()), 3);
    for (std::size_t k = 0; k < indices_.size(); ++k) at_.row(static_cast<Eigen::Index>(k)) = poles.row(indices_[k]);
}

void HeldPoles::zeroRows(Points& x) const {
    for (int i : indices_) x.row(i).setZero();
    for (const PoleLink& l : links_) x.row(l.pole).setZero();
}

void HeldPoles::reduce(Points& x) const {
    for (const PoleLink& l : links_) {
        for (const auto& [m, w] : l.masters)
            if (!held(m)) x.row(m) += w * x.row(l.pole);
        x.row(l.pole).setZero();
    }
    for (int i : indices_) x.row(i).setZero();
}

void HeldPoles::expand(Points& x) const {
    for (int i : indices_) x.row(i).setZero();
    for (const PoleLink& l : links_) {
        x.row(l.pole).setZero();
        for (const auto& [m, w] : l.masters)
            if (!held(m)) x.row(l.pole) += w * x.row(m);
    }
}

void HeldPoles::restrict(Eigen::SparseMatrix<double>& m, bool keepDiagonal) const {
    if (empty()) return;
    if (links_.empty()) {
        m.prune([&](Eigen::Index r, Eigen::Index c, double) {
            if (!held(r) && !held(c)) return true;
            return keepDiagonal && r == c;
        });
        return;
    }
    Eigen::SparseMatrix<double> kept(m.rows(), m.cols());
    if (keepDiagonal) {
        std::vector<Eigen::Triplet<double>> d;
        for (Eigen::Index i = 0; i < m.rows(); ++i)
            if (constrained(i)) d.emplace_back(static_cast<int>(i), static_cast<int>(i), m.coeff(i, i));
        kept.setFromTriplets(d.begin(), d.end());
    }
    const Eigen::SparseMatrix<double> tt = t_.transpose();
    m = (tt * m * t_).pruned() + kept;
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
    for (const PoleLink& l : links_) {
        Vec3 p = l.offset, v = Vec3::Zero();
        for (const auto& [m, w] : l.masters) {
            p += w * poles.row(m).transpose();
            v += w * velocities.row(m).transpose();
        }
        if (poles.row(l.pole) != p.transpose()) moved = true;
        poles.row(l.pole) = p.transpose();
        velocities.row(l.pole) = v.transpose();
    }
    return moved;
}

void HeldPoles::addMasters(std::vector<int>& rows, std::vector<char>& mark) const {
    if (links_.empty()) return;
    for (const PoleLink& l : links_) {
        if (!mark[static_cast<std::size_t>(l.pole)]) continue;
        for (const auto& [m, w] : l.masters)
            if (!held(m) && !mark[static_cast<std::size_t>(m)]) {
                mark[static_cast<std::size_t>(m)] = 1;
                rows.push_back(m);
            }
    }
}

}  // namespace hs
