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
#include "solvers/integrator_verlet.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hs {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

VerletIntegrator::VerletIntegrator(Eigen::Index poles) {
    a_.setZero(poles, 3);
    appliedPoles_.reserve(static_cast<size_t>(poles));
    poleMark_.assign(static_cast<size_t>(poles), 0);
}

double VerletIntegrator::toolTerm(const StepModel& m) const {
    if (!m.settings.explicitWhenStable) return kInf;
    // Non-linear laws stiffen without bound; curvature constraints project onto arcs (not convex).
    if (m.material.springs.law.kind != LawKind::Linear || m.material.dampingLaw.kind != LawKind::Linear ||
        m.forces.constraints().anyNonConvex())
        return kInf;
    // The tool adds at most slope on each point it holds: omega^2 grows by at most slope / m_min;
    // the pull toward a scan by its own omega^2 (its stiffness goes with the mass).
    return (m.forces.tool().grabbed() ? m.toolSlope() / m.material.minMass() : 0.0) + m.forces.pull().maxOmegaSq();
}

double VerletIntegrator::dampingRate(const StepModel& m) {
    // The material's, and the pull's critical damper (2 omega).
    return m.material.maxDampingRate() + 2.0 * std::sqrt(m.forces.pull().maxOmegaSq());
}

bool VerletIntegrator::stable(StepModel& m, double dt) {
    // Damping is explicit too (rate gamma / m, A^T D A <= rate A^T M A): stable up to rate dt = 0.1
    // together with omega dt = 1.8 (the scalar recurrence's spectral radius is then 0.84).
    if (dt * dampingRate(m) > 0.1) return false;
    const double tool = toolTerm(m);
    if (!std::isfinite(tool)) return false;
    const double limit = kVerletStability * kVerletStability / (dt * dt);
    return bound_.below(m, limit - tool);
}

double VerletIntegrator::stepLimit(StepModel& m) {
    const double tool = toolTerm(m);
    if (!std::isfinite(tool)) return 0.0;
    bound_.below(m, kInf, true);
    double dt = kVerletStability / std::sqrt(bound_.upper() + tool);
    if (dampingRate(m) > 0) dt = std::min(dt, 0.1 / dampingRate(m));
    return dt;
}

void VerletIntegrator::solveApplied(StepModel& m) {
    const CsrMatrix& a = m.state.A.matrix();
    const SurfaceForces& forces = m.forces;
    Points& fp = m.scratch.poleForce;
    fp.setZero();
    appliedPoles_.clear();
    for (Eigen::Index r = 0; r < m.state.d.rows(); ++r) {
        Vec3 f = Vec3::Zero();
        if (forces.hasExternal()) f += forces.external().row(r).transpose();
        if (forces.toolActive()) f += forces.fromTool().row(r).transpose();
        if (f.isZero(0.0)) continue;
        for (int e = a.rowStart[static_cast<size_t>(r)]; e < a.rowStart[static_cast<size_t>(r) + 1]; ++e) {
            const int c = a.col[static_cast<size_t>(e)];
            if (!poleMark_[static_cast<size_t>(c)]) {
                poleMark_[static_cast<size_t>(c)] = 1;
                appliedPoles_.push_back(c);
            }
            fp.row(c) += a.value[static_cast<size_t>(e)] * f.transpose();
        }
    }
    m.held.addMasters(appliedPoles_, poleMark_);  // (a linked pole's force goes to its masters)
    for (int c : appliedPoles_) poleMark_[static_cast<size_t>(c)] = 0;
    m.held.reduce(fp);
    m.systems.mass().solveSparse(fp, appliedPoles_, m.scratch.poleStep);
    m.held.expand(m.scratch.poleStep);
}

StepReport VerletIntegrator::step(StepModel& m, double dt) {
    StepReport r;
    r.verlet = true;
    r.substeps = 1;
    m.ensureMass();
    SurfaceState& s = m.state;
    Points &fp = m.scratch.poleForce, &applied = m.scratch.poleStep, &tmp = m.scratch.mesh;
    const PrefactoredSolver& mass = m.systems.mass();
    const double h = dt;
    if (!s.avValid) s.A.apply(s.v, s.av);
    if (!valid_) {
        m.forces.internalLinear(m.material, s.d, s.av);
        s.A.applyTransposed(m.forces.total(), fp);
        m.held.reduce(fp);
        mass.solve(fp, a_);
        m.held.expand(a_);
    }
    if (m.forces.tool().grabbed()) {
        tmp = s.d + (0.5 * h) * s.av;
        m.applyTool(dt, r, tmp, 0.5);
    } else {
        m.applyTool(dt, r, s.d);
    }
    const bool anyApplied = m.forces.anyApplied();
    if (anyApplied) {  // their acceleration, held over the step
        solveApplied(m);
        s.v += (0.5 * h) * applied;
    }
    s.v += (0.5 * h) * a_;
    s.mutablePoles() += h * s.v;
    s.sampleMesh();
    // The mesh velocity at the step's end, to second order, for the damping: 2 v+ - v_n.
    tmp = (2.0 / h) * (s.d - s.meshAtStart) - s.av;
    stepPotential_ = m.forces.internalLinear(m.material, s.d, tmp);
    s.A.applyTransposed(m.forces.total(), fp);
    m.held.reduce(fp);
    mass.solve(fp, a_);
    m.held.expand(a_);
    s.v += (0.5 * h) * a_;
    if (anyApplied) s.v += (0.5 * h) * applied;
    s.A.apply(s.v, s.av);
    s.avValid = valid_ = true;
    return r;
}

}  // namespace hs
