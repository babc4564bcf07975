// C++ tests of the core: basis, prefactored solve, allocation-free stepping, reactions.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <algorithm>
#include <cstdlib>
#include <new>

#include "solvers/dynamic_surface.hpp"
#include "pulled_steps.hpp"

// Counts heap allocations so a test can assert that stepping allocates nothing. Every form of
// operator new and delete is replaced, all on one allocator (malloc/free; Windows: _aligned_*): a library that allocates with one form
// and frees with another (GCC 14's std::stable_sort: nothrow new, then sized delete) must meet a
// matching pair, or AddressSanitizer reports an alloc-dealloc mismatch. GCC 12 with LTO inlines
// these replacements and then mistakes the malloc/free pairing for a mismatch.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
static std::atomic<long> g_allocations{0};
namespace {
#ifdef _WIN32  // (no aligned_alloc on Windows: every block from _aligned_malloc, freed by _aligned_free)
void* allocate(std::size_t n, std::size_t align) { return _aligned_malloc(n, std::max(align, alignof(std::max_align_t))); }
void release(void* p) { _aligned_free(p); }
#else
void* allocate(std::size_t n, std::size_t align) {
    if (align <= alignof(std::max_align_t)) return std::malloc(n);
    return std::aligned_alloc(align, (n + align - 1) / align * align);  // (a multiple of the alignment)
}
void release(void* p) { std::free(p); }
#endif
void* counted(std::size_t n, std::size_t align = 0) noexcept {
    ++g_allocations;
    return allocate(n == 0 ? 1 : n, align);
}
void* countedOrThrow(std::size_t n, std::size_t align = 0) {
    if (void* p = counted(n, align)) return p;
    throw std::bad_alloc();
}
}  // namespace
void* operator new(std::size_t n) { return countedOrThrow(n); }
void* operator new[](std::size_t n) { return countedOrThrow(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return counted(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return counted(n); }
void* operator new(std::size_t n, std::align_val_t a) { return countedOrThrow(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return countedOrThrow(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return counted(n, static_cast<std::size_t>(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return counted(n, static_cast<std::size_t>(a));
}
void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
long allocationCount() { return g_allocations.load(); }  // for the other test files

using namespace hs;

TEST(KnotVector, BasisIsPartitionOfUnityWithMatchingDerivatives) {
    for (int p = 1; p <= kMaxDegree; ++p) {
        std::vector<double> k(static_cast<size_t>(p + 1), 0.0);
        if (p >= 2) k.push_back(0.2);  // a double knot where the degree allows it
        for (double x : {0.2, 0.5, 0.7}) k.push_back(x);
        for (int i = 0; i <= p; ++i) k.push_back(1.0);
        const int n = static_cast<int>(k.size()) - p - 1;
        KnotVector kv(k, n, p, "knots");
        for (double t = 0; t <= 1.0; t += 0.0625) {
            Eigen::Matrix<double, 3, kMaxDegree + 1> d;
            kv.basis(t, 2, d);
            EXPECT_NEAR(d.row(0).sum(), 1.0, 1e-14);
            EXPECT_NEAR(d.row(1).sum(), 0.0, 1e-11);
        }
    }
}

TEST(KnotVector, ValidationNamesTheArgument) {
    EXPECT_THROW(KnotVector({0, 0, 1, 1}, 3, 1, "knots_u"), std::invalid_argument);
    try {
        KnotVector({0, 0, 0, 0, 0.5, 0.5, 0.5, 0.5, 1, 1, 1, 1}, 8, 3, "knots_v");
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("knots_v"), std::string::npos);
    }
}

TEST(PrefactoredSolver, MatchesEigenSolve) {
    DynamicSurface s(BSplineSurface::plane(9, 7, 3, 2, 50, 30), 20, 15);
    const Eigen::SparseMatrix<double> A = s.sampling().matrix().toEigen();
    Eigen::SparseMatrix<double> M = A.transpose() * A;
    for (int i = 0; i < M.rows(); ++i) M.coeffRef(i, i) += 0.1 * (i % 5 + 1);
    PrefactoredSolver solver;
    solver.factor(M, "test");
    Points b = Points::Random(M.rows(), 3), x(M.rows(), 3);
    solver.solve(b, x);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ref(M);
    const Eigen::MatrixXd expect = ref.solve(Eigen::MatrixXd(b));
    EXPECT_LT((Eigen::MatrixXd(x) - expect).cwiseAbs().maxCoeff(), 1e-10);
}

namespace {
/// A bicubic net's system-like matrix (A^T A plus a varying diagonal) on g x h poles, and a
/// reference solve of it.
Eigen::SparseMatrix<double> netSystem(int g, int h) {
    DynamicSurface s(BSplineSurface::plane(g, h, 3, 3, 50, 30), 3 * g, 3 * h);
    const Eigen::SparseMatrix<double> A = s.sampling().matrix().toEigen();
    Eigen::SparseMatrix<double> M = A.transpose() * A;
    for (int i = 0; i < M.rows(); ++i) M.coeffRef(i, i) += 0.1 * (i % 5 + 1);
    return M;
}
double solveError(const PrefactoredSolver& solver, const Eigen::SparseMatrix<double>& M) {
    Points b = Points::Random(M.rows(), 3), x(M.rows(), 3);
    solver.solve(b, x);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ref(M);
    return (Eigen::MatrixXd(x) - ref.solve(Eigen::MatrixXd(b))).cwiseAbs().maxCoeff();
}
}  // namespace

TEST(PrefactoredSolver, ANetRowByRowIsSolvedAsABand) {
    // 30 x 30 poles: a band of 3 x 30 + 3 below the diagonal, about AMD's fill.
    const Eigen::SparseMatrix<double> M = netSystem(30, 30);
    PrefactoredSolver solver;
    solver.factor(M, "test");
    EXPECT_EQ(solver.kind(), PrefactoredSolver::Kind::Band);
    EXPECT_EQ(solver.entriesRead(), 900 * 93);
    EXPECT_LT(solveError(solver, M), 1e-10);
}

TEST(PrefactoredSolver, AMatrixCouplingDistantUnknownsKeepsTheSparseFactor) {
    // The same net with its first pole tied to its last (as a curve's links can tie distant
    // poles): the band would span the whole matrix; AMD's factor barely grows.
    Eigen::SparseMatrix<double> M = netSystem(30, 30);
    const int n = static_cast<int>(M.rows());
    M.coeffRef(n - 1, 0) += 0.01;
    M.coeffRef(0, n - 1) += 0.01;
    PrefactoredSolver solver;
    solver.factor(M, "test");
    EXPECT_EQ(solver.kind(), PrefactoredSolver::Kind::Sparse);
    EXPECT_LT(solveError(solver, M), 1e-10);
}

TEST(PrefactoredSolver, AnIndefiniteBandIsRefused) {
    Eigen::SparseMatrix<double> M = netSystem(30, 30);
    M.coeffRef(450, 450) = -1.0;
    PrefactoredSolver solver;
    EXPECT_THROW(solver.factor(M, "test"), std::runtime_error);
    EXPECT_FALSE(solver.ready());
}

TEST(PrefactoredSolver, RejectsSingularMatrix) {
    Eigen::SparseMatrix<double> m(3, 3);
    m.insert(0, 0) = 1;
    m.insert(1, 1) = 1;
    PrefactoredSolver solver;
    EXPECT_ANY_THROW(solver.factor(m, "test"));
}

TEST(SamplingOperator, SamplesOnKnotsKeepNoVanishingBasisEntries) {
    // Degree-1 poles sampled exactly at their knots: A is the identity, and the matrix the solvers
    // factor must not carry the basis functions that vanish there (they tripled the solve's fill).
    const BSplineSurface plane = BSplineSurface::plane(9, 7, 1, 1, 100, 100);
    const SamplingOperator a(plane, 9, 7);
    const Eigen::SparseMatrix<double> m = a.matrix().toEigen();
    EXPECT_EQ(m.nonZeros(), 9 * 7);
    for (int k = 0; k < m.outerSize(); ++k)
        for (Eigen::SparseMatrix<double>::InnerIterator it(m, k); it; ++it) EXPECT_NEAR(it.value(), 1.0, 1e-12);
}

class AllocationFree : public ::testing::TestWithParam<IntegratorKind> {};

// Steps a patch with a grabbed rope, a point and a normal constraint (penalty stiffness `penalty`),
// plasticity, a painted stiffness map and an external force, moving the cursor each step; returns
// the allocations made after two warm-up steps (factorisations, bounds and first-use buffers),
// and checks every step against `check`.
template <class Check>
long allocationsWhileSculpting(DynamicSurface& s, double penalty, double dt, Check check) {
    s.setSleep({false, 1e-6, 10});
    s.constraints().add(ConstraintKind::Point, 40, penalty, s.mesh(), nullptr, nullptr, nullptr);
    s.constraints().add(ConstraintKind::Normal, 300, penalty, s.mesh(), nullptr, nullptr, nullptr);
    s.setPlasticity({true, 0.05, 1.0});
    s.stiffnessMap().dab(0.5, 0.5, 0.2, 50.0, Falloff::Conical, 1.0);
    Cursor c;
    c.position = Vec3(1, 2, 3);
    c.grab = true;
    s.setCursor(c);
    s.setPointForce(100, Vec3(0, 0, 5));
    s.step(dt);
    s.step(dt);
    const long before = g_allocations.load();
    for (int i = 0; i < 50; ++i) {
        c.position.z() += 0.05;
        s.setCursor(c);
        check(s.step(dt));
    }
    return g_allocations.load() - before;
}

TEST_P(AllocationFree, SteppingWithToolConstraintsAndLawsDoesNotAllocate) {
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
    { SolverSettings solver = s.solver(); solver.kind = GetParam(); s.setSolver(solver); }
    s.setStiffnessLaw({LawKind::Saturating, 50.0});
    s.setDampingLaw({LawKind::CubicHardening, 10.0});
    EXPECT_EQ(allocationsWhileSculpting(s, 1e4, 1e-3, [](const StepReport& r) { ASSERT_FALSE(r.refused); }), 0);
}

TEST_P(AllocationFree, SteppingWithBendingDoesNotAllocate) {
    // The bending energy (a painted map, clay's reference following the plastic flow) in every scheme.
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
    { SolverSettings solver = s.solver(); solver.kind = GetParam(); s.setSolver(solver); }
    s.bendingMap().setUniform(10.0);
    s.bendingMap().dab(0.3, 0.6, 0.2, 40.0, Falloff::Spherical, 1.0);
    EXPECT_EQ(allocationsWhileSculpting(s, 1e4, 1e-3, [](const StepReport& r) { ASSERT_FALSE(r.refused); }), 0);
    EXPECT_GT(s.bending().energy(s.mesh()), 0.0);
}

TEST(CurvatureConstraint, BeatsThePlateItBendsAndFollowsTheBendingMap) {
    // A plate of bending ratio 10 held a curvature constraint 39 % short of its target with the
    // springs' penalty alone; the penalty now grows with the bending ratio at its point.
    auto settle = [](double bending) {
        DynamicSurface s(BSplineSurface::plane(10, 10, 3, 3, 100, 100), 21, 21);
        s.dampingMap().setUniform(30.0);
        s.bendingMap().setUniform(bending);
        const int p = s.meshIndexAt(0.5, 0.5);
        const double kappa = 0.02;
        const int id = s.constraints().add(ConstraintKind::Curvature, p, s.defaultConstraintStiffness(), s.mesh(),
                                           nullptr, &kappa, &kappa);
        for (int i = 0; i < 3000; ++i) s.step(1e-3);
        const Constraint& c = s.constraints().get(id);
        return std::make_pair(s.constraints().error(c, s.mesh()), s.constraints().effectiveStiffness(c) / c.stiffness);
    };
    const auto [springs, one] = settle(0.0);
    const auto [plate, scale] = settle(10.0);
    EXPECT_LT(springs, 0.01);
    EXPECT_LT(plate, 0.01);
    EXPECT_DOUBLE_EQ(one, 1.0);
    EXPECT_DOUBLE_EQ(scale, 1.0 + ConstraintSet::kCurvatureBendingGain * 10.0);
    // A repainted map takes effect at once (a new structure: the system refactors), and a huge
    // one is capped.
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 20, 20);
    const double kappa = 0.01;
    const int id = s.constraints().add(ConstraintKind::Curvature, s.meshIndexAt(0.5, 0.5), 5.0, s.mesh(), nullptr,
                                       &kappa, &kappa);
    s.step(1e-3);
    const auto version = s.constraints().structureVersion();
    s.bendingMap().setUniform(1e6);  // (30 x 1e6 > the cap)
    s.step(1e-3);
    EXPECT_GT(s.constraints().structureVersion(), version);
    EXPECT_DOUBLE_EQ(s.constraints().effectiveStiffness(s.constraints().get(id)), 5.0 * ConstraintSet::kMaxCurvatureScale);
    EXPECT_TRUE(s.poles().allFinite());
}

TEST(Fair, RelaxesWavesAndKeepsHeldPolesExactly) {
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 24, 24);
    Points p = s.poles();
    for (int i = 1; i < 7; ++i)
        for (int j = 1; j < 7; ++j) p(i * 8 + j, 2) = ((i + j) % 2 ? 2.0 : -2.0) + 0.5 * i;  // waves on a slope
    s.setPoles(p);
    s.holdPoles({0, 7, 56, 63, 27});
    auto variation = [&] {  // squared third differences of the mesh along u
        double e = 0;
        for (int a = 0; a + 3 < s.g(); ++a)
            for (int b = 0; b < s.h(); ++b)
                e += (s.mesh().row((a + 3) * s.h() + b) - 3 * s.mesh().row((a + 2) * s.h() + b) +
                      3 * s.mesh().row((a + 1) * s.h() + b) - s.mesh().row(a * s.h() + b)).squaredNorm();
        return e;
    };
    const double before = variation();
    const Points held = s.poles();
    s.fair(Eigen::VectorXd::Ones(24 * 24), 10.0);
    EXPECT_LT(variation(), 0.5 * before);
    for (int i : {0, 7, 56, 63, 27}) EXPECT_EQ(s.poles().row(i), held.row(i)) << i;
    EXPECT_THROW(s.fair(Eigen::VectorXd::Ones(3), 1.0), std::invalid_argument);
    EXPECT_THROW(s.fair(Eigen::VectorXd::Ones(24 * 24), -1.0), std::invalid_argument);
}

TEST(Verlet, SteppingWithBendingDoesNotAllocate) {
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
    s.bendingMap().setUniform(10.0);
    const double dt = 0.5 * s.verletStepLimit();
    ASSERT_GT(dt, 0.0);
    EXPECT_EQ(allocationsWhileSculpting(s, 1.0, dt, [](const StepReport& r) {
                  ASSERT_TRUE(r.verlet);
                  ASSERT_FALSE(r.refused);
              }), 0);
}

TEST(Verlet, SteppingWithToolConstraintsForcesAndPlasticityDoesNotAllocate) {
    // Local/global's explicit branch on a soft patch (linear laws: the only ones it takes).
    DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
    const double dt = 2e-4;
    ASSERT_GT(s.verletStepLimit(), dt);
    EXPECT_EQ(allocationsWhileSculpting(s, 1.0, dt, [](const StepReport& r) {
                  ASSERT_TRUE(r.verlet);
                  ASSERT_FALSE(r.refused);
              }), 0);
}

TEST(Prepare, TheFirstStepAfterItDoesNotAllocate) {
    // What a session does before its clock starts: the first real-time step then factors nothing.
    for (const double dt : {2e-4, 1e-3}) {  // a Verlet step and an implicit one
        DynamicSurface fresh(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
        fresh.stiffnessMap().setUniform(2e3);
        fresh.prepare(dt);
        const long before = g_allocations.load();
        const StepReport r = fresh.step(dt);
        EXPECT_EQ(g_allocations.load() - before, 0) << dt;
        EXPECT_EQ(r.verlet, dt < 5e-4) << dt;
    }
    DynamicSurface s(BSplineSurface::plane(4, 4, 3, 3, 100, 100), 10, 10);
    EXPECT_THROW(s.prepare(0.0), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(Integrators, AllocationFree,
                         ::testing::Values(IntegratorKind::Explicit, IntegratorKind::ImplicitCG, IntegratorKind::LocalGlobal));

TEST(Tools, EveryToolStepsWithoutAllocating) {
    for (const std::string& name : toolNames()) {
        DynamicSurface s(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 30, 30);
        s.setSleep({false, 1e-6, 10});
        s.setTool(name);
        EXPECT_EQ(allocationsWhilePulling(s, 1e-3, Vec3(1, 2, 0.5)), 0) << name;
    }
}

TEST(Tools, ReactionIsMinusTheForceOnTheSurface) {
    for (const std::string& name : toolNames()) {
        DynamicSurface s(BSplineSurface::plane(6, 6, 3, 3, 40, 40), 15, 15);
        Points f = Points::Zero(s.mesh().rows(), 3);
        auto tool = makeTool(name);
        Cursor c;
        c.position = Vec3(3, -2, 4);
        c.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitX()));
        MeshView view{s.mesh(), 15, 15, 40.0 / 14, 40.0 / 14};
        tool->grab(view, c);
        c.position.z() += 20;
        const Reaction r = tool->apply(view, c, 0.5, f);
        const Vec3 total = f.colwise().sum().transpose();
        EXPECT_LT((total + r.force).norm(), 1e-12 * (1 + total.norm())) << name;
    }
}
