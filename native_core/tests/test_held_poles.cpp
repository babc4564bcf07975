// Held poles (hard constraints): exact in every integrator, the rest moves as if they were walls,
// G1 along a boundary from two held rows, no allocation while stepping, clear errors.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "dynamic_surface.hpp"

using namespace hs;

long allocationCount();  // test_core.cpp

namespace {

constexpr int kN = 8;  // 8 x 8 poles

/// The poles of the outer ring (rings = 1: a G0 boundary) or the two outer rings (2: G1).
std::vector<int> rings(int count) {
    std::vector<int> out;
    for (int i = 0; i < kN; ++i)
        for (int j = 0; j < kN; ++j)
            if (i < count || j < count || i >= kN - count || j >= kN - count) out.push_back(i * kN + j);
    return out;
}

struct Scheme {
    const char* name;
    IntegratorKind kind;
    int timeOrder;
    double dt;
    bool verlet;  // local/global's explicit branch expected
};

void PrintTo(const Scheme& scheme, std::ostream* os) { *os << scheme.name; }

class HeldPolesTest : public ::testing::TestWithParam<Scheme> {};

/// An 8 x 8 patch on a 30 x 30 mesh stepped by `scheme`, never sleeping.
void configure(DynamicSurface& s, const Scheme& scheme) {
    SolverSettings solver = s.solver();
    solver.kind = scheme.kind;
    solver.timeOrder = scheme.timeOrder;
    s.setSolver(solver);
    s.setSleep({false, 1e-6, 10});
}

/// A rope grabbed at the centre and pulled up 15 mm, then let go to swing.
void pull(DynamicSurface& s, double dt, int steps, bool expectVerlet) {
    Cursor c;
    c.position = Vec3(0, 0, 0);
    c.grab = true;
    for (int k = 0; k < steps; ++k) {
        if (k < steps / 2) {
            c.position.z() = 30.0 * k / steps;
        } else {
            c.grab = false;
        }
        s.setCursor(c);
        const StepReport r = s.step(dt);
        ASSERT_FALSE(r.refused) << r.reason;
        if (expectVerlet) {
            ASSERT_TRUE(r.verlet);
        }
    }
}

}  // namespace

TEST_P(HeldPolesTest, HeldPolesStayToTheBitAndTheRestMoves) {
    const Scheme setup = GetParam();
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    configure(s, setup);
    const std::vector<int> held = rings(2);
    s.holdPoles(held);
    const Points before = s.poles();
    pull(s, setup.dt, 400, setup.verlet);
    double freeMotion = 0;
    for (int i = 0; i < kN * kN; ++i) {
        const bool isHeld = std::find(held.begin(), held.end(), i) != held.end();
        if (isHeld) {
            ASSERT_EQ(s.poles().row(i), before.row(i)) << setup.name << " pole " << i;
            ASSERT_EQ(s.velocities().row(i), Vec3::Zero().transpose()) << setup.name << " pole " << i;
        } else {
            freeMotion = std::max(freeMotion, (s.poles().row(i) - before.row(i)).norm());
        }
    }
    EXPECT_GT(freeMotion, 1.0) << setup.name;
    EXPECT_TRUE(s.poles().allFinite());
    EXPECT_TRUE(std::isfinite(s.kineticEnergy()));
}

TEST_P(HeldPolesTest, TwoHeldRowsKeepTheBoundaryAndItsTangentPlanes) {
    // G1: along each edge the surface and its derivative across the edge depend only on the two
    // outer rows of a clamped B-spline, so the boundary curve and the normals along it stay.
    const Scheme setup = GetParam();
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    configure(s, setup);
    s.holdPoles(rings(2));
    const BSplineSurface start = s.surface();
    pull(s, setup.dt, 300, setup.verlet);
    double interior = 0;
    for (int k = 0; k <= 20; ++k) {
        const double t = k / 20.0;
        for (const auto& uv : {std::pair{t, 0.0}, {t, 1.0}, {0.0, t}, {1.0, t}}) {
            const SurfaceDerivatives a = start.evaluate(uv.first, uv.second, 1), b = s.surface().evaluate(uv.first, uv.second, 1);
            EXPECT_LT((a.s - b.s).norm(), 1e-12) << setup.name;
            EXPECT_LT((a.su - b.su).norm() + (a.sv - b.sv).norm(), 1e-9) << setup.name;
        }
        interior = std::max(interior, (s.surface().evaluate(t, 0.5, 0).s - start.evaluate(t, 0.5, 0).s).norm());
    }
    EXPECT_GT(interior, 1.0) << setup.name;  // while the inside was pulled
}

TEST_P(HeldPolesTest, SteppingWithHeldPolesDoesNotAllocate) {
    const Scheme setup = GetParam();
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    configure(s, setup);
    s.holdPoles(rings(1));
    Cursor c;
    c.grab = true;
    s.setCursor(c);
    s.step(setup.dt);
    s.step(setup.dt);
    const long before = allocationCount();
    for (int k = 0; k < 50; ++k) {
        c.position.z() += 0.05;
        s.setCursor(c);
        s.step(setup.dt);
    }
    EXPECT_EQ(allocationCount() - before, 0) << setup.name;
}

INSTANTIATE_TEST_SUITE_P(Integrators, HeldPolesTest,
                         ::testing::Values(Scheme{"explicit", IntegratorKind::Explicit, 2, 1e-3, false},
                                           Scheme{"implicit CG", IntegratorKind::ImplicitCG, 2, 1e-3, false},
                                           Scheme{"local/global BDF2", IntegratorKind::LocalGlobal, 2, 1e-3, false},
                                           Scheme{"local/global Euler", IntegratorKind::LocalGlobal, 1, 1e-3, false},
                                           Scheme{"local/global Verlet", IntegratorKind::LocalGlobal, 2, 2e-4, true}),
                         [](const auto& param) {
                             std::string n = param.param.name;
                             for (char& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });

TEST(HeldPoles, FreePolesAccelerateAsIfTheHeldOnesWereWalls) {
    // One explicit step from rest under a point force: the free poles' velocity is dt times the
    // solution of the mass matrix cut down to the free poles, (A_f^T M A_f) a_f = A_f^T f.
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 20, 20);
    SolverSettings solver = s.solver();
    solver.kind = IntegratorKind::Explicit;
    solver.accelerationLimit = 1e12;  // no halving: one plain step
    s.setSolver(solver);
    const std::vector<int> held = rings(1);
    s.holdPoles(held);
    const int point = s.meshIndexAt(0.3, 0.6);
    s.setPointForce(point, Vec3(0, 0, 7));
    const double dt = 1e-5;
    s.step(dt);
    // The reference, dense: only the applied force acts (the mesh is at rest, springs unstretched).
    const Eigen::MatrixXd A = Eigen::MatrixXd(s.sampling().matrix().toEigen());
    std::vector<int> free;
    for (int i = 0; i < kN * kN; ++i)
        if (std::find(held.begin(), held.end(), i) == held.end()) free.push_back(i);
    Eigen::VectorXd masses(A.rows());
    {
        // The lumped masses the core uses: the mass map's density times trapezoid weights.
        const int G = s.g(), H = s.h();
        for (int a = 0; a < G; ++a)
            for (int b = 0; b < H; ++b)
                masses[a * H + b] = s.massMap().at(static_cast<double>(a) / (G - 1), static_cast<double>(b) / (H - 1)) *
                                    ((a == 0 || a == G - 1) ? 0.5 : 1.0) / (G - 1) * ((b == 0 || b == H - 1) ? 0.5 : 1.0) / (H - 1);
    }
    Eigen::MatrixXd Af(A.rows(), static_cast<Eigen::Index>(free.size()));
    for (std::size_t k = 0; k < free.size(); ++k) Af.col(static_cast<Eigen::Index>(k)) = A.col(free[k]);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(A.rows());
    f[point] = 7;
    const Eigen::VectorXd af = (Af.transpose() * masses.asDiagonal() * Af).ldlt().solve(Af.transpose() * f);
    for (std::size_t k = 0; k < free.size(); ++k)
        EXPECT_NEAR(s.velocities()(free[k], 2), dt * af[static_cast<Eigen::Index>(k)], 1e-9 * dt * af.cwiseAbs().maxCoeff())
            << "pole " << free[k];
}

TEST(HeldPoles, NewNetsVelocitiesAndReleases) {
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 20, 20);
    s.holdPoles({0, 5, 5, 63});
    EXPECT_EQ(s.heldPoles(), (std::vector<int>{0, 5, 63}));
    // A new net (undo) holds the poles where it puts them.
    Points moved = s.poles();
    moved.row(5) += Vec3(0, 0, 3).transpose();
    s.setPoles(moved);
    Cursor c;
    c.grab = true;
    c.position = Vec3(10, 10, 5);
    s.setCursor(c);
    for (int k = 0; k < 50; ++k) s.step(1e-3);
    EXPECT_EQ(s.poles().row(5), moved.row(5));
    // Velocities given to held poles are dropped.
    Points v = Points::Constant(s.poles().rows(), 3, 1.0);
    s.setVelocities(v);
    EXPECT_EQ(s.velocities().row(63), Vec3::Zero().transpose());
    EXPECT_EQ(s.velocities().row(62), Vec3::Ones().transpose());
    // Released: they move again.
    s.holdPoles({});
    EXPECT_TRUE(s.heldPoles().empty());
    const Points before = s.poles();
    for (int k = 0; k < 50; ++k) s.step(1e-3);
    EXPECT_GT((s.poles().row(5) - before.row(5)).norm(), 0.0);
}

TEST(HeldPoles, AnIndexOutOfRangeIsRefusedByName) {
    DynamicSurface s(BSplineSurface::plane(4, 4, 3, 3, 100, 100), 10, 10);
    try {
        s.holdPoles({3, 16});
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("indices: pole index 16 outside 0..15"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(s.heldPoles().empty());  // nothing changed
}
