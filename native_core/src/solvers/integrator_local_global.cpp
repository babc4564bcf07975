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
#include "solvers/integrator_local_global.hpp"

#include <algorithm>
#include <cmath>

namespace hs {

namespace {
// Weight of an explicit extrapolation over a step with rho = dt^2 omega_max^2: whole up to 1,
// falling as 1/rho^2 past it (it went unstable near rho = 2.7), none below a tenth (rho > 3.2),
// where it no longer buys accuracy but would still cost a pass over the mesh.
double extrapolationWeight(double rho) {
    const double w = rho <= 1 ? 1.0 : 1.0 / (rho * rho);
    return w >= 0.1 ? w : 0.0;
}
// BDF2 carries a tool's explicit force only while dt^2 slope / m_min stays below about 0.05: past
// it the magnet rang and pulled 1.3 to 20 times too hard (64^2 mesh, 1 ms: 549 N against 50 N at a
// converged 0.25 ms; 128^2 at 0.065: 60 N against 42 N), at any step length. Backward Euler carries
// it at every slope measured (to 2.6), within 5 % of the converged force.
constexpr double kBdf2ExplicitToolLimit = 0.03;
/// Row i of M x (M: mesh x poles, x: poles x 3).
Vec3 meshRow(const CsrMatrix& m, int i, const Points& x) {
    Vec3 out = Vec3::Zero();
    for (int k = m.rowStart[i]; k < m.rowStart[i + 1]; ++k) out += m.value[k] * x.row(m.col[k]).transpose();
    return out;
}
}  // namespace

LocalGlobalIntegrator::LocalGlobalIntegrator(Eigen::Index meshPoints, Eigen::Index poles) {
    for (Points* m : {&history_.d, &history_.av, &history_.dHat, &yMesh_, &base_}) m->setZero(meshPoints, 3);
    for (Points* m : {&history_.p, &history_.v, &history_.xHat, &x_, &tool_.z[0], &tool_.z[1]}) m->setZero(poles, 3);
}

void LocalGlobalIntegrator::ensureImplicitTool(StepModel& m, int anchor) {
    ImplicitTool& t = tool_;
    const int partner = m.mirror.empty() ? anchor : m.mirror.mirrorPoint(anchor);
    if (anchor == t.anchors[0] && partner == t.anchors[1] && m.systemBuild() == t.system) return;
    t.anchors[0] = anchor;
    t.anchors[1] = partner;
    t.count = partner != anchor ? 2 : 1;
    t.system = m.systemBuild();
    Points &unit = m.scratch.mesh2, &fp = m.scratch.poleForce;
    for (int k = 0; k < t.count; ++k) {  // z_k = S^-1 A^T e_anchor_k (the same in x, y, z: column 0)
        unit.setZero();
        unit.row(t.anchors[k]).setOnes();
        m.state.A.applyTransposed(unit, fp);
        m.held.reduce(fp);
        m.solveSystem(fp, t.z[k]);
        m.held.expand(t.z[k]);
    }
    t.gram.setZero();
    for (int k = 0; k < t.count; ++k)
        for (int l = 0; l < t.count; ++l) t.gram(k, l) = meshRow(m.state.A.matrix(), t.anchors[k], t.z[l])[0];
}

double LocalGlobalIntegrator::predictorWeight(const StepModel& m, double dt, bool fixedTargets) const {
    // The prediction d_n + dt A v_n + dt^2/2 A a_n (a_n from the BDF2 history) is O(dt^3) off the
    // step's end, where the inertial prediction y is O(dt^2) off: one iteration from it stays second
    // order (17x smaller error at 16 us in bench/time_vs_error.py). Extrapolation feeds the stiffest
    // modes back explicitly (omega_max^2 <= 8 k / m_min, k the stiffest spring or penalty term;
    // point constraints pull toward fixed targets and do not feed back through a projection, but
    // they do through an extrapolated history). Non-linear laws can stiffen a spring by up to
    // m / (4 h^2): no prediction there.
    if (m.material.springs.law.kind != LawKind::Linear) return 0.0;
    const double k = std::max(m.material.maxStiffness(), m.forces.constraints().maxStiffness(!fixedTargets));
    return extrapolationWeight(dt * dt * 8 * k / m.material.minMass());
}

void LocalGlobalIntegrator::startHistory(StepModel& m, double dt) {
    // The state one step back. Without the acceleration term v_n-1 = v_n is O(dt) off, and a
    // start from rest under load (a pushed pole let go) was then first order throughout.
    // Where extrapolation is unstable (predictorWeight, point constraints included: their
    // stiff pull would enter as a velocity impulse) the term fades out.
    const SurfaceState& s = m.state;
    history_.p = s.poles() - dt * s.v;
    history_.v = s.v;
    history_.d = s.d - dt * s.av;
    history_.av = s.av;
    // Heavy damping is a stiff mode too (rate gamma / m): a past accelerating freely
    // against it is not one BDF2 can start from.
    const double rate = dt * m.material.maxDampingRate();
    const double wh = m.material.dampingLaw.kind != LawKind::Linear
                          ? 0.0 : std::min(predictorWeight(m, dt, true), extrapolationWeight(rate * rate));
    if (wh > 0) {
        m.ensureMass();
        Points &acc = m.scratch.poleStep, &meshAcc = m.scratch.meshVelocity;
        m.acceleration(acc);
        s.A.apply(acc, meshAcc);
        history_.p += (0.5 * dt * dt * wh) * acc;
        history_.v -= (dt * wh) * acc;
        history_.d += (0.5 * dt * dt * wh) * meshAcc;
        history_.av -= (dt * wh) * meshAcc;
    }
}

void LocalGlobalIntegrator::settleOutside(StepModel& m) {
    // Outside the region nothing moves: its poles' prediction is where they are, with no past
    // motion, so every formula below gives them back unchanged and reads only the region.
    SurfaceState& s = m.state;
    const ActiveRegion& region = m.region;
    for (Eigen::Index k = 0; k < s.poles().rows(); ++k)
        if (!region.poles.containsIndex(k)) {
            x_.row(k) = s.poles().row(k);
            history_.p.row(k) = s.poles().row(k);
            history_.v.row(k).setZero();
        }
    for (Eigen::Index k = 0; k < s.d.rows(); ++k)
        if (!region.mesh.containsIndex(k)) {
            history_.d.row(k) = s.d.row(k);
            history_.av.row(k).setZero();
            s.av.row(k).setZero();
        }
}

StepReport LocalGlobalIntegrator::step(StepModel& m, double dt) {
    StepReport r;
    SurfaceState& s = m.state;
    const Material& material = m.material;
    SurfaceForces& forces = m.forces;
    const ConstraintSet& constraints = forces.constraints();
    const Eigen::VectorXd &gamma = material.damping(), &masses = material.masses();
    Points &tmp = m.scratch.mesh, &rhs = m.scratch.mesh2, &fp = m.scratch.poleForce, &inc = m.scratch.poleStep;
    Points& motion = m.scratch.meshVelocity;
    // What the step moves: the poles P, the mesh points W they move, and W's halo H where forces
    // are read (all of the net on a whole step: then each is one run).
    const GridRect &P = m.region.poles, &W = m.region.mesh, &H = m.region.halo;
    const bool regional = !m.region.whole;
    // A tool taken explicitly (every one but the rope, whose anchor joins the solve) and too stiff
    // for BDF2 makes the step backward Euler while it holds (kBdf2ExplicitToolLimit).
    const Tool& tool = forces.tool();
    const double toolRho = dt * dt * m.toolSlope() / material.minMass();  // (infinite: slope unknown)
    const bool stiffTool = tool.grabbed() && !tool.implicitOnAnchor() && std::isfinite(toolRho) &&
                           toolRho > kBdf2ExplicitToolLimit;
    const bool bdf2 = m.settings.timeOrder == 2 && !stiffTool;
    const double h = bdf2 ? systemStep(m.settings, dt) : dt;
    m.ensureStepSystem(h);
    const Points& p = s.poles();
    if (!s.avValid) s.A.apply(s.v, s.av);
    const double w = bdf2 ? predictorWeight(m, dt, false) : 0.0;
    const Points* dBase = &s.d;  // x^ on the mesh
    bool fresh = false;
    if (bdf2 && (!history_.valid || history_.dt != dt)) {
        startHistory(m, dt);
        fresh = true;
    }
    if (regional && (fresh || m.region.serial != regionSerial_)) settleOutside(m);
    regionSerial_ = m.region.serial;
    // y, the inertial prediction: x_ in control space, yMesh_ on the mesh (A y without a product by A)
    if (bdf2) {
        P.forSpans([&](const auto& q) {
            q(history_.xHat) = (4.0 / 3.0) * q(p) - (1.0 / 3.0) * q(history_.p);
            q(x_) = q(history_.xHat) + h * ((4.0 / 3.0) * q(s.v) - (1.0 / 3.0) * q(history_.v));
        });
        H.forSpans([&](const auto& q) {
            q(history_.dHat) = (4.0 / 3.0) * q(s.d) - (1.0 / 3.0) * q(history_.d);
            q(yMesh_) = q(history_.dHat) + h * ((4.0 / 3.0) * q(s.av) - (1.0 / 3.0) * q(history_.av));
        });
        dBase = &history_.dHat;
    } else {
        P.forSpans([&](const auto& q) { q(x_) = q(p) + dt * q(s.v); });
        H.forSpans([&](const auto& q) { q(yMesh_) = q(s.d) + dt * q(s.av); });
    }
    // The tool pulls where the mesh is predicted at the step's end, as BDF2 wants its forces: taken
    // at the start, they made the rope scene first order. The tool is explicit, so its own slope
    // limits the prediction as the springs' does (the smooth tool's slope is unknown: none).
    if (w > 0)  // the predicted motion over the step (mesh)
        H.forSpans([&](const auto& q) { q(motion) = dt * q(s.av) + (0.5 * dt) * (q(s.av) - q(history_.av)); });
    if (stiffTool) H.forSpans([&](const auto& q) { q(motion) = dt * q(s.av); });
    const double toolWeight = extrapolationWeight(toolRho);
    const double wt = stiffTool ? toolWeight : w > 0 && tool.grabbed() ? std::min(w, toolWeight) : 0.0;
    if (wt > 0) {
        H.forSpans([&](const auto& q) { q(tmp) = q(s.d) + wt * q(motion); });
        m.applyTool(dt, r, tmp);
    } else {
        m.applyTool(dt, r, s.d);
    }
    // A one-point tool (the rope) is stiff, and on a plate it pulls harder still (kRopePlateGain):
    // taken explicitly it rang the sheet's slow modes up (an elastic sheet held at its corners, a
    // rope of slope 800: the lift swung 17..28 mm over 4 s and grew; mirrored, kinetic energy 900
    // after 6 s). Its linearisation where it was taken joins the solve, on its anchor and the
    // anchor's mirror image: S + c sum a_k a_k^T with c = h^2 slope, by Woodbury on one more solve
    // per anchor and grab.
    const int anchor = tool.grabbed() ? tool.anchor() : -1;
    const double toolC = anchor >= 0 ? h * h * tool.anchorSlope() : 0.0;
    ImplicitTool& implicit = tool_;
    Eigen::Matrix2d capacitance = Eigen::Matrix2d::Identity();
    if (toolC > 0) {
        ensureImplicitTool(m, anchor);
        implicit.at[0] = (wt > 0 ? tmp : s.d).row(anchor).transpose();
        implicit.at[1] = m.mirror.empty() ? implicit.at[0] : m.mirror.reflectPoint(implicit.at[0]);
        capacitance = (Eigen::Matrix2d::Identity() + toolC * implicit.gram).inverse();
    }
    // The parts of the right-hand side that do not depend on the iterate (see the loop).
    H.forRuns([&](Eigen::Index i, Eigen::Index n) {
        base_.middleRows(i, n) = (h * gamma.segment(i, n)).asDiagonal() * (dBase->middleRows(i, n) - yMesh_.middleRows(i, n));
        if (forces.hasExternal()) base_.middleRows(i, n) += (h * h) * forces.external().middleRows(i, n);
        if (forces.toolActive()) base_.middleRows(i, n) += (h * h) * forces.fromTool().middleRows(i, n);
    });
    if (material.dampingLaw.kind != LawKind::Linear) {  // (never regional)
        // Extra non-linear damping, explicit, limited to h * extra / m <= 1 so it cannot destabilise.
        Points& springForce = forces.total();
        springForce.setZero();
        m.material.springs.addForces(s.d, springForce);
        for (Eigen::Index i = 0; i < s.d.rows(); ++i) {
            const double extra = (material.dampingLaw.dampingFactor(springForce.row(i).norm()) - 1.0) * gamma[i];
            const double limited = std::min(extra, masses[i] / h);
            base_.row(i) -= h * limited * (yMesh_.row(i) - dBase->row(i));  // h^2 * extra * v^
        }
    }
    // The first iterate: y, or the end of the step predicted to O(dt^3) (predictorWeight).
    const Points* iterate = &yMesh_;
    if (w > 0) {
        P.forSpans([&](const auto& q) {
            q(x_) += w * (q(p) + dt * q(s.v) + (0.5 * dt) * (q(s.v) - q(history_.v)) - q(x_));
        });
        H.forSpans([&](const auto& q) { q(tmp) = q(yMesh_) + w * (q(s.d) + q(motion) - q(yMesh_)); });
        iterate = &tmp;
    }
    // Each iteration solves for the increment from the iterate x (mesh d = A x):
    //   S (x' - x) = A^T [ (M + h D)(y - d) + h D (x^ - y) + h^2 (f + J t - L d) ]
    // Every term is small, so rounding stays relative to the step's motion. Solving for x' itself
    // puts M y (large) beside h^2 f (small): the solve's rounding, of the order of the positions,
    // then biases every step the same way, and BDF2 turns that into a drifting velocity (error
    // 4.7e-5 at a 1 us step in bench/time_vs_error.py's oscillation, growing as the step shrinks).
    // A regional step reads the halo H and writes W's rows of the right-hand side, which are all
    // that A^T takes onto the region's poles.
    const GridRect* window = regional ? &H : nullptr;
    const GridRect* rows = regional ? &W : nullptr;
    double change = 0;
    for (int it = 0; it < m.settings.iterations; ++it) {
        if (it > 0) {
            if (regional) s.A.applyTo(x_, tmp, H);
            else s.A.apply(x_, tmp);
            iterate = &tmp;
        }
        if (iterate == &yMesh_) H.forSpans([&](const auto& q) { q(rhs) = q(base_); });  // d = y
        else
            H.forRuns([&](Eigen::Index i, Eigen::Index n) {
                rhs.middleRows(i, n) = base_.middleRows(i, n) + (masses.segment(i, n) + h * gamma.segment(i, n)).asDiagonal() *
                                                                    (yMesh_.middleRows(i, n) - iterate->middleRows(i, n));
            });
        m.material.springs.addProjections(*iterate, rhs, 0.25 * material.minMass() / (h * h), h * h, false, window);
        material.bending.addForces(*iterate, rhs, h * h, rows);  // quadratic: its force is J t - L d's part
        if (!constraints.empty()) constraints.addProjections(*iterate, rhs, forces.terms(), h * h);  // (never regional)
        if (toolC > 0)
            for (int k = 0; k < implicit.count; ++k)
                rhs.row(implicit.anchors[k]) -= toolC * (iterate->row(implicit.anchors[k]) - implicit.at[k].transpose());
        if (regional) s.A.applyTransposedTo(rhs, fp, P, W);
        else s.A.applyTransposed(rhs, fp);
        m.held.reduce(fp);
        m.solveSystem(fp, inc);
        m.held.expand(inc);
        if (toolC > 0) {  // inc -= Z (I + c G)^-1 c A_anchors inc, per coordinate
            const Vec3 moved0 = meshRow(s.A.matrix(), implicit.anchors[0], inc);
            const Vec3 moved1 = implicit.count == 2 ? meshRow(s.A.matrix(), implicit.anchors[1], inc) : Vec3::Zero();
            Eigen::Vector2d weights[3];
            for (int c = 0; c < 3; ++c) weights[c] = capacitance * (toolC * Eigen::Vector2d(moved0[c], moved1[c]));
            P.forSpans([&](const auto& q) {
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < implicit.count; ++k) q(inc).col(c) -= weights[c][k] * q(implicit.z[k]).col(0);
            });
        }
        change = 0;
        P.forSpans([&](const auto& q) {
            change = std::max(change, q(inc).cwiseAbs().maxCoeff());
            q(x_) += q(inc);
        });
        ++r.iterations;
    }
    r.residual = change / s.size;
    if (bdf2) {
        P.forSpans([&](const auto& q) {
            q(s.v) = (q(x_) - q(history_.xHat)) / h;
            // History for the next step: the state this step started from.
            q(history_.p) = q(s.polesAtStart);
            q(history_.v) = q(s.velocitiesAtStart);
        });
        H.forSpans([&](const auto& q) { q(history_.d) = q(s.meshAtStart); });
        history_.av.swap(s.av);
    } else {
        P.forSpans([&](const auto& q) { q(s.v) = (q(x_) - q(p)) / dt; });
    }
    P.forSpans([&](const auto& q) { q(s.mutablePoles()) = q(x_); });
    if (regional) s.A.applyTo(s.poles(), s.d, W);
    else s.sampleMesh();
    if (toolC > 0) {
        // What the surface received is the linearised force at the step's end: the work the guard
        // counts takes it, and the reaction stays the exact opposite of the tool's own (not its
        // mirror image's) force.
        for (int k = 0; k < implicit.count; ++k) {
            const int a = implicit.anchors[k];
            const Vec3 part = -(toolC / (h * h)) * (s.d.row(a).transpose() - implicit.at[k]);
            forces.fromTool().row(a) += part.transpose();
            if (k == 0) {
                r.reaction.force -= part;
                r.reaction.torque -= (implicit.at[0] - forces.cursor.position).cross(part);
            }
        }
    }
    // A v up to rounding, since A is linear, without a product by A
    if (bdf2) H.forSpans([&](const auto& q) { q(s.av) = (q(s.d) - q(history_.dHat)) / h; });
    else H.forSpans([&](const auto& q) { q(s.av) = (q(s.d) - q(s.meshAtStart)) / dt; });
    s.avValid = true;
    history_.valid = bdf2;
    history_.dt = dt;
    return r;
}

}  // namespace hs
