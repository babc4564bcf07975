// B-spline knot vectors: validation, span search and basis functions with derivatives
// (Piegl & Tiller, The NURBS Book, A2.1 and A2.3).
#pragma once
#include <Eigen/Core>
#include <string>
#include <vector>

namespace hs {

/// Maximum B-spline degree supported in each parametric direction.
constexpr int kMaxDegree = 5;

/// Clamped uniform knot vector for `count` control points of degree `degree` on [0, 1].
std::vector<double> clampedUniformKnots(int count, int degree, const char* countName = "controls");

/// Throws std::invalid_argument naming `name` unless `knots` is a valid clamped-or-not,
/// non-decreasing knot vector for `count` control points of degree `degree`
/// (length count+degree+1, finite, inner multiplicities <= degree, non-empty domain).
void validateKnots(const std::vector<double>& knots, int count, int degree, const std::string& name);

/// A validated knot vector with its degree; evaluates basis functions without allocating.
class KnotVector {
public:
    KnotVector() = default;
    KnotVector(std::vector<double> knots, int count, int degree, const std::string& name);

    int degree() const { return degree_; }
    int count() const { return count_; }
    const std::vector<double>& knots() const { return knots_; }
    double domainStart() const { return knots_[degree_]; }
    double domainEnd() const { return knots_[count_]; }

    /// Index of the knot span containing t (t is clamped into the domain).
    int span(double t) const;

    /// Non-zero basis functions N_{span-p..span} and their derivatives up to order nd (<= 2)
    /// at t: ders(k, j) is the k-th derivative of N_{span-p+j}. Returns the span.
    int basis(double t, int nd, Eigen::Matrix<double, 3, kMaxDegree + 1>& ders) const;

private:
    std::vector<double> knots_;
    int count_ = 0;
    int degree_ = 0;
};

}  // namespace hs
