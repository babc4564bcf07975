// The pull toward a scan (data springs): a plate settles onto a scanned plane in every integrator;
// it is not pulled past the scan's edge, beyond its reach, or where the pull map is 0; any strength
// stays finite and bounded; a run is bit-identical; stepping allocates nothing; clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "solvers/dynamic_surface.hpp"
#include "pulled_steps.hpp"

using namespace hs;

namespace {

/// A grid of points z = height over x, y in [x0, x1] x [-60, 60] (a scan of a plane).
std::shared_ptr<PointTree> scanOfPlane(double height, double x0 = -60, double x1 = 60) {
    const int n = 121;
    Points p(n * n, 3);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            p.row(i * n + j) << x0 + (x1 - x0) * i / (n - 1), -60 + 120.0 * j / (n - 1), height;
    return std::make_shared<PointTree>(p);
}

/// A 100 x 100 plate (x, y in -50..50) on a 24 x 24 mesh, pulled toward `tree`.
std::unique_ptr<DynamicSurface> pulled(std::shared_ptr<PointTree> tree, IntegratorKind kind = IntegratorKind::LocalGlobal,
                                       double strength = 1.0) {
    auto s = std::make_unique<DynamicSurface>(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 24, 24);
    SolverSettings solver = s->solver();
    solver.kind = kind;
    s->setSolver(solver);
    s->setPullTarget(std::move(tree), 20.0);
    s->setPull(true, strength);
    return s;
}

double meanZ(const DynamicSurface& s) { return s.mesh().col(2).mean(); }

}  // namespace

TEST(DataSprings, APlateSettlesOntoTheScannedPlaneInEveryIntegrator) {
    for (IntegratorKind kind : {IntegratorKind::LocalGlobal, IntegratorKind::ImplicitCG, IntegratorKind::Explicit}) {
        auto s = pulled(scanOfPlane(5.0), kind);
        const double dt = kind == IntegratorKind::Explicit ? 1e-4 : 1e-3;
        for (int k = 0; k < static_cast<int>(0.4 / dt); ++k) ASSERT_FALSE(s->step(dt).refused);
        EXPECT_NEAR(s->mesh().col(2).minCoeff(), 5.0, 1e-3) << static_cast<int>(kind);
        EXPECT_NEAR(s->mesh().col(2).maxCoeff(), 5.0, 1e-3) << static_cast<int>(kind);
        EXPECT_EQ(s->pull().anchored(), 24 * 24);
    }
}

TEST(DataSprings, NothingPullsPastTheScansEdgeBeyondReachOrWhereTheMapIsZero) {
    // The scan covers x >= 10 only: the points over x < 0 find its edge off to the side.
    auto half = pulled(scanOfPlane(3.0, 10, 60));
    for (int k = 0; k < 300; ++k) half->step(1e-3);
    const Eigen::Index anchored = half->pull().anchored();
    EXPECT_GT(anchored, 24 * 24 / 4);
    EXPECT_LT(anchored, 24 * 24 * 2 / 3);
    // Beyond reach (20 mm): no spring at all, the plate stays where it is and falls asleep.
    auto far = pulled(scanOfPlane(25.0));
    for (int k = 0; k < 300; ++k) far->step(1e-3);
    EXPECT_EQ(far->pull().anchored(), 0);
    EXPECT_EQ(meanZ(*far), 0.0);
    // The map at 0 everywhere: anchored, but no force.
    auto off = pulled(scanOfPlane(5.0));
    off->pullMap().setUniform(0.0);
    for (int k = 0; k < 300; ++k) off->step(1e-3);
    EXPECT_EQ(meanZ(*off), 0.0);
    EXPECT_EQ(off->externalForces().cwiseAbs().maxCoeff(), 0.0);
    // Switched off: the same.
    auto stopped = pulled(scanOfPlane(5.0));
    stopped->setPull(false, 1.0);
    for (int k = 0; k < 300; ++k) stopped->step(1e-3);
    EXPECT_EQ(meanZ(*stopped), 0.0);
}

TEST(DataSprings, AnyStrengthAndStepStaysFiniteAndBounded) {
    for (double strength : {1e-6, 1.0, 1e3, 1e6})
        for (double dt : {1e-5, 1e-3, 2e-2}) {
            auto s = pulled(scanOfPlane(5.0), IntegratorKind::LocalGlobal, strength);
            for (int k = 0; k < 200; ++k) {
                s->step(dt);
                ASSERT_TRUE(s->poles().allFinite());
            }
            // Never past the scan by more than the plate's own overshoot, and at rest at the end
            // for the strong pulls (critically damped).
            EXPECT_LT(s->mesh().col(2).maxCoeff(), 5.0 * 1.5) << strength << " " << dt;
            EXPECT_GT(s->mesh().col(2).minCoeff(), -1e-9) << strength << " " << dt;
            EXPECT_TRUE(std::isfinite(s->kineticEnergy()));
        }
}

TEST(DataSprings, ARunIsBitIdenticalAndAllocatesNothingPerStep) {
    auto a = pulled(scanOfPlane(4.0)), b = pulled(scanOfPlane(4.0));
    for (int k = 0; k < 120; ++k) {
        a->step(1e-3);
        b->step(1e-3);
    }
    EXPECT_TRUE(a->poles() == b->poles());
    auto c = pulled(scanOfPlane(4.0));
    EXPECT_EQ(allocationsWhilePulling(*c, 1e-3, Vec3(0, 0, 0.1)), 0);
}

TEST(DataSprings, BadSettingsAreRefusedByName) {
    auto s = pulled(scanOfPlane(1.0));
    EXPECT_THROW(s->setPull(true, -1.0), std::invalid_argument);
    EXPECT_THROW(s->setPull(true, std::nan("")), std::invalid_argument);
    EXPECT_THROW(s->setPullTarget(scanOfPlane(1.0), 0.0), std::invalid_argument);
    EXPECT_THROW(s->pullMap().setUniform(-1.0), std::invalid_argument);
    s->setPullTarget(nullptr, 0.0);  // (no target: no reach needed)
    EXPECT_FALSE(s->pull().active());
}
