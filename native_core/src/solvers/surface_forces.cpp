#include "solvers/surface_forces.hpp"

#include <stdexcept>

namespace hs {

SurfaceForces::SurfaceForces(int g, int h) : pull_(g, h), constraints_(g, h) {
    const Eigen::Index S = static_cast<Eigen::Index>(g) * h;
    for (Points* m : {&pointForces_, &external_, &fromTool_, &total_}) m->setZero(S, 3);
    dampingFactor_.setZero(S);
    terms_.reserve(64);
    setTool("rope");
}

void SurfaceForces::setPointForce(int index, const Vec3& force, const MirrorSymmetry& mirror) {
    if (index < 0 || index >= external_.rows()) throw std::invalid_argument("index: mesh index out of range");
    if (!force.allFinite()) throw std::invalid_argument("force: must be finite");
    const double n = force.norm();
    const Vec3 f = n > maxPointForce ? Vec3(force * (maxPointForce / n)) : force;
    for (Points* to : {&pointForces_, &external_}) {  // (the pull adds its part at the next step)
        if (mirror.empty()) to->row(index) = f.transpose();
        else mirror.pointForce(*to, index, f);
    }
    hasPointForces_ = true;
}

void SurfaceForces::clearExternal() {
    pointForces_.setZero();
    external_.setZero();
    hasPointForces_ = false;
}

void SurfaceForces::applyPull(const Points& d, const Points& dd, double su, double sv, const Eigen::VectorXd& m, double dt) {
    if (!pull_.active()) {
        if (pullOn_) external_ = pointForces_;
        pullOn_ = false;
        return;
    }
    pull_.refresh(d, su, sv);
    pull_.forces(d, dd, m, dt, external_);
    if (hasPointForces_) external_ += pointForces_;
    pullOn_ = true;
}

double SurfaceForces::appliedWork(const Points& d, const Points& before, const GridRect& window) const {
    // (whole runs of rows, so the loop vectorises)
    double work = 0;
    window.forSpans([&](const auto& r) {
        if (hasExternal()) work += r(external_).cwiseProduct(r(d) - r(before)).sum();
        if (toolActive_) work += r(fromTool_).cwiseProduct(r(d) - r(before)).sum();
    });
    return work;
}

void SurfaceForces::setTool(const std::string& name) {
    auto t = makeTool(name);
    t->reserve(static_cast<size_t>(total_.rows()));
    tool_ = std::move(t);
    fromTool_.setZero();
    toolActive_ = false;
}

bool SurfaceForces::applyTool(const Points& at, int g, int h, double su, double sv, const MirrorSymmetry& mirror,
                              double dt, Reaction& reaction, double phase) {
    if (tool_->grabbed()) {
        // (only the rows it pushed last: a whole-mesh fill would cost a regional step its gain)
        if (mirror.empty()) for (int i : tool_->pushed()) fromTool_.row(i).setZero();
        else fromTool_.setZero();
        reaction = tool_->apply({at, g, h, su, sv}, cursor, dt, fromTool_, phase);
        if (!mirror.empty()) mirror.addMirrored(fromTool_);
        toolActive_ = true;
        return true;
    }
    if (!toolActive_) return false;
    fromTool_.setZero();
    toolActive_ = false;
    return true;
}

double SurfaceForces::all(Material& material, const Points& d, const Points& dd) {
    total_.setZero();
    const double energy = material.springs.addForces(d, total_);
    const ResponseLaw& law = material.dampingLaw;
    const bool nonlinearDamping = law.kind != LawKind::Linear;
    if (nonlinearDamping)
        for (Eigen::Index i = 0; i < d.rows(); ++i) dampingFactor_[i] = law.dampingFactor(total_.row(i).norm());
    const double bend = material.bending.addForces(d, total_);  // (after the damping law: it reads spring forces)
    if (hasExternal()) total_ += external_;
    if (toolActive_) total_ += fromTool_;
    double penalty = 0;
    if (!constraints_.empty()) penalty = constraints_.addForces(d, total_, terms_);
    const Eigen::VectorXd& gamma = material.damping();
    if (nonlinearDamping)
        for (Eigen::Index i = 0; i < d.rows(); ++i) total_.row(i) -= gamma[i] * dampingFactor_[i] * dd.row(i);
    else
        total_ -= gamma.asDiagonal() * dd;
    return energy + bend + penalty;
}

double SurfaceForces::internalLinear(Material& material, const Points& d, const Points& dd) {
    total_.setZero();
    double energy = material.springs.addProjections(d, total_, 0.0, 1.0, true);  // the spring forces, for a linear law
    energy += material.bending.addForces(d, total_);
    if (!constraints_.empty()) energy += constraints_.addForces(d, total_, terms_);
    if (material.maxDampingRate() > 0) total_ -= material.damping().asDiagonal() * dd;
    return energy;
}

double SurfaceForces::potential(Material& material, const Points& d) {
    total_.setZero();
    double e = material.springs.addForces(d, total_);
    e += material.bending.addForces(d, total_);
    if (!constraints_.empty()) e += constraints_.addForces(d, total_, terms_);
    return e;
}

double SurfaceForces::potentialEnergy(const Material& material, const Points& d) {
    double e = material.springs.energy(d) + material.bending.energy(d);
    if (!constraints_.empty()) {
        total_.setZero();
        e += constraints_.addForces(d, total_, terms_);
    }
    return e;
}

}  // namespace hs
