#include "dynamics/data_springs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hs {

namespace {
// A scan point further to the side than this many mesh spacings, or than tan(60 deg) of its
// distance along the normal, is past the scan's edge or across a hole from the mesh point.
constexpr double kSideSpacings = 1.5, kSideSlope = 1.7320508075688772;
// Largest omega dt the pull takes: a quarter of the explicit limit (2), and the critical damper's
// rate 2 omega dt stays at 1.
constexpr double kMaxOmegaDt = 0.5;
}  // namespace

DataSprings::DataSprings(int g, int h) : map(1.0, "pull"), g_(g), h_(h) {
    map.allowZero(true);
    const Eigen::Index S = static_cast<Eigen::Index>(g) * h;
    anchor_.setZero(S, 3);
    normal_.setZero(S, 3);
    held_.assign(static_cast<size_t>(S), 0);
    misses_.assign(static_cast<size_t>(S), 0);
    weight_.setOnes(S);
}

void DataSprings::setTarget(std::shared_ptr<const PointTree> tree, double reach) {
    if (tree) requireInRange(reach, "reach", 1e-9, kMaxCoordinate);
    tree_ = std::move(tree);
    reach_ = tree_ ? reach : 0.0;
    forget();
}

void DataSprings::setEnabled(bool enabled) { enabled_ = enabled; }

void DataSprings::setStrength(double strength) { strength_ = requireInRange(strength, "strength", 0.0, 1e6); }

void DataSprings::forget() {
    std::fill(held_.begin(), held_.end(), 0);
    std::fill(misses_.begin(), misses_.end(), 0);
    next_ = 0;
    sweeps_ = 0;
}

Eigen::Index DataSprings::anchored() const {
    return static_cast<Eigen::Index>(std::count(held_.begin(), held_.end(), 1));
}

Vec3 DataSprings::normalAt(const Points& d, int a, int b) const {
    // Central differences, one-sided at the mesh's edges.
    const int a0 = std::max(a - 1, 0), a1 = std::min(a + 1, g_ - 1), b0 = std::max(b - 1, 0), b1 = std::min(b + 1, h_ - 1);
    const Vec3 du = (d.row(a1 * h_ + b) - d.row(a0 * h_ + b)).transpose();
    const Vec3 dv = (d.row(a * h_ + b1) - d.row(a * h_ + b0)).transpose();
    const Vec3 n = du.cross(dv);
    const double len = n.norm();
    return len > 0 ? Vec3(n / len) : Vec3::Zero();
}

void DataSprings::refresh(const Points& d, double su, double sv) {
    if (!tree_) return;
    const Eigen::Index S = d.rows();
    const Eigen::Index count = std::min(S, std::clamp(S / 128, kMinRefresh, kMaxRefresh));
    const double side = kSideSpacings * std::max(su, sv), reachSq = reach_ * reach_;
    for (Eigen::Index visited = 0, sought = 0; sought < count && visited < S; ++visited) {
        const Eigen::Index i = next_;
        if (++next_ == S) {
            next_ = 0;
            ++sweeps_;
        }
        // A point that found no scan point twice running (over a hole, past the scan's edge) is
        // sought one sweep in kMissedEvery: its search is the dearest (far from every point).
        std::uint8_t& missed = misses_[static_cast<size_t>(i)];
        if (missed >= 2 && (sweeps_ + static_cast<std::uint64_t>(i)) % kMissedEvery != 0) continue;
        ++sought;
        const Vec3 x = d.row(i).transpose();
        const Vec3 n = normalAt(d, static_cast<int>(i / h_), static_cast<int>(i % h_));
        // Sought within the distance of the last anchor (it moved a little since): the search
        // prunes most of the tree at once, and keeps that anchor where nothing is nearer; a point
        // without one within the reach.
        const bool had = held_[static_cast<size_t>(i)] != 0;
        double distSq = 0;
        const double bound = had ? (anchor_.row(i).transpose() - x).squaredNorm() * (1 + 1e-12) + 1e-300 : reachSq;
        const Eigen::Index found = tree_->nearest(x, distSq, bound);
        bool pulls = false;
        if (found >= 0 || had) {
            const Vec3 a = found >= 0 ? tree_->point(found) : Vec3(anchor_.row(i).transpose());
            const Vec3 off = a - x;
            const double along = off.dot(n), sideways = (off - along * n).norm();
            pulls = off.squaredNorm() <= reachSq && n.squaredNorm() > 0 &&
                    sideways <= std::max(side, kSideSlope * std::abs(along));
            if (pulls) {
                anchor_.row(i) = a.transpose();
                normal_.row(i) = n.transpose();
            }
        }
        held_[static_cast<size_t>(i)] = pulls ? 1 : 0;
        missed = pulls ? 0 : static_cast<std::uint8_t>(std::min(missed + 1, 255));
    }
}

void DataSprings::refreshWeights() {
    if (map.version() == mapVersion_) return;
    for (int a = 0; a < g_; ++a)
        for (int b = 0; b < h_; ++b)
            weight_[a * h_ + b] = map.at(g_ > 1 ? static_cast<double>(a) / (g_ - 1) : 0.0,
                                         h_ > 1 ? static_cast<double>(b) / (h_ - 1) : 0.0);
    mapVersion_ = map.version();
}

double DataSprings::maxOmegaSq() const {
    return active() ? strength_ * map.values().maxCoeff() * kOmega * kOmega : 0.0;
}

void DataSprings::takeAnchors(const DataSprings& other) {
    if (tree_ != other.tree_ || reach_ != other.reach_ || anchor_.rows() != other.anchor_.rows()) return;
    anchor_ = other.anchor_;
    normal_ = other.normal_;
    held_ = other.held_;
    misses_ = other.misses_;
    next_ = other.next_;
    sweeps_ = other.sweeps_;
}

void DataSprings::forces(const Points& d, const Points& dd, const Eigen::VectorXd& m, double dt, Points& out) {
    refreshWeights();
    const double base = strength_ * kOmega * kOmega, limit = kMaxOmegaDt * kMaxOmegaDt / (dt * dt);
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
        if (!held_[static_cast<size_t>(i)]) {
            out.row(i).setZero();
            continue;
        }
        // The damper acts in every direction: along the normal only, the sheet's sliding modes
        // rang on undamped (kinetic energy 100-700 after 1-2 s where it is 1e-3 with it).
        const double omegaSq = std::min(base * weight_[i], limit);
        const double k = omegaSq * m[i], c = 2.0 * std::sqrt(omegaSq) * m[i];
        const double gap = (anchor_.row(i) - d.row(i)).dot(normal_.row(i));
        out.row(i) = (k * gap) * normal_.row(i) - c * dd.row(i);
    }
}

}  // namespace hs
