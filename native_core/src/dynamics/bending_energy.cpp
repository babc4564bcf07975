#include "dynamics/bending_energy.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/types.hpp"

namespace hs {

BendingEnergy::BendingEnergy(int g, int h, double su, double sv, const Points& reference)
    : g_(g), h_(h), ref_(reference) {
    diff_.setZero(reference.rows(), 3);
    prod_.setZero(reference.rows(), 3);
    const Eigen::SparseMatrix<double, Eigen::RowMajor> B = differences(g, h, su, sv, &centres_);
    w_.setZero(B.rows());
    // K_b's pattern (B^T B) and, for each of its values, the rows of B that add to it.
    K_ = Eigen::SparseMatrix<double, Eigen::RowMajor>(B.transpose() * B);
    K_.makeCompressed();
    auto valueIndex = [this](int i, int j) {
        const int* inner = K_.innerIndexPtr();
        const int* first = inner + K_.outerIndexPtr()[i];
        const int* last = inner + K_.outerIndexPtr()[i + 1];
        return static_cast<int>(std::lower_bound(first, last, j) - inner);
    };
    for (Eigen::Index r = 0; r < B.rows(); ++r)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator a(B, r); a; ++a)
            for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator b(B, r); b; ++b)
                contributions_.push_back({valueIndex(static_cast<int>(a.col()), static_cast<int>(b.col())),
                                          static_cast<int>(r), a.value() * b.value()});
    std::sort(contributions_.begin(), contributions_.end(),
              [](const Contribution& x, const Contribution& y) { return x.value < y.value; });
    std::fill(K_.valuePtr(), K_.valuePtr() + K_.nonZeros(), 0.0);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> BendingEnergy::differences(int g, int h, double su, double sv,
                                                                        std::vector<int>* centres) {
    const double cuu = sv / su, cvv = su / sv, cuv = std::sqrt(2.0);
    std::vector<Eigen::Triplet<double>> t;
    std::vector<int> centre;
    int row = 0;
    auto at = [h](int a, int b) { return a * h + b; };
    for (int a = 0; a < g; ++a)
        for (int b = 0; b < h; ++b) {
            if (a > 0 && a + 1 < g) {  // u second difference
                t.emplace_back(row, at(a - 1, b), cuu);
                t.emplace_back(row, at(a, b), -2 * cuu);
                t.emplace_back(row, at(a + 1, b), cuu);
                centre.push_back(at(a, b));
                ++row;
            }
            if (b > 0 && b + 1 < h) {  // v second difference
                t.emplace_back(row, at(a, b - 1), cvv);
                t.emplace_back(row, at(a, b), -2 * cvv);
                t.emplace_back(row, at(a, b + 1), cvv);
                centre.push_back(at(a, b));
                ++row;
            }
            if (a + 1 < g && b + 1 < h) {  // mixed difference over the cell, counted twice (sqrt 2)
                t.emplace_back(row, at(a, b), cuv);
                t.emplace_back(row, at(a + 1, b), -cuv);
                t.emplace_back(row, at(a, b + 1), -cuv);
                t.emplace_back(row, at(a + 1, b + 1), cuv);
                centre.push_back(at(a, b));
                ++row;
            }
        }
    Eigen::SparseMatrix<double, Eigen::RowMajor> B(row, g * h);
    B.setFromTriplets(t.begin(), t.end());
    if (centres) *centres = std::move(centre);
    return B;
}

void BendingEnergy::setWeights(const MaterialMap& bending, const MaterialMap& stiffness) {
    for (Eigen::Index r = 0; r < w_.size(); ++r) {
        const int i = centres_[static_cast<std::size_t>(r)];
        const double u = g_ > 1 ? static_cast<double>(i / h_) / (g_ - 1) : 0.0;
        const double v = h_ > 1 ? static_cast<double>(i % h_) / (h_ - 1) : 0.0;
        w_[r] = bending.at(u, v) * stiffness.at(u, v);
    }
    double* k = K_.valuePtr();
    std::fill(k, k + K_.nonZeros(), 0.0);
    for (const Contribution& c : contributions_) k[c.value] += w_[c.row] * c.coefficient;
    maxRowSum_ = 0;
    for (Eigen::Index r = 0; r < K_.outerSize(); ++r) {
        double sum = 0;
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(K_, r); it; ++it) sum += std::abs(it.value());
        maxRowSum_ = std::max(maxRowSum_, sum);
    }
}

void BendingEnergy::setReference(const Points& reference) {
    if (reference.rows() != ref_.rows()) throw std::invalid_argument("reference: one point per mesh point (g x h rows)");
    if (!withinRange(reference)) throw std::invalid_argument("reference: must be finite and within +-1e9");
    ref_ = reference;
}

void BendingEnergy::follow(const Points& d, double fraction, const GridRect* window) {
    if (window) {
        window->forSpans([&](const auto& r) { r(ref_) += std::min(1.0, fraction) * (r(d) - r(ref_)); });
        return;
    }
    if (fraction >= 1) ref_ = d;
    else ref_ += fraction * (d - ref_);
}

double BendingEnergy::addForces(const Points& d, Points& f, double scale, const GridRect* window) const {
    if (!active()) return 0.0;
    if (window) {
        window->grown(2, g_).forSpans([&](const auto& r) { r(diff_) = r(d) - r(ref_); });
        window->forRuns([&](Eigen::Index i, Eigen::Index n) {
            prod_.middleRows(i, n).noalias() = K_.middleRows(i, n) * diff_;
            f.middleRows(i, n) -= scale * prod_.middleRows(i, n);
        });
        return 0.0;
    }
    diff_ = d - ref_;
    prod_.noalias() = K_ * diff_;
    f -= scale * prod_;
    return 0.5 * diff_.cwiseProduct(prod_).sum();
}

double BendingEnergy::energy(const Points& d) const {
    if (!active()) return 0.0;
    diff_ = d - ref_;
    prod_.noalias() = K_ * diff_;
    return 0.5 * diff_.cwiseProduct(prod_).sum();
}

void BendingEnergy::addStiffness(const Points& y, Points& out) const {
    if (!active()) return;
    prod_.noalias() = K_ * y;
    out += prod_;
}

void BendingEnergy::addMatrix(std::vector<Eigen::Triplet<double>>& t) const {
    if (!active()) return;
    for (Eigen::Index r = 0; r < K_.outerSize(); ++r)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(K_, r); it; ++it)
            t.emplace_back(static_cast<int>(r), static_cast<int>(it.col()), it.value());
}

}  // namespace hs
