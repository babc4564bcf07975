// Implicit time stepping by local/global iterations (Liu et al. 2013, "Fast Simulation of Mass-
// Spring Systems") carried into the reduced control-point space. Springs and penalty constraints
// are all terms 1/2 k |x_a - x_b - t|^2, so one step solves
//   A^T (M + h D + h^2 L) A p' = A^T [ M y + h D x^ + h^2 (f_ext + J t) ]
// alternating the projection of t (local) with a solve by the prefactored system (global), in
// increments (see the loop). Where an explicit step is provably stable, step() takes the Verlet
// step of integrator_verlet.cpp instead.
// Backward Euler (order 1) has x^ = x_n, y = x_n + dt v_n, h = dt. BDF2 (order 2, the default;
// beyond the paper and Liu et al.) has the same form with
//   x^ = (4 x_n - x_n-1) / 3,  v^ = (4 v_n - v_n-1) / 3,  y = x^ + h v^,  h = 2 dt / 3,
// and v_n+1 = (x_n+1 - x^) / h, so it costs the same per step: one matrix, factored once.
// Without history (first step, after an edit) BDF2 starts from x_n-1 = x_n - dt v_n + dt^2/2 a_n,
// v_n-1 = v_n - dt a_n.
#include <algorithm>
#include <cmath>

#include "solvers/dynamic_surface.hpp"

namespace hs {

namespace {
// Weight of an explicit extrapolation over a step with rho = dt^2 omega_max^2: whole up to 1,
// falling as 1/rho^2 past it (it went unstable near rho = 2.7), none below a tenth (rho > 3.2),
// where it no longer buys accuracy but would still cost a pass over the mesh.
double extrapolationWeight(double rho) {
    const double w = rho <= 1 ? 1.0 : 1.0 / (rho * rho);
    return w >= 0.1 ? w : 0.0;
}
/// Row i of M x (M: mesh x poles, x: poles x 3).
Vec3 meshRow(const CsrMatrix& m, int i, const Points& x) {
    Vec3 out = Vec3::Zero();
    for (int k = m.rowStart[i]; k < m.rowStart[i + 1]; ++k) out += m.value[k] * x.row(m.col[k]).transpose();
    return out;
}
}  // namespace

void DynamicSurface::ensureImplicitTool(int anchor) {
    ImplicitTool& t = implicitTool_;
    const SystemSlot& slot = systems_[system_];
    const int partner = mirror_.empty() ? anchor : mirror_.mirrorPoint(anchor);
    if (anchor == t.anchors[0] && partner == t.anchors[1] && slot.built == t.system) return;
    t.anchors[0] = anchor;
    t.anchors[1] = partner;
    t.count = partner != anchor ? 2 : 1;
    t.system = slot.built;
    for (int k = 0; k < t.count; ++k) {  // z_k = S^-1 A^T e_anchor_k (the same in x, y, z: column 0)
        meshTmp2_.setZero();
        meshTmp2_.row(t.anchors[k]).setOnes();
        A_.applyTransposed(meshTmp2_, fp_);
        held_.reduce(fp_);
        slot.solver.solve(fp_, t.z[k]);
        held_.expand(t.z[k]);
    }
    t.gram.setZero();
    for (int k = 0; k < t.count; ++k)
        for (int l = 0; l < t.count; ++l) t.gram(k, l) = meshRow(A_.matrix(), t.anchors[k], t.z[l])[0];
}

double DynamicSurface::predictorWeight(double dt, bool fixedTargets) const {
    // The prediction d_n + dt A v_n + dt^2/2 A a_n (a_n from the BDF2 history) is O(dt^3) off the
    // step's end, where the inertial prediction y is O(dt^2) off: one iteration from it stays second
    // order (17x smaller error at 16 us in bench/time_vs_error.py). Extrapolation feeds the stiffest
    // modes back explicitly (omega_max^2 <= 8 k / m_min, k the stiffest spring or penalty term;
    // point constraints pull toward fixed targets and do not feed back through a projection, but
    // they do through an extrapolated history). Non-linear laws can stiffen a spring by up to
    // m / (4 h^2): no prediction there.
    if (springs_.law.kind != LawKind::Linear) return 0.0;
    const double k = std::max(maxStiffness_, constraints_.maxStiffness(!fixedTargets));
    return extrapolationWeight(dt * dt * 8 * k / minMass_);
}

StepReport DynamicSurface::stepLocalGlobal(double dt) {
    StepReport r;
    const bool bdf2 = solver_.timeOrder == 2;
    const double h = localGlobalH(dt);
    ensureSystem(h, true);
    const Points& p = surface_.poles();
    if (!avValid_) A_.apply(v_, av_);
    const double w = bdf2 ? predictorWeight(dt, false) : 0.0;
    const Points* dBase = &d_;  // x^ on the mesh
    // y, the inertial prediction: x_ in control space, yMesh_ on the mesh (A y without a product by A)
    if (bdf2) {
        if (!history_.valid || history_.dt != dt) {
            // The state one step back. Without the acceleration term v_n-1 = v_n is O(dt) off, and a
            // start from rest under load (a pushed pole let go) was then first order throughout.
            // Where extrapolation is unstable (predictorWeight, point constraints included: their
            // stiff pull would enter as a velocity impulse) the term fades out.
            history_.p = p - dt * v_;
            history_.v = v_;
            history_.d = d_ - dt * av_;
            history_.av = av_;
            // Heavy damping is a stiff mode too (rate gamma / m): a past accelerating freely
            // against it is not one BDF2 can start from.
            const double rate = dt * maxDampingRate_;
            const double wh = dampingLaw_.kind != LawKind::Linear
                                  ? 0.0 : std::min(predictorWeight(dt, true), extrapolationWeight(rate * rate));
            if (wh > 0) {
                ensureMassFactor();
                computeAcceleration();  // acc_, and A acc_ into dd_ below
                A_.apply(acc_, dd_);
                history_.p += (0.5 * dt * dt * wh) * acc_;
                history_.v -= (dt * wh) * acc_;
                history_.d += (0.5 * dt * dt * wh) * dd_;
                history_.av -= (dt * wh) * dd_;
            }
        }
        history_.xHat = (4.0 / 3.0) * p - (1.0 / 3.0) * history_.p;
        x_ = history_.xHat + h * ((4.0 / 3.0) * v_ - (1.0 / 3.0) * history_.v);
        history_.dHat = (4.0 / 3.0) * d_ - (1.0 / 3.0) * history_.d;
        yMesh_ = history_.dHat + h * ((4.0 / 3.0) * av_ - (1.0 / 3.0) * history_.av);
        dBase = &history_.dHat;
    } else {
        x_ = p + dt * v_;
        yMesh_ = d_ + dt * av_;
    }
    // The tool pulls where the mesh is predicted at the step's end, as BDF2 wants its forces: taken
    // at the start, they made the rope scene first order. The tool is explicit, so its own slope
    // limits the prediction as the springs' does (the smooth tool's slope is unknown: none).
    if (w > 0) dd_ = dt * av_ + (0.5 * dt) * (av_ - history_.av);  // the predicted motion over the step (mesh)
    const double wt = w > 0 && tool_->grabbed() ? std::min(w, extrapolationWeight(dt * dt * toolSlope() / minMass_)) : 0.0;
    if (wt > 0) {
        meshTmp_ = d_ + wt * dd_;
        applyToolForces(dt, r, meshTmp_);
    } else {
        applyToolForces(dt, r, d_);
    }
    // A one-point tool (the rope) is stiff, and on a plate it pulls harder still (kRopePlateGain):
    // taken explicitly it rang the sheet's slow modes up (an elastic sheet held at its corners, a
    // rope of slope 800: the lift swung 17..28 mm over 4 s and grew; mirrored, kinetic energy 900
    // after 6 s). Its linearisation where it was taken joins the solve, on its anchor and the
    // anchor's mirror image: S + c sum a_k a_k^T with c = h^2 slope, by Woodbury on one more solve
    // per anchor and grab.
    const int anchor = tool_->grabbed() ? tool_->anchor() : -1;
    const double toolC = anchor >= 0 ? h * h * tool_->anchorSlope() : 0.0;
    ImplicitTool& implicit = implicitTool_;
    Eigen::Matrix2d capacitance = Eigen::Matrix2d::Identity();
    if (toolC > 0) {
        ensureImplicitTool(anchor);
        implicit.at[0] = (wt > 0 ? meshTmp_ : d_).row(anchor).transpose();
        implicit.at[1] = mirror_.empty() ? implicit.at[0] : mirror_.reflectPoint(implicit.at[0]);
        capacitance = (Eigen::Matrix2d::Identity() + toolC * implicit.gram).inverse();
    }
    // The parts of the right-hand side that do not depend on the iterate (see the loop).
    base_ = (h * gamma_).asDiagonal() * (*dBase - yMesh_);
    if (hasExternal_) base_ += (h * h) * fext_;
    if (toolForces_) base_ += (h * h) * ftool_;
    if (dampingLaw_.kind != LawKind::Linear) {
        // Extra non-linear damping, explicit, limited to h * extra / m <= 1 so it cannot destabilise.
        force_.setZero();
        springs_.addForces(d_, force_);
        for (Eigen::Index i = 0; i < d_.rows(); ++i) {
            const double extra = (dampingLaw_.dampingFactor(force_.row(i).norm()) - 1.0) * gamma_[i];
            const double limited = std::min(extra, m_[i] / h);
            base_.row(i) -= h * limited * (yMesh_.row(i) - dBase->row(i));  // h^2 * extra * v^
        }
    }
    // The first iterate: y, or the end of the step predicted to O(dt^3) (predictorWeight).
    const Points* iterate = &yMesh_;
    if (w > 0) {
        x_ += w * (p + dt * v_ + (0.5 * dt) * (v_ - history_.v) - x_);
        meshTmp_ = yMesh_ + w * (d_ + dd_ - yMesh_);
        iterate = &meshTmp_;
    }
    // Each iteration solves for the increment from the iterate x (mesh d = A x):
    //   S (x' - x) = A^T [ (M + h D)(y - d) + h D (x^ - y) + h^2 (f + J t - L d) ]
    // Every term is small, so rounding stays relative to the step's motion. Solving for x' itself
    // puts M y (large) beside h^2 f (small): the solve's rounding, of the order of the positions,
    // then biases every step the same way, and BDF2 turns that into a drifting velocity (error
    // 4.7e-5 at a 1 us step in bench/time_vs_error.py's oscillation, growing as the step shrinks).
    double change = 0;
    for (int it = 0; it < solver_.iterations; ++it) {
        if (it > 0) {
            A_.apply(x_, meshTmp_);
            iterate = &meshTmp_;
        }
        if (iterate == &yMesh_) meshTmp2_ = base_;  // d = y
        else meshTmp2_ = base_ + (m_ + h * gamma_).asDiagonal() * (yMesh_ - *iterate);
        springs_.addProjections(*iterate, meshTmp2_, 0.25 * minMass_ / (h * h), h * h);
        bending_.addForces(*iterate, meshTmp2_, h * h);  // quadratic: its force is J t - L d's part
        if (!constraints_.empty()) constraints_.addProjections(*iterate, meshTmp2_, terms_, h * h);
        if (toolC > 0)
            for (int k = 0; k < implicit.count; ++k)
                meshTmp2_.row(implicit.anchors[k]) -= toolC * (iterate->row(implicit.anchors[k]) - implicit.at[k].transpose());
        A_.applyTransposed(meshTmp2_, fp_);
        held_.reduce(fp_);
        systems_[system_].solver.solve(fp_, acc_);
        held_.expand(acc_);
        if (toolC > 0) {  // acc -= Z (I + c G)^-1 c A_anchors acc, per coordinate
            const Vec3 moved0 = meshRow(A_.matrix(), implicit.anchors[0], acc_);
            const Vec3 moved1 = implicit.count == 2 ? meshRow(A_.matrix(), implicit.anchors[1], acc_) : Vec3::Zero();
            for (int c = 0; c < 3; ++c) {
                const Eigen::Vector2d weights = capacitance * (toolC * Eigen::Vector2d(moved0[c], moved1[c]));
                for (int k = 0; k < implicit.count; ++k) acc_.col(c) -= weights[k] * implicit.z[k].col(0);
            }
        }
        change = acc_.cwiseAbs().maxCoeff();
        x_ += acc_;
        ++r.iterations;
    }
    r.residual = change / size_;
    if (bdf2) {
        v_ = (x_ - history_.xHat) / h;
        // History for the next step: the state this step started from (step()'s backups).
        history_.p = backup_.p;
        history_.v = backup_.v;
        history_.d = dPrev_;
        history_.av.swap(av_);
    } else {
        v_ = (x_ - p) / dt;
    }
    surface_.mutablePoles() = x_;
    A_.apply(surface_.poles(), d_);
    if (toolC > 0) {
        // What the surface received is the linearised force at the step's end: the work the guard
        // counts takes it, and the reaction stays the exact opposite of the tool's own (not its
        // mirror image's) force.
        for (int k = 0; k < implicit.count; ++k) {
            const int a = implicit.anchors[k];
            const Vec3 part = -(toolC / (h * h)) * (d_.row(a).transpose() - implicit.at[k]);
            ftool_.row(a) += part.transpose();
            if (k == 0) {
                r.reaction.force -= part;
                r.reaction.torque -= (implicit.at[0] - cursor_.position).cross(part);
            }
        }
    }
    // A v up to rounding, since A is linear, without a product by A
    if (bdf2) av_ = (d_ - history_.dHat) / h;
    else av_ = (d_ - dPrev_) / dt;
    avValid_ = true;
    history_.valid = bdf2;
    history_.dt = dt;
    accelerationValid_ = false;
    return r;
}

}  // namespace hs
