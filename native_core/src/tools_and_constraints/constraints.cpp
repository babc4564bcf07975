#include "tools_and_constraints/constraints.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hs {

double curvatureChord(double kappa, double c1, double c2) {
    kappa = std::abs(kappa);
    if (kappa == 0) return c1 + c2;
    const double s1 = std::min(1.0, kappa * c1 / 2), s2 = std::min(1.0, kappa * c2 / 2);
    const double half = std::asin(s1) + std::asin(s2);  // half the central angle over both chords
    return 2.0 / kappa * std::sin(half);
}

int ConstraintSet::interior(int point) const {
    const int i = std::clamp(point / h_, 1, g_ - 2), j = std::clamp(point % h_, 1, h_ - 2);
    return i * h_ + j;
}

Vec3 ConstraintSet::meshNormal(const Points& d, int p) const {
    const Vec3 du = d.row(p + h_) - d.row(p - h_), dv = d.row(p + 1) - d.row(p - 1);
    const Vec3 n = du.cross(dv);
    const double l = n.norm();
    return l > 0 ? Vec3(n / l) : Vec3::UnitZ();
}

double ConstraintSet::meshCurvature(const Points& d, int p, int dir) const {
    const int step = dir == 0 ? h_ : 1;
    const Vec3 a = d.row(p - step), b = d.row(p), c = d.row(p + step);
    const double ab = (b - a).norm(), bc = (c - b).norm(), ac = (c - a).norm();
    const double denom = ab * bc * ac;
    return denom > 0 ? 2.0 * (b - a).cross(c - a).norm() / denom : 0.0;
}

int ConstraintSet::add(ConstraintKind kind, int point, double stiffness, const Points& d, const Vec3* target,
                       const double* curvatureU, const double* curvatureV) {
    if (!(stiffness > 0) || !std::isfinite(stiffness))
        throw std::invalid_argument("stiffness: must be finite and > 0");
    if (point < 0 || point >= g_ * h_) throw std::invalid_argument("point: mesh index out of range");
    if (target && !target->allFinite()) throw std::invalid_argument("target: must be finite");
    Constraint c;
    c.id = nextId_;
    c.kind = kind;
    c.stiffness = stiffness;
    c.point = kind == ConstraintKind::Point ? point : interior(point);
    if (kind != ConstraintKind::Point && (g_ < 3 || h_ < 3))
        throw std::invalid_argument("kind: this constraint needs a mesh of at least 3x3");
    const int p = c.point;
    switch (kind) {
        case ConstraintKind::Point:
            c.target = target ? *target : Vec3(d.row(p));
            break;
        case ConstraintKind::Tangent:
        case ConstraintKind::Normal: {
            const Vec3 current = meshNormal(d, p);
            if (target && !(target->norm() > 0)) throw std::invalid_argument("normal: must be a non-zero vector");
            c.target = target ? Vec3(target->normalized()) : current;
            const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(current, c.target);
            const int nb[4] = {p + h_, p - h_, p + 1, p - 1};
            for (int k = 0; k < 4; ++k) c.offsets[k] = turn * Vec3(d.row(nb[k]) - d.row(p));
            break;
        }
        case ConstraintKind::Curvature: {
            c.curvatureU = curvatureU ? std::abs(*curvatureU) : meshCurvature(d, p, 0);
            c.curvatureV = curvatureV ? std::abs(*curvatureV) : meshCurvature(d, p, 1);
            if (!std::isfinite(c.curvatureU) || !std::isfinite(c.curvatureV))
                throw std::invalid_argument("curvature: targets must be finite");
            const double cu = std::max((d.row(p + h_) - d.row(p)).norm(), (d.row(p) - d.row(p - h_)).norm());
            const double cv = std::max((d.row(p + 1) - d.row(p)).norm(), (d.row(p) - d.row(p - 1)).norm());
            if (c.curvatureU * cu > 2 || c.curvatureV * cv > 2)
                throw std::invalid_argument("curvature: target radius is smaller than half the mesh spacing");
            break;
        }
    }
    ++nextId_;
    items_.push_back(c);
    ++structureVersion_;
    ++version_;
    return c.id;
}

void ConstraintSet::restore(const Constraint& c) {
    if (c.id <= 0) throw std::invalid_argument("id: must be > 0");
    for (const auto& o : items_)
        if (o.id == c.id) throw std::invalid_argument("id: constraint " + std::to_string(c.id) + " exists");
    if (!(c.stiffness > 0) || !std::isfinite(c.stiffness)) throw std::invalid_argument("stiffness: must be finite and > 0");
    if (c.point < 0 || c.point >= g_ * h_) throw std::invalid_argument("index: mesh index out of range");
    if (c.kind != ConstraintKind::Point && c.point != interior(c.point))
        throw std::invalid_argument("index: this constraint needs an interior mesh point");
    if (!c.target.allFinite() || !std::isfinite(c.curvatureU) || !std::isfinite(c.curvatureV))
        throw std::invalid_argument("target: must be finite");
    for (const auto& o : c.offsets)
        if (!o.allFinite()) throw std::invalid_argument("offsets: must be finite");
    if ((c.kind == ConstraintKind::Tangent || c.kind == ConstraintKind::Normal) && std::abs(c.target.norm() - 1) > 1e-9)
        throw std::invalid_argument("target: normal must be a unit vector");
    items_.push_back(c);
    nextId_ = std::max(nextId_, c.id + 1);
    ++structureVersion_;
    ++version_;
}

void ConstraintSet::remove(int id) {
    const auto it = std::find_if(items_.begin(), items_.end(), [&](const Constraint& c) { return c.id == id; });
    if (it == items_.end()) throw std::invalid_argument("id: no constraint " + std::to_string(id));
    items_.erase(it);
    ++structureVersion_;
    ++version_;
}

void ConstraintSet::clear() {
    items_.clear();
    ++structureVersion_;
    ++version_;
}

Constraint& ConstraintSet::get(int id) {
    for (auto& c : items_)
        if (c.id == id) return c;
    throw std::invalid_argument("id: no constraint " + std::to_string(id));
}

void ConstraintSet::setStiffness(int id, double k) {
    if (!(k > 0) || !std::isfinite(k)) throw std::invalid_argument("stiffness: must be finite and > 0");
    get(id).stiffness = k;
    ++structureVersion_;
    ++version_;
}

void ConstraintSet::setTarget(int id, const Vec3& target) {
    if (!target.allFinite()) throw std::invalid_argument("target: must be finite");
    Constraint& c = get(id);
    if (c.kind == ConstraintKind::Curvature) throw std::invalid_argument("target: use curvature targets for a curvature constraint");
    ++version_;
    if (c.kind == ConstraintKind::Point) { c.target = target; return; }
    if (!(target.norm() > 0)) throw std::invalid_argument("target: normal must be non-zero");
    const Vec3 n = target.normalized();
    const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(c.target, n);
    for (auto& o : c.offsets) o = turn * o;
    c.target = n;
}

void ConstraintSet::setCurvature(int id, double ku, double kv) {
    if (!std::isfinite(ku) || !std::isfinite(kv)) throw std::invalid_argument("curvature: targets must be finite");
    Constraint& c = get(id);
    if (c.kind != ConstraintKind::Curvature) throw std::invalid_argument("id: not a curvature constraint");
    ++version_;
    c.curvatureU = std::abs(ku);
    c.curvatureV = std::abs(kv);
}

void ConstraintSet::terms(const Points& d, std::vector<ConstraintTerm>& out) const {
    out.clear();
    for (const Constraint& c : items_) {
        const int p = c.point;
        const Vec3 x = d.row(p);
        switch (c.kind) {
            case ConstraintKind::Point:
                out.push_back({p, -1, effectiveStiffness(c), c.target});
                break;
            case ConstraintKind::Tangent: {
                const int nb[4] = {p + h_, p - h_, p + 1, p - 1};
                for (int k = 0; k < 4; ++k) out.push_back({nb[k], p, effectiveStiffness(c), c.offsets[k]});
                break;
            }
            case ConstraintKind::Normal: {
                // Paper 4.4, alternate method, as a projection: each neighbour edge e_k = x_k - x_p is
                // moved to its nearest point in the plane normal to the target, e_k - (e_k . n) n, so
                // the energy is 1/2 k sum (e_k . n)^2 and these forces are its exact gradient.
                // Pairing each neighbour with the centre keeps the net force zero; rotation about n
                // and the edges' lengths stay free (the mesh springs hold those). A true nearest-
                // point projection onto a fixed (convex) set keeps local/global a descent method at
                // any penalty stiffness.
                const int nb[4] = {p + h_, p - h_, p + 1, p - 1};
                for (int k = 0; k < 4; ++k) {
                    const Vec3 e = Vec3(d.row(nb[k])) - x;
                    out.push_back({nb[k], p, effectiveStiffness(c), e - e.dot(c.target) * c.target});
                }
                break;
            }
            case ConstraintKind::Curvature: {
                // The three points around p along u (and along v) are projected onto the nearest
                // circle arc of the target curvature that keeps their mean half-chord s and the
                // side they bend to: the outer chord is the exact chord curvatureChord(k, s, s) and
                // p sits at the arc's sagitta. Neighbour-to-centre targets make it rotation and
                // translation free (zero net force), and give p the transverse pull a chord spring
                // alone cannot (from a flat start, a chord spring only compresses the row).
                const int step[2] = {h_, 1};
                const double kappa[2] = {c.curvatureU, c.curvatureV};
                for (int k = 0; k < 2; ++k) {
                    const int a = p + step[k], b = p - step[k];
                    const Vec3 xa = d.row(a), xb = d.row(b);
                    const Vec3 span = xa - xb;
                    const double l = span.norm();
                    if (!(l > 0)) continue;
                    const Vec3 e = span / l;
                    Vec3 w = x - 0.5 * (xa + xb);
                    w -= w.dot(e) * e;
                    if (!(w.norm() > 1e-9 * l)) {  // flat: bend toward the surface normal
                        w = meshNormal(d, p);
                        w -= w.dot(e) * e;
                    }
                    if (!(w.norm() > 0)) continue;
                    w.normalize();
                    const double half = 0.5 * ((xa - x).norm() + (x - xb).norm());
                    const double halfChord = 0.5 * curvatureChord(kappa[k], half, half);
                    const double sagitta = std::sqrt(std::max(0.0, half * half - halfChord * halfChord));
                    out.push_back({a, p, effectiveStiffness(c), halfChord * e - sagitta * w});
                    out.push_back({b, p, effectiveStiffness(c), -halfChord * e - sagitta * w});
                }
                break;
            }
        }
    }
}

double ConstraintSet::addForces(const Points& d, Points& f, std::vector<ConstraintTerm>& scratch) const {
    terms(d, scratch);
    double energy = 0;
    for (const auto& t : scratch) {
        const Vec3 xb = t.b >= 0 ? Vec3(d.row(t.b)) : Vec3::Zero();
        const Vec3 r = Vec3(d.row(t.a)) - xb - t.t;
        f.row(t.a) -= t.k * r.transpose();
        if (t.b >= 0) f.row(t.b) += t.k * r.transpose();
        energy += 0.5 * t.k * r.squaredNorm();
    }
    return energy;
}

void ConstraintSet::addProjections(const Points& d, Points& out, std::vector<ConstraintTerm>& scratch, double scale) const {
    terms(d, scratch);
    for (const auto& t : scratch) {
        const Vec3 current = t.b >= 0 ? Vec3(d.row(t.a) - d.row(t.b)) : Vec3(d.row(t.a));
        const Vec3 pull = (scale * t.k) * (t.t - current);
        out.row(t.a) += pull.transpose();
        if (t.b >= 0) out.row(t.b) -= pull.transpose();
    }
}

void ConstraintSet::addLaplacian(std::vector<Eigen::Triplet<double>>& trip) const {
    for (const Constraint& c : items_) {
        const int p = c.point;
        auto pair = [&](int a, int b) {
            trip.emplace_back(a, a, effectiveStiffness(c));
            trip.emplace_back(b, b, effectiveStiffness(c));
            trip.emplace_back(a, b, -effectiveStiffness(c));
            trip.emplace_back(b, a, -effectiveStiffness(c));
        };
        switch (c.kind) {
            case ConstraintKind::Point: trip.emplace_back(p, p, effectiveStiffness(c)); break;
            case ConstraintKind::Tangent:  // (all three tie the point to its four neighbours)
            case ConstraintKind::Normal:
            case ConstraintKind::Curvature:
                pair(p + h_, p); pair(p - h_, p); pair(p + 1, p); pair(p - 1, p);
                break;
        }
    }
}

void ConstraintSet::addStiffness(const Points& y, Points& out) const {
    for (const Constraint& c : items_) {
        const int p = c.point;
        auto pair = [&](int a, int b) {
            const Vec3 r = effectiveStiffness(c) * Vec3(y.row(a) - y.row(b));
            out.row(a) += r.transpose();
            out.row(b) -= r.transpose();
        };
        switch (c.kind) {
            case ConstraintKind::Point: out.row(p) += effectiveStiffness(c) * y.row(p); break;
            case ConstraintKind::Tangent:  // (all three tie the point to its four neighbours)
            case ConstraintKind::Normal:
            case ConstraintKind::Curvature:
                pair(p + h_, p); pair(p - h_, p); pair(p + 1, p); pair(p - 1, p);
                break;
        }
    }
}

void ConstraintSet::setBendingRatio(const Eigen::VectorXd& ratio) {
    curvatureScale_.resize(static_cast<std::size_t>(ratio.size()));
    bool changed = false;
    for (Eigen::Index i = 0; i < ratio.size(); ++i) {
        const double scale = std::min(1.0 + kCurvatureBendingGain * ratio[i], kMaxCurvatureScale);
        changed = changed || scale != curvatureScale_[static_cast<std::size_t>(i)];
        curvatureScale_[static_cast<std::size_t>(i)] = scale;
    }
    if (changed && anyNonConvex()) {
        ++structureVersion_;
        ++version_;
    }
}

double ConstraintSet::error(const Constraint& c, const Points& d) const {
    const int p = c.point;
    switch (c.kind) {
        case ConstraintKind::Point: return (Vec3(d.row(p)) - c.target).norm();
        case ConstraintKind::Tangent:
        case ConstraintKind::Normal:
            return std::acos(std::clamp(meshNormal(d, p).dot(c.target), -1.0, 1.0));
        case ConstraintKind::Curvature: {
            auto rel = [](double actual, double want) {
                // relative where a curvature is wanted, absolute (1/length) for a flat target
                return want > 1e-9 ? std::abs(actual - want) / want : std::abs(actual - want);
            };
            return std::max(rel(meshCurvature(d, p, 0), c.curvatureU), rel(meshCurvature(d, p, 1), c.curvatureV));
        }
    }
    return 0;
}

}  // namespace hs
