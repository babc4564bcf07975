// Local/global's explicit branch: velocity Verlet in control space, taken instead of the implicit
// step wherever it is provably stable (stiffness switching, as LSODA switches between its non-stiff
// and stiff methods). Below its stability limit an explicit step is the better buy: one force
// evaluation and one solve by the prefactored mass matrix, second order, and no numerical damping,
// where BDF2 damps and dephases the mesh modes it cannot resolve (bench/time_vs_error.py: converged
// BDF2 on the free oscillation at 125 us is 6x less accurate than the explicit scheme at the same
// step).
//   v+ = v_n + h/2 a_n,  x_n+1 = x_n + h v+,  v_n+1 = v+ + h/2 a_n+1
// with a = (A^T M A)^-1 A^T f. The internal forces (springs, constraints, damping) are evaluated once
// per step and carried to the next (first same as last); damping is taken at the second-order
// estimate 2 v+ - v_n of v_n+1. The applied forces (tool, external) are held over the step, taken
// at the mesh predicted half a step ahead (midpoint rule, second order), so a cursor that moves
// between steps is seen at once.
#include <algorithm>
#include <cmath>
#include <limits>

#include "solvers/dynamic_surface.hpp"

namespace hs {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

double DynamicSurface::verletForces(const Points& d, const Points& dd) {
    force_.setZero();
    double energy = springs_.addProjections(d, force_, 0.0, 1.0, true);  // the spring forces, for a linear law
    energy += bending_.addForces(d, force_);
    if (!constraints_.empty()) energy += constraints_.addForces(d, force_, terms_);
    if (maxDampingRate_ > 0) force_ -= gamma_.asDiagonal() * dd;
    return energy;
}

double DynamicSurface::verletToolTerm() const {
    if (!solver_.explicitWhenStable) return kInf;
    // Non-linear laws stiffen without bound; curvature constraints project onto arcs (not convex).
    if (springs_.law.kind != LawKind::Linear || dampingLaw_.kind != LawKind::Linear || constraints_.anyNonConvex())
        return kInf;
    // The tool adds at most slope on each point it holds: omega^2 grows by at most slope / m_min.
    return tool_->grabbed() ? toolSlope() / minMass_ : 0.0;
}

bool DynamicSurface::verletStable(double dt) {
    // Damping is explicit too (rate gamma / m, A^T D A <= rate A^T M A): stable up to rate dt = 0.1
    // together with omega dt = 1.8 (the scalar recurrence's spectral radius is then 0.84).
    if (dt * maxDampingRate_ > 0.1) return false;
    const double tool = verletToolTerm();
    if (!std::isfinite(tool)) return false;
    const double limit = kVerletStability * kVerletStability / (dt * dt);
    return omegaSquaredBelow(limit - tool);
}

double DynamicSurface::verletStepLimit() {
    refreshMaterials();
    const double tool = verletToolTerm();
    if (!std::isfinite(tool)) return 0.0;
    omegaSquaredBelow(kInf, true);
    double dt = kVerletStability / std::sqrt(omega_.upper + tool);
    if (maxDampingRate_ > 0) dt = std::min(dt, 0.1 / maxDampingRate_);
    return dt;
}

void DynamicSurface::solveApplied() {
    const CsrMatrix& a = A_.matrix();
    fp_.setZero();
    verlet_.appliedPoles.clear();
    for (Eigen::Index r = 0; r < d_.rows(); ++r) {
        Vec3 f = Vec3::Zero();
        if (hasExternal_) f += fext_.row(r).transpose();
        if (toolForces_) f += ftool_.row(r).transpose();
        if (f.isZero(0.0)) continue;
        for (int e = a.rowStart[static_cast<size_t>(r)]; e < a.rowStart[static_cast<size_t>(r) + 1]; ++e) {
            const int c = a.col[static_cast<size_t>(e)];
            if (!verlet_.poleMark[static_cast<size_t>(c)]) {
                verlet_.poleMark[static_cast<size_t>(c)] = 1;
                verlet_.appliedPoles.push_back(c);
            }
            fp_.row(c) += a.value[static_cast<size_t>(e)] * f.transpose();
        }
    }
    held_.addMasters(verlet_.appliedPoles, verlet_.poleMark);  // (a linked pole's force goes to its masters)
    for (int c : verlet_.appliedPoles) verlet_.poleMark[static_cast<size_t>(c)] = 0;
    held_.reduce(fp_);
    massSolver_.solveSparse(fp_, verlet_.appliedPoles, acc_);
    held_.expand(acc_);
}

StepReport DynamicSurface::stepVerlet(double dt) {
    StepReport r;
    r.verlet = true;
    r.substeps = 1;
    ensureMassFactor();
    const double h = dt;
    if (!avValid_) A_.apply(v_, av_);
    if (!verlet_.valid) {
        verletForces(d_, av_);
        A_.applyTransposed(force_, fp_);
        held_.reduce(fp_);
        massSolver_.solve(fp_, verlet_.a);
        held_.expand(verlet_.a);
    }
    if (tool_->grabbed()) {
        meshTmp_ = d_ + (0.5 * h) * av_;
        applyToolForces(dt, r, meshTmp_, 0.5);
    } else {
        applyToolForces(dt, r, d_);
    }
    const bool applied = hasExternal_ || toolForces_;
    if (applied) {  // their acceleration, held over the step, into acc_
        solveApplied();
        v_ += (0.5 * h) * acc_;
    }
    v_ += (0.5 * h) * verlet_.a;
    surface_.mutablePoles() += h * v_;
    A_.apply(surface_.poles(), d_);
    // The mesh velocity at the step's end, to second order, for the damping: 2 v+ - v_n.
    meshTmp_ = (2.0 / h) * (d_ - dPrev_) - av_;
    verlet_.stepPotential = verletForces(d_, meshTmp_);
    A_.applyTransposed(force_, fp_);
    held_.reduce(fp_);
    massSolver_.solve(fp_, verlet_.a);
    held_.expand(verlet_.a);
    v_ += (0.5 * h) * verlet_.a;
    if (applied) v_ += (0.5 * h) * acc_;
    A_.apply(v_, av_);
    avValid_ = verlet_.valid = true;
    history_.valid = accelerationValid_ = false;
    return r;
}

}  // namespace hs
