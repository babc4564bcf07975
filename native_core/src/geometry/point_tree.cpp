#include "geometry/point_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace hs {

namespace {
// The median split halves every range, so depth stays below log2(kMaxPoints) + 1 < 32, and a
// depth-first search keeps at most one pending cell per level (plus the one it came from).
constexpr int kMaxPending = 64;
}  // namespace

PointTree::PointTree(const Points& points, const char* name) {
    const Eigen::Index n = points.rows();
    if (n == 0) throw std::invalid_argument(std::string(name) + ": no points");
    if (n > kMaxPoints)
        throw std::invalid_argument(std::string(name) + ": at most " + std::to_string(kMaxPoints) + " points, got " +
                                    std::to_string(n));
    if (!withinRange(points)) throw std::invalid_argument(std::string(name) + ": must be finite and within +-1e9");
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), Eigen::Index{0});
    cells_.reserve(static_cast<std::size_t>(n / (kLeaf / 2) + 1));
    sorted_ = points;  // read by build() in the order as given
    build(0, n);
    Points inTreeOrder(n, 3);
    rank_.resize(n);
    for (Eigen::Index k = 0; k < n; ++k) {
        inTreeOrder.row(k) = sorted_.row(order_[k]);
        rank_[order_[k]] = k;
    }
    sorted_ = std::move(inTreeOrder);
}

std::int32_t PointTree::build(Eigen::Index lo, Eigen::Index hi) {
    Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), high = -low;
    for (Eigen::Index k = lo; k < hi; ++k) {
        const Eigen::Vector3d p = sorted_.row(order_[k]).transpose();
        low = low.cwiseMin(p);
        high = high.cwiseMax(p);
    }
    const auto at = static_cast<std::int32_t>(cells_.size());
    Cell cell{lo, hi, -1, -1, 0, {}, {}};
    for (int c = 0; c < 3; ++c) {  // outwards, so the float box still holds every point
        cell.low[c] = std::nextafter(static_cast<float>(low[c]), -std::numeric_limits<float>::infinity());
        cell.high[c] = std::nextafter(static_cast<float>(high[c]), std::numeric_limits<float>::infinity());
    }
    cells_.push_back(cell);
    if (hi - lo <= kLeaf) return at;
    int axis = 0;
    (high - low).maxCoeff(&axis);  // split the longest side: well-shaped cells on flat scans
    const Eigen::Index mid = lo + (hi - lo) / 2;
    std::nth_element(order_.begin() + lo, order_.begin() + mid, order_.begin() + hi,
                     [&](Eigen::Index a, Eigen::Index b) { return sorted_(a, axis) < sorted_(b, axis); });
    cells_[at].axis = static_cast<std::int8_t>(axis);
    const std::int32_t below = build(lo, mid);
    const std::int32_t above = build(mid + 1, hi);  // (a leaf's range may be empty)
    cells_[at].below = below;
    cells_[at].above = above;
    return at;
}

double PointTree::outsideSq(const Cell& c, const Vec3& x) const {
    double d = 0;
    for (int a = 0; a < 3; ++a) {
        const double o = std::max({0.0, c.low[a] - x[a], x[a] - c.high[a]});
        d += o * o;
    }
    return d;
}

Eigen::Index PointTree::nearest(const Vec3& x, double& distanceSq, double bound) const {
    std::int32_t stack[kMaxPending];
    int top = 0;
    stack[top++] = 0;
    double best = bound;
    Eigen::Index bestAt = -1;
    const auto visit = [&](Eigen::Index k) {
        const double d = (sorted_.row(k).transpose() - x).squaredNorm();
        if (d < best) best = d, bestAt = k;
    };
    while (top > 0) {
        const Cell* c = &cells_[stack[--top]];
        if (outsideSq(*c, x) >= best) continue;
        while (c->below >= 0) {
            const Eigen::Index mid = c->lo + (c->hi - c->lo) / 2;
            visit(mid);
            // The side x is on first; the other waits, and is skipped if its box is too far by then.
            const bool low = x[c->axis] < sorted_(mid, c->axis);
            stack[top++] = low ? c->above : c->below;
            c = &cells_[low ? c->below : c->above];
        }
        for (Eigen::Index k = c->lo; k < c->hi; ++k) visit(k);
    }
    distanceSq = best;
    return bestAt >= 0 ? order_[bestAt] : -1;
}

}  // namespace hs
