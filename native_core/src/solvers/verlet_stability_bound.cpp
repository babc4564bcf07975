// The bound behind local/global's Verlet branch: omega_max^2 of the springs and penalty terms in
// control space, for the current masses, stiffnesses and constraints.
// For linear springs the Hessian of 1/2 k (|x_a - x_b| - l)^2 is k n n^T + k (1 - l / |x_a - x_b|)
// (I - n n^T) <= k I: the Laplacian L bounds it whatever the state, and penalty terms are the same
// form (projections onto convex sets). So omega_max^2 <= lambda_max(M^-1 K) with K = A^T L A and
// M = A^T M A, found by Lanczos. Painting a map changes K and M every few steps: there the bounds
// are rescaled from the last computed ones instead (K' <= max(k'/k) K, M' >= min(m'/m) M, and the
// reverse for the lower bound), and recomputed only when the rescaled pair no longer decides.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <Eigen/Eigenvalues>
#include <limits>
#include <random>
#include <vector>

#include "solvers/dynamic_surface.hpp"

namespace hs {

bool DynamicSurface::omegaSquaredBelow(double limit, bool tight) {
    const std::uint64_t key[4] = {mass_.version(), stiffness_.version(), structureKey(), bendingMap_.version()};
    if (key[0] != omega_.key[0] || key[1] != omega_.key[1] || key[2] != omega_.key[2] || key[3] != omega_.key[3]) {
        rescaleOmegaBounds();
        for (int i = 0; i < 4; ++i) omega_.key[i] = key[i];
    }
    if (!tight) {
        if (omega_.upper <= limit) return true;
        if (omega_.lower > limit || omega_.tight) return false;
    }
    if (!omega_.tight) computeOmegaBounds(tight ? std::numeric_limits<double>::infinity() : limit);
    return omega_.upper <= limit;
}

void DynamicSurface::rescaleOmegaBounds() {
    omega_.tight = false;
    if (omega_.snapK.size() == 0 || omega_.snapStructure != structureKey()) {
        omega_.upper = std::numeric_limits<double>::infinity();
        omega_.lower = 0;
        return;
    }
    double kUp = 1, kDown = 1, mUp = 0, mDown = std::numeric_limits<double>::infinity();
    for (Eigen::Index s = 0; s < omega_.snapK.size(); ++s) {
        const double r = springs_.stiffness(static_cast<int>(s)) / omega_.snapK[s];
        kUp = std::max(kUp, r);
        kDown = std::min(kDown, r);
    }
    // K_b = B^T W B grows by at most the largest ratio of its row weights (0 stays 0; from 0, unbounded).
    const Eigen::VectorXd& w = bending_.weights();
    for (Eigen::Index s = 0; s < w.size(); ++s) {
        const double was = omega_.snapBending[s];
        const double r = was > 0 ? w[s] / was : w[s] > 0 ? std::numeric_limits<double>::infinity() : 1.0;
        kUp = std::max(kUp, r);
        kDown = std::min(kDown, r);
    }
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
        const double r = m_[i] / omega_.snapM[i];
        mUp = std::max(mUp, r);
        mDown = std::min(mDown, r);
    }
    omega_.upper = omega_.snapUpper * kUp / mDown;
    omega_.lower = omega_.snapLower * kDown / mUp;
}

void DynamicSurface::computeOmegaBounds(double limit) {
    ensureMassFactor();
    const Eigen::SparseMatrix<double> A = A_.matrix().toEigen();
    Eigen::SparseMatrix<double> K = A.transpose() * laplacian() * A;
    held_.restrict(K, false);  // the held poles' modes are gone (massMatrix_ is restricted too)
    const Eigen::SparseMatrix<double>& M = massMatrix_;
    omega_.snapK.resize(static_cast<Eigen::Index>(springs_.first().size()));
    for (Eigen::Index s = 0; s < omega_.snapK.size(); ++s) omega_.snapK[s] = springs_.stiffness(static_cast<int>(s));
    omega_.snapM = m_;
    omega_.snapStructure = structureKey();
    omega_.snapBending = bending_.weights();
    // max K_ii / M_ii is a Rayleigh quotient, so a lower bound: it rules out long steps cheaply.
    const double lower = (K.diagonal().array() / M.diagonal().array()).maxCoeff();
    if (lower > limit) {
        omega_.lower = omega_.snapLower = lower;
        omega_.upper = omega_.snapUpper = std::numeric_limits<double>::infinity();
        omega_.tight = false;
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
    held_.zeroRows(q);
    mw = M * q;
    for (int c = 0; c < 3; ++c) q.col(c) /= std::sqrt(q.col(c).dot(mw.col(c)));
    Eigen::MatrixXd alpha = Eigen::MatrixXd::Zero(kMaxSteps, 3), beta = Eigen::MatrixXd::Zero(kMaxSteps, 3);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> tri;
    double best = lower, last = 0;
    bool live[3] = {true, true, true};
    for (int j = 0; j < kMaxSteps; ++j) {
        kq = K * q;
        massSolver_.solve(kq, w);
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
    omega_.lower = omega_.snapLower = best;
    omega_.upper = omega_.snapUpper = 1.05 * best;
    omega_.tight = true;
}

}  // namespace hs
