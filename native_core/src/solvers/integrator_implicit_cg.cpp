// Linearised backward Euler (Baraff & Witkin 1998) in control-point space, solved matrix-free with
// a fixed number of Jacobi-preconditioned conjugate-gradient iterations (the paper's Table 1 scheme):
//   (Mp + dt Dp + dt^2 Kp) dv = dt A^T f - dt^2 Kp v,   Kp = A^T K(d) A.
#include <cmath>

#include "solvers/dynamic_surface.hpp"

namespace hs {

StepReport DynamicSurface::stepImplicitCG(double dt) {
    StepReport r;
    ensureSystem(dt, false);
    applyToolForces(dt, r, d_);
    A_.apply(v_, dd_);
    meshForces(d_, dd_, dt);  // also records the springs' tangent stiffness at d
    auto stiffnessTimes = [&](const Points& y, Points& out) {
        out.setZero();
        springs_.addTangentStiffness(y, out);
        bending_.addStiffness(y, out);
        if (!constraints_.empty()) constraints_.addStiffness(y, out);
    };
    stiffnessTimes(dd_, meshTmp2_);
    meshTmp_ = dt * force_ - dt * dt * meshTmp2_;
    A_.applyTransposed(meshTmp_, cg_.r);
    held_.reduce(cg_.r);  // (and q below: CG stays in the free poles' subspace, P = T z)
    const double bnorm = std::sqrt(cg_.r.squaredNorm());
    x_.setZero();
    double rnorm = bnorm;
    if (bnorm > 0) {
        cg_.z = systems_[system_].invDiag.asDiagonal() * cg_.r;
        cg_.p = cg_.z;
        double rz = cg_.r.cwiseProduct(cg_.z).sum();
        for (int it = 0; it < solver_.cgIterations; ++it) {
            // q = (Mp + dt Dp + dt^2 Kp) p, applied through the mesh.
            if (held_.links().empty()) {
                A_.apply(cg_.p, meshTmp_);
            } else {  // T p: the linked poles follow (z is free until the next preconditioning)
                cg_.z = cg_.p;
                held_.expand(cg_.z);
                A_.apply(cg_.z, meshTmp_);
            }
            stiffnessTimes(meshTmp_, meshTmp2_);
            meshTmp2_ = (m_ + dt * gamma_).asDiagonal() * meshTmp_ + dt * dt * meshTmp2_;
            A_.applyTransposed(meshTmp2_, cg_.q);
            held_.reduce(cg_.q);
            const double pq = cg_.p.cwiseProduct(cg_.q).sum();
            ++r.iterations;
            if (!(pq > 0)) break;
            const double alpha = rz / pq;
            x_ += alpha * cg_.p;
            cg_.r -= alpha * cg_.q;
            rnorm = std::sqrt(cg_.r.squaredNorm());
            if (rnorm <= 1e-14 * bnorm) break;
            cg_.z = systems_[system_].invDiag.asDiagonal() * cg_.r;
            const double rzNew = cg_.r.cwiseProduct(cg_.z).sum();
            cg_.p = cg_.z + (rzNew / rz) * cg_.p;
            rz = rzNew;
        }
    }
    r.residual = bnorm > 0 ? rnorm / bnorm : 0.0;
    held_.expand(x_);
    v_ += x_;
    Points& p = surface_.mutablePoles();
    p += dt * v_;
    A_.apply(p, d_);
    accelerationValid_ = false;
    return r;
}

}  // namespace hs
