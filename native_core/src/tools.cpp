#include "tools.hpp"

#include "material_map.hpp"
#include "names.hpp"

#include <cmath>
#include <stdexcept>

namespace hs {

int nearestPoint(const Points& d, const Vec3& x) {
    Eigen::Index best = 0;
    (d.rowwise() - x.transpose()).rowwise().squaredNorm().minCoeff(&best);
    return static_cast<int>(best);
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

bool RopeTool::describeLaw(const MeshView& mesh, HapticEstimate& e) const {
    e.kind = EstimateKind::Rope;
    e.points = 1;
    e.x[0] = mesh.d.row(point_).transpose();
    e.stiffness = gain_ * stiffness;
    e.stiffStiffness = gain_ * stiffStiffness;
    e.threshold = threshold;
    e.length0 = length0_;
    e.reelTime = reelTime;
    e.slope = slope();
    return true;
}

bool MagnetTool::describeLaw(const MeshView& mesh, HapticEstimate& e) const {
    e.kind = EstimateKind::Magnet;
    e.stiffness = stiffness;
    e.weightSum = 0;
    e.offsetSum.setZero();
    for (size_t k = 0; k < points_.size(); ++k) {
        e.weightSum += weights_[k];
        e.offsetSum += weights_[k] * (offsets_[k] - mesh.d.row(points_[k]).transpose());
    }
    e.slope = stiffness * e.weightSum;
    return true;
}

bool OrientationTool::describeLaw(const MeshView& mesh, HapticEstimate& e) const {
    e.kind = EstimateKind::Orientation;
    e.stiffness = stiffness;
    const int i = center_ / mesh.h, j = center_ % mesh.h;
    const int di[5] = {0, 1, -1, 0, 0}, dj[5] = {0, 0, 0, 1, -1}, axis[5] = {0, 1, 1, 2, 2};
    const double spacing[5] = {0, mesh.spacingU, -mesh.spacingU, mesh.spacingV, -mesh.spacingV};
    e.points = 0;
    for (int k = 0; k < 5; ++k) {
        const int ii = i + di[k], jj = j + dj[k];
        if (ii < 0 || jj < 0 || ii >= mesh.g || jj >= mesh.h) continue;
        e.x[e.points] = mesh.d.row(ii * mesh.h + jj).transpose();
        e.axis[e.points] = axis[k];
        e.spacing[e.points] = spacing[k];
        ++e.points;
    }
    e.slope = stiffness * e.points;
    return true;
}

void RopeTool::grab(const MeshView& mesh, const Cursor& cursor) {
    point_ = nearestPoint(mesh.d, cursor.position);
    length0_ = (mesh.d.row(point_).transpose() - cursor.position).norm();
    const double u = mesh.g > 1 ? double(point_ / mesh.h) / (mesh.g - 1) : 0.0;
    const double v = mesh.h > 1 ? double(point_ % mesh.h) / (mesh.h - 1) : 0.0;
    gain_ = 1.0 + (mesh.bending ? kRopePlateGain * mesh.bending->at(u, v) : 0.0);
    time_ = 0;
    grabbed_ = true;
}

double RopeTool::restLengthAt(double t) const {
    return reelTime > 0 ? length0_ * std::max(0.0, 1.0 - t / reelTime) : 0.0;
}

void RopeTool::computeForces(const MeshView& mesh, const Cursor& cursor) {
    const Vec3 x = mesh.d.row(point_).transpose();
    const Vec3 toCursor = cursor.position - x;
    const double dist = toCursor.norm();
    const double ext = dist - restLengthAt(forceTime_);
    slopeNow_ = 0;
    if (ext <= 0 || !(dist > 0)) return;  // a slack rope transmits nothing: it cannot push
    slopeNow_ = gain_ * (ext < threshold ? stiffness : stiffStiffness);
    const double tension =
        gain_ * (stiffness * std::min(ext, threshold) + stiffStiffness * std::max(0.0, ext - threshold));
    emit(point_, tension / dist * toCursor);
}

void MagnetTool::grab(const MeshView& mesh, const Cursor& cursor) {
    points_.clear();
    weights_.clear();
    offsets_.clear();
    const Vec3 axis = cursor.orientation * Vec3::UnitZ();
    for (Eigen::Index i = 0; i < mesh.d.rows(); ++i) {
        const Vec3 rel = mesh.d.row(i).transpose() - cursor.position;
        const double dist = falloff == Falloff::Cylindrical ? (rel - rel.dot(axis) * axis).norm() : rel.norm();
        const double w = falloffWeight(falloff, dist / radius);
        if (w > 0) {
            points_.push_back(static_cast<int>(i));
            weights_.push_back(w);
            offsets_.push_back(rel);
        }
    }
    time_ = 0;
    grabbed_ = !points_.empty();
}

void MagnetTool::computeForces(const MeshView& mesh, const Cursor& cursor) {
    for (size_t k = 0; k < points_.size(); ++k) {
        const Vec3 target = cursor.position + offsets_[k];
        emit(points_[k], stiffness * weights_[k] * (target - mesh.d.row(points_[k]).transpose()));
    }
}

void OrientationTool::grab(const MeshView& mesh, const Cursor& cursor) {
    center_ = nearestPoint(mesh.d, cursor.position);
    time_ = 0;
    grabbed_ = true;
}

void OrientationTool::computeForces(const MeshView& mesh, const Cursor& cursor) {
    const int i = center_ / mesh.h, j = center_ % mesh.h;
    const Vec3 ax = cursor.orientation * Vec3::UnitX(), ay = cursor.orientation * Vec3::UnitY();
    auto spring = [&](int ii, int jj, const Vec3& target) {
        if (ii < 0 || jj < 0 || ii >= mesh.g || jj >= mesh.h) return;
        const int idx = ii * mesh.h + jj;
        emit(idx, stiffness * (target - mesh.d.row(idx).transpose()));
    };
    const Vec3& c = cursor.position;
    spring(i, j, c);
    spring(i + 1, j, c + mesh.spacingU * ax);
    spring(i - 1, j, c - mesh.spacingU * ax);
    spring(i, j + 1, c + mesh.spacingV * ay);
    spring(i, j - 1, c - mesh.spacingV * ay);
}

void SmoothTool::grab(const MeshView& mesh, const Cursor&) {
    u1_.resize(mesh.d.rows(), 3);
    u2_.resize(mesh.d.rows(), 3);
    u3_.resize(mesh.d.rows(), 3);
    time_ = 0;
    grabbed_ = true;
}

namespace {
// Umbrella operator: mean of the 4-neighbours minus the point.
void umbrella(const Points& x, int g, int h, Points& out) {
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < h; ++j) {
            Vec3 s = Vec3::Zero();
            int n = 0;
            if (i > 0) { s += x.row((i - 1) * h + j).transpose(); ++n; }
            if (i + 1 < g) { s += x.row((i + 1) * h + j).transpose(); ++n; }
            if (j > 0) { s += x.row(i * h + j - 1).transpose(); ++n; }
            if (j + 1 < h) { s += x.row(i * h + j + 1).transpose(); ++n; }
            out.row(i * h + j) = (s / n).transpose() - x.row(i * h + j);
        }
}
}  // namespace

void SmoothTool::computeForces(const MeshView& mesh, const Cursor& cursor) {
    umbrella(mesh.d, mesh.g, mesh.h, u1_);
    umbrella(u1_, mesh.g, mesh.h, u2_);
    umbrella(u2_, mesh.g, mesh.h, u3_);
    for (Eigen::Index i = 0; i < mesh.d.rows(); ++i) {
        const double w = falloffWeight(falloff, (mesh.d.row(i).transpose() - cursor.position).norm() / radius);
        if (w > 0) emit(static_cast<int>(i), strength * w * u3_.row(i).transpose());
    }
}

// Settings only: the grab (point, offsets, clock) stays with the tool being held.
void RopeTool::copySettings(const Tool& other) {
    Tool::copySettings(other);
    const auto& o = dynamic_cast<const RopeTool&>(other);
    stiffness = o.stiffness;
    stiffStiffness = o.stiffStiffness;
    threshold = o.threshold;
    reelTime = o.reelTime;
}

void MagnetTool::copySettings(const Tool& other) {
    Tool::copySettings(other);
    const auto& o = dynamic_cast<const MagnetTool&>(other);
    radius = o.radius;
    stiffness = o.stiffness;
    falloff = o.falloff;
}

void OrientationTool::copySettings(const Tool& other) {
    Tool::copySettings(other);
    stiffness = dynamic_cast<const OrientationTool&>(other).stiffness;
}

void SmoothTool::copySettings(const Tool& other) {
    Tool::copySettings(other);
    const auto& o = dynamic_cast<const SmoothTool&>(other);
    radius = o.radius;
    strength = o.strength;
    falloff = o.falloff;
}

std::unique_ptr<Tool> makeTool(const std::string& name) {
    if (name == "rope") return std::make_unique<RopeTool>();
    if (name == "magnet") return std::make_unique<MagnetTool>();
    if (name == "orientation") return std::make_unique<OrientationTool>();
    if (name == "smooth") return std::make_unique<SmoothTool>();
    throw std::invalid_argument("tool: unknown tool '" + name + "' (" + listNames(kToolNames) + ")");
}

}  // namespace hs
