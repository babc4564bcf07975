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

#include "dynamic_surface.hpp"

namespace hs {

bool DynamicSurface::omegaSquaredBelow(double limit, bool tight) {
    const std::uint64_t key[3] = {mass_.version(), stiffness_.version(), constraints_.structureVersion()};
    if (key[0] != omegaKey_[0] || key[1] != omegaKey_[1] || key[2] != omegaKey_[2]) {
        rescaleOmegaBounds();
        for (int i = 0; i < 3; ++i) omegaKey_[i] = key[i];
    }
    if (!tight) {
        if (omegaUpper_ <= limit) return true;
        if (omegaLower_ > limit || omegaTight_) return false;
    }
    if (!omegaTight_) computeOmegaBounds(tight ? std::numeric_limits<double>::infinity() : limit);
    return omegaUpper_ <= limit;
}

void DynamicSurface::rescaleOmegaBounds() {
    omegaTight_ = false;
    if (snapK_.size() == 0 || snapStructure_ != constraints_.structureVersion()) {
        omegaUpper_ = std::numeric_limits<double>::infinity();
        omegaLower_ = 0;
        return;
    }
    double kUp = 1, kDown = 1, mUp = 0, mDown = std::numeric_limits<double>::infinity();
    for (Eigen::Index s = 0; s < snapK_.size(); ++s) {
        const double r = springs_.stiffness(static_cast<int>(s)) / snapK_[s];
        kUp = std::max(kUp, r);
        kDown = std::min(kDown, r);
    }
    for (Eigen::Index i = 0; i < m_.size(); ++i) {
        const double r = m_[i] / snapM_[i];
        mUp = std::max(mUp, r);
        mDown = std::min(mDown, r);
    }
    omegaUpper_ = snapUpper_ * kUp / mDown;
    omegaLower_ = snapLower_ * kDown / mUp;
}

void DynamicSurface::computeOmegaBounds(double limit) {
    ensureMassFactor();
    const Eigen::SparseMatrix<double> A = A_.matrix().toEigen();
    const Eigen::SparseMatrix<double> K = A.transpose() * laplacian() * A;
    const Eigen::SparseMatrix<double>& M = massMatrix_;
    snapK_.resize(static_cast<Eigen::Index>(springs_.first().size()));
    for (Eigen::Index s = 0; s < snapK_.size(); ++s) snapK_[s] = springs_.stiffness(static_cast<int>(s));
    snapM_ = m_;
    snapStructure_ = constraints_.structureVersion();
    // max K_ii / M_ii is a Rayleigh quotient, so a lower bound: it rules out long steps cheaply.
    const double lower = (K.diagonal().array() / M.diagonal().array()).maxCoeff();
    if (lower > limit) {
        omegaLower_ = snapLower_ = lower;
        omegaUpper_ = snapUpper_ = std::numeric_limits<double>::infinity();
        omegaTight_ = false;
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
    omegaLower_ = snapLower_ = best;
    omegaUpper_ = snapUpper_ = 1.05 * best;
    omegaTight_ = true;
}

}  // namespace hs
