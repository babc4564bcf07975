// Held poles (hard constraints): exact in every integrator, the rest moves as if they were walls,
// G1 along a boundary from two held rows, no allocation while stepping, clear errors.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "solvers/dynamic_surface.hpp"
#include "pulled_steps.hpp"

using namespace hs;


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
    EXPECT_EQ(allocationsWhilePulling(s, setup.dt), 0) << setup.name;
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

namespace {

/// Two patches joined along u = 0.5 (a knot of full multiplicity: C0 there), 7 x 8 poles, the
/// seam's pole row 3. Linking each seam pole to the mean of its neighbours across the seam keeps
/// the tangent plane continuous (G1).
std::unique_ptr<DynamicSurface> twoPatches() {
    const BSplineSurface flat = BSplineSurface::plane(7, 8, 3, 3, 100, 80);
    BSplineSurface joined(7, 8, 3, 3, {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1}, clampedUniformKnots(8, 3), flat.poles(), {});
    Points poles = flat.poles();  // Greville spacing of the joined knots: even in u
    for (int i = 0; i < 7; ++i)
        for (int j = 0; j < 8; ++j) poles(i * 8 + j, 0) = (std::array<double, 7>{0, 1, 2, 3, 4, 5, 6}[i] / 6.0 - 0.5) * 100;
    joined.mutablePoles() = poles;
    return std::make_unique<DynamicSurface>(joined, 31, 24);
}

std::vector<int> outerRing() {
    std::vector<int> out;
    for (int i = 0; i < 7; ++i)
        for (int j = 0; j < 8; ++j)
            if (i == 0 || i == 6 || j == 0 || j == 7) out.push_back(i * 8 + j);
    return out;
}

std::vector<PoleLink> seamLinks() {
    std::vector<PoleLink> links;
    for (int j = 1; j < 7; ++j) links.push_back({3 * 8 + j, {{2 * 8 + j, 0.5}, {4 * 8 + j, 0.5}}});
    return links;
}

/// Largest angle (radians) between the derivatives across the seam from its two sides.
double seamKink(const BSplineSurface& s) {
    double worst = 0;
    for (int k = 0; k <= 20; ++k) {
        const double v = k / 20.0;
        const Vec3 a = s.evaluate(0.5 - 1e-12, v, 1).su, b = s.evaluate(0.5 + 1e-12, v, 1).su;
        worst = std::max(worst, std::atan2(a.cross(b).norm(), a.dot(b)));
    }
    return worst;
}

}  // namespace

TEST_P(HeldPolesTest, LinkedPolesKeepTheTangentPlaneAcrossASeam) {
    const Scheme setup = GetParam();
    for (bool linked : {true, false}) {
        auto made = twoPatches();
        DynamicSurface& s = *made;
        configure(s, setup);
        s.holdPoles(outerRing(), linked ? seamLinks() : std::vector<PoleLink>{});
        Cursor c;
        c.position = Vec3(-20, 0, 0);  // on the left patch, near the seam
        c.grab = true;
        for (int k = 0; k < 300; ++k) {
            c.position.z() = std::min(15.0, 0.1 * k);
            s.setCursor(c);
            const StepReport r = s.step(setup.dt);
            ASSERT_FALSE(r.refused) << setup.name << ": " << r.reason;
        }
        if (!linked) {
            EXPECT_GT(seamKink(s.surface()), 1e-3) << setup.name << ": without links the seam kinks (the test can fail)";
            continue;
        }
        EXPECT_LT(seamKink(s.surface()), 1e-9) << setup.name;  // (rounding of the derivatives)
        for (int j = 1; j < 7; ++j) {
            Vec3 mean = Vec3::Zero();
            mean += 0.5 * s.poles().row(2 * 8 + j).transpose();
            mean += 0.5 * s.poles().row(4 * 8 + j).transpose();
            EXPECT_EQ(s.poles().row(3 * 8 + j), mean.transpose()) << setup.name;
        }
        EXPECT_GT(s.poles()(3 * 8 + 4, 2), 1.0) << setup.name << ": the seam moved with the stroke";
    }
}

// A curve the surface must pass through is an affine condition A P = B: linked poles with an offset.
TEST_P(HeldPolesTest, LinkedPolesWithAnOffsetKeepTheirConditionExactly) {
    const Scheme setup = GetParam();
    auto made = twoPatches();
    DynamicSurface& s = *made;
    configure(s, setup);
    std::vector<PoleLink> links = seamLinks();
    for (PoleLink& l : links) l.offset = Vec3(0.0, 0.25, 2.0);
    s.holdPoles(outerRing(), links);
    for (const PoleLink& l : links)  // put there at once
        EXPECT_NEAR(s.poles()(l.pole, 2), 0.5 * (s.poles()(l.pole - 8, 2) + s.poles()(l.pole + 8, 2)) + 2.0, 1e-12);
    Cursor c;
    c.position = Vec3(-20, 0, 0);
    c.grab = true;
    for (int k = 0; k < 1000; ++k) {
        c.position.z() = std::min(15.0, 0.1 * k);
        s.setCursor(c);
        const StepReport r = s.step(setup.dt);
        ASSERT_FALSE(r.refused) << setup.name << ": " << r.reason;
        ASSERT_TRUE(s.poles().allFinite()) << setup.name;
    }
    for (const PoleLink& l : links) {
        Vec3 p = l.offset;
        for (const auto& [m, w] : l.masters) p += w * s.poles().row(m).transpose();
        EXPECT_EQ(s.poles().row(l.pole), p.transpose()) << setup.name;
    }
    EXPECT_GT(s.poles()(3 * 8 + 4, 2), 3.0) << setup.name << ": the linked poles moved with the stroke";
}

TEST_P(HeldPolesTest, SteppingWithLinkedPolesDoesNotAllocate) {
    const Scheme setup = GetParam();
    auto made = twoPatches();
    DynamicSurface& s = *made;
    configure(s, setup);
    s.holdPoles(outerRing(), seamLinks());
    EXPECT_EQ(allocationsWhilePulling(s, setup.dt), 0) << setup.name;
}

TEST(HeldPoles, BadLinksAreRefusedByName) {
    auto made = twoPatches();
    DynamicSurface& s = *made;
    const std::vector<std::pair<std::vector<PoleLink>, std::string>> cases = {
        {{{99, {{1, 1.0}}}}, "links: pole 99 outside"},
        {{{0, {{1, 1.0}}}}, "links: pole 0 is held"},
        {{{26, {{1, 1.0}}}, {26, {{2, 1.0}}}}, "links: pole 26 is linked twice"},
        {{{26, {}}}, "links: pole 26 has no masters"},
        {{{26, {{26, 1.0}}}}, "master 26 is not another pole"},
        {{{26, {{27, 1.0}}}, {27, {{28, 1.0}}}}, "master 27 is linked itself"},
        {{{26, {{27, std::nan("")}}}}, "weights must be finite"},
        {{{26, {{27, 1.0}}, Vec3(0, std::nan(""), 0)}}, "offset must be finite"},
    };
    for (const auto& [links, text] : cases) {
        try {
            s.holdPoles({0}, links);
            ADD_FAILURE() << "no error, expected " << text;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(s.heldPoles().empty());
    EXPECT_TRUE(s.linkedPoles().empty());
}
