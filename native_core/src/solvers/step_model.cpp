#include "solvers/step_model.hpp"

#include <stdexcept>
#include <vector>

namespace hs {

Scratch::Scratch(Eigen::Index meshPoints, Eigen::Index poles) {
    for (Points* m : {&meshVelocity, &mesh, &mesh2}) m->setZero(meshPoints, 3);
    for (Points* m : {&poleForce, &poleStep}) m->setZero(poles, 3);
}

Eigen::SparseMatrix<double> StepModel::laplacian() const {
    std::vector<Eigen::Triplet<double>> t;
    material.springs.addLaplacian(t);
    forces.constraints().addLaplacian(t);
    material.bending.addMatrix(t);
    Eigen::SparseMatrix<double> L(state.d.rows(), state.d.rows());
    L.setFromTriplets(t.begin(), t.end());
    return L;
}

void StepModel::ensureMass() {
    // (mass and held-set versions only grow, so their sum changes whenever either does)
    const std::uint64_t version = material.massMap.version() + held.version();
    if (systems.massCurrent(version)) return;
    const Eigen::SparseMatrix<double> A = state.A.matrix().toEigen();
    Eigen::SparseMatrix<double> m = A.transpose() * material.masses().asDiagonal() * A;
    held.restrict(m, true);
    systems.setMass(std::move(m), version);
}

void StepModel::ensureSystem(double dt, bool factor) {
    const SystemCache::Key key = {material.massMap.version(), material.dampingMap.version(),
                                  material.stiffnessMap.version(), structureKey(), material.bendingMap.version()};
    if (systems.use(dt, factor, key)) return;
    // Rebuild the slot used least recently. S = A^T (M + dt D + dt^2 L) A with L the Laplacian of
    // springs and penalty terms and the bending matrix K_b.
    SystemCache::Slot& slot = systems.replace();
    Eigen::SparseMatrix<double> D(state.d.rows(), state.d.rows());
    D = (material.masses() + dt * material.damping()).asDiagonal();
    const Eigen::SparseMatrix<double> Sm = D + (dt * dt) * laplacian();
    const Eigen::SparseMatrix<double> A = state.A.matrix().toEigen();
    Eigen::SparseMatrix<double> sys = A.transpose() * Sm * A;
    held.restrict(sys, true);
    slot.invDiag = sys.diagonal().cwiseInverse();  // Jacobi preconditioner
    slot.matrix = sys;  // (regions cut theirs from it)
    if (factor) {
        ensureMass();  // throws first if the mesh does not see every control point
        try {
            slot.solver.factor(sys, "system matrix A^T (M + dt D + dt^2 L) A");
        } catch (const std::runtime_error&) {
            // The mass matrix factors, so only dt^2 L (singular: free translations) can swamp it.
            throw std::invalid_argument("dt: too long for this mass and stiffness (dt^2 x stiffness / mass swamps the "
                                        "mass matrix and the system is numerically singular); use a shorter step");
        }
    }
    systems.built(dt, factor, key);
}

void StepModel::ensureStepSystem(double dt) {
    if (region.whole) {
        ensureSystem(dt, true);
        regionSystem = nullptr;
        return;
    }
    ensureSystem(dt, false);
    regionSystem = &systems.region(region.poles);
}

void StepModel::solveSystem(const Points& b, Points& x) {
    if (!regionSystem) return systems.current().solver.solve(b, x);
    SystemCache::RegionSlot& r = *regionSystem;
    Eigen::Index k = 0;
    region.poles.forRuns([&](Eigen::Index first, Eigen::Index n) { r.b.middleRows(k, n) = b.middleRows(first, n); k += n; });
    r.solver.solve(r.b, r.x);
    k = 0;
    region.poles.forRuns([&](Eigen::Index first, Eigen::Index n) { x.middleRows(first, n) = r.x.middleRows(k, n); k += n; });
}

double StepModel::acceleration(Points& acc) {
    Points& dd = scratch.meshVelocity;
    state.A.apply(state.v, dd);
    const double energy = forces.all(material, state.d, dd) + 0.5 * (material.masses().asDiagonal() * dd).cwiseProduct(dd).sum();
    state.A.applyTransposed(forces.total(), scratch.poleForce);
    held.reduce(scratch.poleForce);
    systems.mass().solve(scratch.poleForce, acc);
    held.expand(acc);
    return energy;
}

}  // namespace hs
