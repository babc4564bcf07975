// Implicit steps by local/global iterations in control space, BDF2 or backward Euler
// (integrator_local_global.cpp).
#pragma once
#include <Eigen/Core>
#include <cstdint>

#include "solvers/step_model.hpp"

namespace hs {

class LocalGlobalIntegrator {
public:
    explicit LocalGlobalIntegrator(Eigen::Index meshPoints, Eigen::Index poles);
    /// The step length its system is built for: 2 dt / 3 for BDF2, dt for backward Euler.
    static double systemStep(const SolverSettings& s, double dt) { return s.timeOrder == 2 ? 2.0 * dt / 3.0 : dt; }
    StepReport step(StepModel& m, double dt);
    /// The next step starts BDF2 afresh (the state jumped, or the applied forces did: see Bdf2History).
    void restart() { history_.valid = false; }
    /// Carries `live`'s history over, so the step after an edit stays second order.
    void continueFrom(const LocalGlobalIntegrator& live) { history_ = live.history_; }

private:
    /// The state one step back (poles, velocities, mesh, A v) taken at step `dt`, and
    /// x^ = (4 x_n - x_n-1) / 3 on the poles and the mesh.
    /// `valid`: the history is the previous step's (cleared where the applied forces jump: external
    /// forces set or cleared, a grab or a release). BDF2 extrapolates the acceleration from its
    /// history, so across a jump it overshoots: a force held for one step from rest and then removed
    /// left 16/9 of the kinetic energy it put in. Restarting (the history synthesised from the new
    /// forces) is the textbook cure for multistep methods.
    struct Bdf2History {
        Points p, v, d, av, xHat, dHat;
        double dt = 0;
        bool valid = false;
    };
    /// A one-point tool taken implicitly: its anchor and, mirrored, the anchor's partner (Woodbury
    /// on S + c sum_k a_k a_k^T, a_k = A^T e_anchor_k), with z_k = S^-1 a_k and gram(k, l) =
    /// a_k^T z_l for the system build they were solved for.
    struct ImplicitTool {
        int anchors[2] = {-1, -1};
        int count = 0;
        Points z[2];
        Eigen::Matrix2d gram = Eigen::Matrix2d::Zero();
        std::uint64_t system = 0;
        Vec3 at[2] = {Vec3::Zero(), Vec3::Zero()};  // where the force on each was taken this step
    };
    /// Local/global BDF2: weight in [0, 1] of a second-order extrapolation over dt (the prediction
    /// of the step's end; with `fixedTargets`, point constraints count too: the history's start).
    double predictorWeight(const StepModel& m, double dt, bool fixedTargets) const;
    void ensureImplicitTool(StepModel& m, int anchor);
    /// The history of a step with none: synthesised from the current state and acceleration.
    void startHistory(StepModel& m, double dt);
    /// On a regional step after the region changed or the history restarted: everything outside
    /// the region at rest where it is (x_, history), so the step need not read it.
    void settleOutside(StepModel& m);

    Bdf2History history_;
    Points x_;      // the iterate on the poles
    Points yMesh_;  // the inertial prediction on the mesh
    Points base_;   // the right-hand side's part that does not depend on the iterate
    ImplicitTool tool_;
    std::uint64_t regionSerial_ = 0;  // the region the outside was last settled for
};

}  // namespace hs
