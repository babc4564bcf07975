// Walls (half-spaces the poles stay in): a stroke that pushes a patch across one stops at it, pole
// and surface, in every integrator; a pole already outside is put back at once; held poles are
// not moved; no allocation while stepping; clear errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "solvers/dynamic_surface.hpp"
#include "pulled_steps.hpp"

using namespace hs;

namespace {

constexpr int kN = 8;

/// The outer ring of an 8 x 8 net (a G0 boundary).
std::vector<int> ring() {
    std::vector<int> out;
    for (int i = 0; i < kN; ++i)
        for (int j = 0; j < kN; ++j)
            if (i == 0 || j == 0 || i == kN - 1 || j == kN - 1) out.push_back(i * kN + j);
    return out;
}

std::vector<int> allPoles() {
    std::vector<int> out(kN * kN);
    for (int i = 0; i < kN * kN; ++i) out[static_cast<std::size_t>(i)] = i;
    return out;
}

/// A 100 x 100 patch (x in -50..50) held on its ring, behind the wall x <= 50 through its edge, as
/// a box's top is behind its side (the normal unnormalised: the wall makes it unit).
std::unique_ptr<DynamicSurface> walled(IntegratorKind kind) {
    auto s = std::make_unique<DynamicSurface>(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    SolverSettings solver = s->solver();
    solver.kind = kind;
    s->setSolver(solver);
    s->setSleep({false, 1e-6, 10});
    s->holdPoles(ring());
    s->stiffnessMap().setUniform(0.05);  // (soft: a rope stroke carries it far)
    s->setWalls({PoleWall{Vec3(50, 0, 0), Vec3(2, 0, 0), allPoles()}});
    return s;
}

double largestX(const Points& p) { return p.col(0).maxCoeff(); }

}  // namespace

class PoleWallsTest : public ::testing::TestWithParam<IntegratorKind> {};

/// A rope grabbed at the centre, pulled 90 mm sideways and 20 up over 0.3 s and held; the largest x
/// any pole reached. The energy guard may refuse a step held against the wall (the wall put back
/// what the rope stretched: motion stops there, as at a wall), a few in the 600.
double pushSideways(DynamicSurface& s) {
    Cursor c;
    c.grab = true;
    s.setCursor(c);
    double reached = -1e9;
    int refused = 0;
    for (int k = 0; k < 600; ++k) {
        const double t = std::min(1.0, k / 300.0);
        c.position = Vec3(90 * t, 0, 20 * t);
        s.setCursor(c);
        const StepReport r = s.step(1e-3);
        refused += r.refused;
        reached = std::max(reached, largestX(s.poles()));
    }
    EXPECT_LE(refused, 30);
    EXPECT_TRUE(s.poles().allFinite() && s.velocities().allFinite());
    return reached;
}

TEST_P(PoleWallsTest, AStrokeAcrossAWallStopsThereAndSoDoesTheSurface) {
    const auto unwalled = walled(GetParam());
    unwalled->setWalls({});
    EXPECT_GT(pushSideways(*unwalled), 55.0);  // without it the stroke folds the patch over its edge
    const auto owner = walled(GetParam());
    DynamicSurface& s = *owner;
    EXPECT_LE(pushSideways(s), 50 + 1e-9);
    EXPECT_LE(largestX(s.mesh()), 50 + 1e-9);  // (the surface is in its poles' convex hull)
    EXPECT_GT(s.poles().col(2).maxCoeff(), 5.0);  // while it rose
}

TEST_P(PoleWallsTest, SteppingWithWallsDoesNotAllocate) {
    const auto s = walled(GetParam());
    EXPECT_EQ(allocationsWhilePulling(*s, 1e-3), 0);
}

INSTANTIATE_TEST_SUITE_P(Integrators, PoleWallsTest,
                         ::testing::Values(IntegratorKind::Explicit, IntegratorKind::ImplicitCG, IntegratorKind::LocalGlobal),
                         [](const auto& param) { return std::to_string(static_cast<int>(param.param)); });

TEST(PoleWalls, APoleOutsideIsPutBackAtOnceAndHeldPolesAreNot) {
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    s.holdPoles({0});
    const Points before = s.poles();
    s.setWalls({PoleWall{Vec3(0, 0, 0), Vec3(1, 0, 0), allPoles()}});  // x <= 0: half the net is outside
    EXPECT_EQ(s.poles().row(0), before.row(0));  // held (x = -50 anyway)
    for (int i = 1; i < kN * kN; ++i) {
        EXPECT_LE(s.poles()(i, 0), 1e-12);
        EXPECT_EQ(s.poles()(i, 1), before(i, 1));  // only across the wall
    }
    EXPECT_LE(largestX(s.mesh()), 1e-9);
    ASSERT_EQ(s.walls().size(), 1u);
    EXPECT_EQ(s.walls()[0].normal, Vec3(1, 0, 0));
    s.setWalls({});
    EXPECT_TRUE(s.walls().empty());
}

TEST(PoleWalls, BadWallsAreRefusedByName) {
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 30, 30);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (const PoleWall& bad : {PoleWall{Vec3(0, 0, 0), Vec3(0, 0, 0), {1}}, PoleWall{Vec3(nan, 0, 0), Vec3(1, 0, 0), {1}},
                                PoleWall{Vec3(0, 0, 0), Vec3(1, 0, 0), {kN * kN}}, PoleWall{Vec3(2e9, 0, 0), Vec3(1, 0, 0), {1}},
                                PoleWall{Vec3(0, 0, 0), Vec3(1, 0, 0), {-1}}}) {
        try {
            s.setWalls({bad});
            FAIL() << "accepted a bad wall";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("walls"), std::string::npos) << e.what();
        }
    }
    EXPECT_TRUE(s.walls().empty());  // (nothing half-set)
}

TEST(PoleWalls, APoleOutsideSeveralWallsGoesToTheNearestPointBehindThemAll) {
    // x <= 0, y <= 0 and x + y <= -1: from (3, 2, 5) the nearest point behind all three is (0, -1, 5),
    // on the third alone (one wall at a time would end at (-0.5, -0.5, 5), further away).
    PoleWalls walls;
    walls.set({PoleWall{Vec3(0, 0, 0), Vec3(1, 0, 0), {0}}, PoleWall{Vec3(0, 0, 0), Vec3(0, 1, 0), {0}},
               PoleWall{Vec3(-0.5, -0.5, 0), Vec3(1, 1, 0), {0}}},
              1);
    Points p(1, 3), v(1, 3);
    p << 3, 2, 5;
    v << 1, -3, 2;  // (out through x = 0, which it now touches as well as the third)
    EXPECT_TRUE(walls.project(p, v, [](int) { return false; }));
    EXPECT_LT((p.row(0) - Eigen::RowVector3d(0, -1, 5)).norm(), 1e-12) << p;
    EXPECT_LT((v.row(0) - Eigen::RowVector3d(0, -3, 2)).norm(), 1e-12) << v;  // the outward part taken out
    EXPECT_FALSE(walls.project(p, v, [](int) { return false; }));          // behind them now: nothing moves
}
