// The bound behind local/global's Verlet branch: omega_max^2 of the springs and penalty terms in
// control space, for the current masses, stiffnesses and constraints.
// For linear springs the Hessian of 1/2 k (|x_a - x_b| - l)^2 is k n n^T + k (1 - l / |x_a - x_b|)
// (I - n n^T) <= k I: the Laplacian L bounds it whatever the state, and penalty terms are the same
// form (projections onto convex sets). So omega_max^2 <= lambda_max(M^-1 K) with K = A^T L A and
// M = A^T M A, found by Lanczos. Painting a map changes K and M every few steps: there the bounds
// are rescaled from the last computed ones instead (K' <= max(k'/k) K, M' >= min(m'/m) M, and the
// reverse for the lower bound), and recomputed only when the rescaled pair no longer decides.
#include "solvers/verlet_stability_bound.hpp"

#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

namespace hs {

bool VerletStabilityBound::below(StepModel& m, double limit, bool tight) {
    const Material& mat = m.material;
    const std::uint64_t key[4] = {mat.massMap.version(), mat.stiffnessMap.version(), m.structureKey(),
                                  mat.bendingMap.version()};
    if (key[0] != key_[0] || key[1] != key_[1] || key[2] != key_[2] || key[3] != key_[3]) {
        rescale(m);
        for (int i = 0; i < 4; ++i) key_[i] = key[i];
    }
    if (!tight) {
        if (upper_ <= limit) return true;
        if (lower_ > limit || tight_) return false;
    }
    if (!tight_) compute(m, tight ? std::numeric_limits<double>::infinity() : limit);
    return upper_ <= limit;
}

void VerletStabilityBound::rescale(const StepModel& m) {
    tight_ = false;
    if (snapK_.size() == 0 || snapStructure_ != m.structureKey()) {
        upper_ = std::numeric_limits<double>::infinity();
        lower_ = 0;
        return;
    }
    double kUp = 1, kDown = 1, mUp = 0, mDown = std::numeric_limits<double>::infinity();
    for (Eigen::Index s = 0; s < snapK_.size(); ++s) {
        const double r = m.material.springs.stiffness(static_cast<int>(s)) / snapK_[s];
        kUp = std::max(kUp, r);
        kDown = std::min(kDown, r);
    }
    // K_b = B^T W B grows by at most the largest ratio of its row weights (0 stays 0; from 0, unbounded).
    const Eigen::VectorXd& w = m.material.bending.weights();
    for (Eigen::Index s = 0; s < w.size(); ++s) {
        const double was = snapBending_[s];
        const double r = was > 0 ? w[s] / was : w[s] > 0 ? std::numeric_limits<double>::infinity() : 1.0;
        kUp = std::max(kUp, r);
        kDown = std::min(kDown, r);
    }
    const Eigen::VectorXd& masses = m.material.masses();
    for (Eigen::Index i = 0; i < masses.size(); ++i) {
        const double r = masses[i] / snapM_[i];
        mUp = std::max(mUp, r);
        mDown = std::min(mDown, r);
    }
    upper_ = snapUpper_ * kUp / mDown;
    lower_ = snapLower_ * kDown / mUp;
}

void VerletStabilityBound::compute(StepModel& m, double limit) {
    m.ensureMass();
    const Eigen::SparseMatrix<double> A = m.state.A.matrix().toEigen();
    Eigen::SparseMatrix<double> K = A.transpose() * m.laplacian() * A;
    m.held.restrict(K, false);  // the held poles' modes are gone (the mass matrix is restricted too)
    const Eigen::SparseMatrix<double>& M = m.systems.massMatrix();
    const SpringMesh& springs = m.material.springs;
    snapK_.resize(static_cast<Eigen::Index>(springs.first().size()));
    for (Eigen::Index s = 0; s < snapK_.size(); ++s) snapK_[s] = springs.stiffness(static_cast<int>(s));
    snapM_ = m.material.masses();
    snapStructure_ = m.structureKey();
    snapBending_ = m.material.bending.weights();
    // max K_ii / M_ii is a Rayleigh quotient, so a lower bound: it rules out long steps cheaply.
    const double lower = (K.diagonal().array() / M.diagonal().array()).maxCoeff();
    if (lower > limit) {
        lower_ = snapLower_ = lower;
        upper_ = snapUpper_ = std::numeric_limits<double>::infinity();
        tight_ = false;
        return;
    }
    // Lanczos in the M inner product (M^-1 K is self-adjoint there): its largest Ritz value is a
    // Rayleigh quotient too, and reaches lambda_max in a few dozen products where power iteration
    // took over a hundred. Three seeded random starts run side by side (the mass solver works on
    // N x 3 blocks); stop when the largest Ritz value has settled to 1e-6.
    constexpr int kMaxSteps = 60;
    const Eigen::Index n = K.rows();
    Points q(n, 3), qPrev = Points::Zero(n, 3), kq(n, 3), w(n, 3), mw(n, 3);
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    for (Eigen::Index i = 0; i < q.size(); ++i) q.data()[i] = uni(rng);
    m.held.zeroRows(q);
    mw = M * q;
    for (int c = 0; c < 3; ++c) q.col(c) /= std::sqrt(q.col(c).dot(mw.col(c)));
    Eigen::MatrixXd alpha = Eigen::MatrixXd::Zero(kMaxSteps, 3), beta = Eigen::MatrixXd::Zero(kMaxSteps, 3);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tri;
    double best = lower, last = 0;
    bool live[3] = {true, true, true};
    for (int j = 0; j < kMaxSteps; ++j) {
        kq = K * q;
        m.systems.mass().solve(kq, w);
        for (int c = 0; c < 3; ++c) {
            if (!live[c]) continue;
            alpha(j, c) = q.col(c).dot(kq.col(c));
            w.col(c) -= alpha(j, c) * q.col(c) + (j > 0 ? beta(j - 1, c) : 0.0) * qPrev.col(c);
            Eigen::VectorXd sub = beta.col(c).head(std::max(0, j));
            tri.computeFromTridiagonal(alpha.col(c).head(j + 1), sub, Eigen::EigenvaluesOnly);
            best = std::max(best, tri.eigenvalues().maxCoeff());
        }
        if (j > 2 && best <= last * (1 + 1e-6)) break;
        last = best;
        mw = M * w;
        qPrev = q;
        for (int c = 0; c < 3; ++c) {
            const double b = std::sqrt(std::max(0.0, w.col(c).dot(mw.col(c))));
            live[c] = live[c] && b > 1e-12 * std::abs(alpha(j, c));  // an invariant subspace: exact
            beta(j, c) = b;
            if (live[c]) q.col(c) = w.col(c) / b;
        }
        if (!live[0] && !live[1] && !live[2]) break;
    }
    // Ritz values are Rayleigh quotients: lower bounds that reach lambda_max from below; hence the margin.
    lower_ = snapLower_ = best;
    upper_ = snapUpper_ = 1.05 * best;
    tight_ = true;
}

}  // namespace hs
