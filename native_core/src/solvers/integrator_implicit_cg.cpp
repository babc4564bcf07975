// Linearised backward Euler (Baraff & Witkin 1998) in control-point space, solved matrix-free with
// a fixed number of Jacobi-preconditioned conjugate-gradient iterations (the paper's Table 1 scheme):
//   (Mp + dt Dp + dt^2 Kp) dv = dt A^T f - dt^2 Kp v,   Kp = A^T K(d) A.
#include "solvers/integrator_implicit_cg.hpp"

#include <cmath>

namespace hs {

ImplicitCgIntegrator::ImplicitCgIntegrator(Eigen::Index poles) {
    for (Points* m : {&r_, &z_, &p_, &q_, &dv_}) m->setZero(poles, 3);
}

StepReport ImplicitCgIntegrator::step(StepModel& m, double dt) {
    StepReport r;
    m.ensureSystem(dt, false);
    m.applyTool(dt, r, m.state.d);
    SurfaceState& s = m.state;
    Material& material = m.material;
    const HeldPoles& held = m.held;
    const ConstraintSet& constraints = m.forces.constraints();
    Points &dd = m.scratch.meshVelocity, &tmp = m.scratch.mesh, &tmp2 = m.scratch.mesh2;
    s.A.apply(s.v, dd);
    m.forces.all(material, s.d, dd);  // also records the springs' tangent stiffness at d
    auto stiffnessTimes = [&](const Points& y, Points& out) {
        out.setZero();
        material.springs.addTangentStiffness(y, out);
        material.bending.addStiffness(y, out);
        if (!constraints.empty()) constraints.addStiffness(y, out);
    };
    stiffnessTimes(dd, tmp2);
    tmp = dt * m.forces.total() - dt * dt * tmp2;
    s.A.applyTransposed(tmp, r_);
    held.reduce(r_);  // (and q below: CG stays in the free poles' subspace, P = T z)
    const double bnorm = std::sqrt(r_.squaredNorm());
    dv_.setZero();
    double rnorm = bnorm;
    const Eigen::VectorXd& invDiag = m.systems.current().invDiag;
    if (bnorm > 0) {
        z_ = invDiag.asDiagonal() * r_;
        p_ = z_;
        double rz = r_.cwiseProduct(z_).sum();
        for (int it = 0; it < m.settings.cgIterations; ++it) {
            // q = (Mp + dt Dp + dt^2 Kp) p, applied through the mesh.
            if (held.links().empty()) {
                s.A.apply(p_, tmp);
            } else {  // T p: the linked poles follow (z is free until the next preconditioning)
                z_ = p_;
                held.expand(z_);
                s.A.apply(z_, tmp);
            }
            stiffnessTimes(tmp, tmp2);
            tmp2 = (material.masses() + dt * material.damping()).asDiagonal() * tmp + dt * dt * tmp2;
            s.A.applyTransposed(tmp2, q_);
            held.reduce(q_);
            const double pq = p_.cwiseProduct(q_).sum();
            ++r.iterations;
            if (!(pq > 0)) break;
            const double alpha = rz / pq;
            dv_ += alpha * p_;
            r_ -= alpha * q_;
            rnorm = std::sqrt(r_.squaredNorm());
            if (rnorm <= 1e-14 * bnorm) break;
            z_ = invDiag.asDiagonal() * r_;
            const double rzNew = r_.cwiseProduct(z_).sum();
            p_ = z_ + (rzNew / rz) * p_;
            rz = rzNew;
        }
    }
    r.residual = bnorm > 0 ? rnorm / bnorm : 0.0;
    held.expand(dv_);
    s.v += dv_;
    s.mutablePoles() += dt * s.v;
    s.sampleMesh();
    return r;
}

}  // namespace hs
