// A rectangle of a row-major grid (mesh points a * h + b, poles i * nv + j): the unit a regional
// step works in. Its rows of points are contiguous runs, so a loop over the rectangle is a few
// vectorisable streams, and a rectangle as wide as the grid is one run.
#pragma once
#include <Eigen/Core>
#include <algorithm>

namespace hs {

/// Grid rows [r0, r1) and columns [c0, c1) of a grid with `stride` columns.
struct GridRect {
    int r0 = 0, r1 = 0, c0 = 0, c1 = 0, stride = 0;

    static GridRect whole(int rows, int cols) { return {0, rows, 0, cols, cols}; }
    bool empty() const { return r1 <= r0 || c1 <= c0; }
    Eigen::Index count() const { return empty() ? 0 : static_cast<Eigen::Index>(r1 - r0) * (c1 - c0); }
    bool contains(int row, int col) const { return row >= r0 && row < r1 && col >= c0 && col < c1; }
    bool containsIndex(Eigen::Index i) const { return contains(static_cast<int>(i / stride), static_cast<int>(i % stride)); }
    bool operator==(const GridRect& o) const {
        return r0 == o.r0 && r1 == o.r1 && c0 == o.c0 && c1 == o.c1 && stride == o.stride;
    }
    bool operator!=(const GridRect& o) const { return !(*this == o); }
    /// Grown by `n` on every side, clipped to a grid of `rows` rows.
    GridRect grown(int n, int rows) const {
        return {std::max(0, r0 - n), std::min(rows, r1 + n), std::max(0, c0 - n), std::min(stride, c1 + n), stride};
    }

    /// Calls f(first index, length) for each contiguous run of the rectangle.
    template <class F>
    void forRuns(F&& f) const {
        if (empty()) return;
        if (c0 == 0 && c1 == stride) {
            f(static_cast<Eigen::Index>(r0) * stride, static_cast<Eigen::Index>(r1 - r0) * stride);
            return;
        }
        for (int r = r0; r < r1; ++r) f(static_cast<Eigen::Index>(r) * stride + c0, static_cast<Eigen::Index>(c1 - c0));
    }
    /// Calls f(span) for each run, where span(matrix) is that run's rows of a matrix:
    ///   rect.forSpans([&](const auto& r) { r(x) = 2 * r(y); });
    template <class F>
    void forSpans(F&& f) const {
        forRuns([&](Eigen::Index first, Eigen::Index length) {
            const auto span = [first, length](auto& m) { return m.middleRows(first, length); };
            f(span);
        });
    }
};

}  // namespace hs
