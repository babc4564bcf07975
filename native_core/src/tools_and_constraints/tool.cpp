#include "tools_and_constraints/tool.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/names.hpp"

namespace hs {

int ToolInfo::parameterCount() const {
    int n = 0;
    while (n < kMaxParameters && parameters[n].name) ++n;
    return n;
}

int ToolInfo::readoutCount() const {
    int n = 0;
    while (n < kMaxReadouts && readouts[n].name) ++n;
    return n;
}

Tool::Tool(const ToolInfo& info) : info_(info) {
    for (int i = 0; i < info.parameterCount(); ++i) parameters_[i] = info.parameters[i].value;
}

void Tool::setParameter(int i, double value) {
    if (i < 0 || i >= info_.parameterCount()) throw std::invalid_argument(std::string(info_.name) + ": no parameter " + std::to_string(i));
    const ParameterInfo& p = info_.parameters[i];
    parameters_[i] = requirePositive(value, p.name, p.allowZero);
}

double Tool::get(const std::string& name) const {
    for (int i = 0; i < info_.parameterCount(); ++i)
        if (name == info_.parameters[i].name) return parameters_[i];
    if (name == kToolLimitParameters[0].name) return limits.maxForce;
    if (name == kToolLimitParameters[1].name) return limits.rampTime;
    throw std::invalid_argument(std::string(info_.name) + " tool has no parameter '" + name + "'");
}

void Tool::set(const std::string& name, double value) {
    for (int i = 0; i < info_.parameterCount(); ++i)
        if (name == info_.parameters[i].name) return setParameter(i, value);
    if (name == kToolLimitParameters[0].name) {
        limits.maxForce = requirePositive(value, kToolLimitParameters[0].name, kToolLimitParameters[0].allowZero);
        return;
    }
    if (name == kToolLimitParameters[1].name) {
        limits.rampTime = requirePositive(value, kToolLimitParameters[1].name, kToolLimitParameters[1].allowZero);
        return;
    }
    throw std::invalid_argument(std::string(info_.name) + " tool has no parameter '" + name + "'");
}

double Tool::read(const std::string& name) const {
    for (int i = 0; i < info_.readoutCount(); ++i)
        if (name == info_.readouts[i].name) return readout(i);
    throw std::invalid_argument(std::string(info_.name) + " tool has no readout '" + name + "'");
}

void Tool::setFalloff(Falloff f) {
    if (!info_.falloff) throw std::invalid_argument(std::string("falloff: the ") + info_.name + " tool has none");
    falloff_ = f;
}

// Settings only: the grab (points, offsets, clock) stays with the tool being held.
void Tool::copySettings(const Tool& other) {
    if (&other.info_ != &info_) throw std::invalid_argument("copySettings: tools of different kinds");
    limits = other.limits;
    parameters_ = other.parameters_;
    falloff_ = other.falloff_;
}

void Tool::reserve(size_t n) {
    index_.reserve(n);
    force_.reserve(n);
}

GridRect boundingRect(const std::vector<int>& points, int h) {
    if (points.empty()) return {0, 0, 0, 0, h};
    GridRect r{points[0] / h, points[0] / h + 1, points[0] % h, points[0] % h + 1, h};
    for (int p : points) {
        r.r0 = std::min(r.r0, p / h); r.r1 = std::max(r.r1, p / h + 1);
        r.c0 = std::min(r.c0, p % h); r.c1 = std::max(r.c1, p % h + 1);
    }
    return r;
}

int nearestPoint(const Points& d, const Vec3& x) {
    Eigen::Index best = 0;
    (d.rowwise() - x.transpose()).rowwise().squaredNorm().minCoeff(&best);
    return static_cast<int>(best);
}

void selectWithin(const MeshView& mesh, const Vec3& centre, const Vec3& axis, double radius, Falloff falloff,
                  std::vector<int>& points, std::vector<double>& weights) {
    points.clear();
    weights.clear();
    for (Eigen::Index i = 0; i < mesh.d.rows(); ++i) {
        const Vec3 rel = mesh.d.row(i).transpose() - centre;
        const double dist = falloff == Falloff::Cylindrical ? (rel - rel.dot(axis) * axis).norm() : rel.norm();
        const double w = falloffWeight(falloff, dist / radius);
        if (w > 0) {
            points.push_back(static_cast<int>(i));
            weights.push_back(w);
        }
    }
}

void Tool::emit(int index, const Vec3& force) {
    index_.push_back(index);
    force_.push_back(force);
}

Reaction Tool::apply(const MeshView& mesh, const Cursor& cursor, double dt, Points& f, double phase) {
    Reaction r;
    if (!grabbed_) return r;
    forceTime_ = time_ + phase * dt;
    time_ += dt;
    index_.clear();
    force_.clear();
    computeForces(mesh, cursor);
    Vec3 total = Vec3::Zero();
    for (const Vec3& fi : force_) total += fi;
    // Ramp in after the grab, then clamp the total; one scale for all points keeps the reaction exact.
    double scale = limits.rampTime > 0 ? std::min(1.0, forceTime_ / limits.rampTime) : 1.0;
    const double mag = total.norm() * scale;
    if (mag > gain_ * limits.maxForce) scale *= gain_ * limits.maxForce / mag;
    appliedScale_ = scale;
    for (size_t i = 0; i < index_.size(); ++i) {
        const Vec3 fi = scale * force_[i];
        f.row(index_[i]) += fi.transpose();
        r.force -= fi;
        r.torque -= (mesh.d.row(index_[i]).transpose() - cursor.position).cross(fi);
    }
    return r;
}

void Tool::describe(const MeshView& mesh, const Reaction& last, HapticEstimate& e) const {
    e.toolTime = time_;
    e.maxForce = gain_ * limits.maxForce;
    e.rampTime = limits.rampTime;
    e.points = 0;
    e.heldForce = last.force;
    e.slope = 0;
    if (!grabbed_) {
        e.kind = EstimateKind::None;
        return;
    }
    if (!describeLaw(mesh, e)) e.kind = EstimateKind::Hold;
}

}  // namespace hs
