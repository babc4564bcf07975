// The flatten tool: the region it grabs is pressed flat (onto the plane tangent where it grabs, at
// the region's mean height), as much down as up, and nothing outside its radius is pushed; the plane
// follows the cursor along the normal only; its falloff weights.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>
#include <memory>
#include <utility>

#include "solvers/dynamic_surface.hpp"

using namespace hs;

namespace {

/// A 100 mm patch (8 x 8 poles, 31 x 31 mesh: one point on the summit) with a 12 mm round bump
/// around the middle, at rest, its edges held (a free sheet would rise whole under the tool's net pull).
std::unique_ptr<DynamicSurface> bumpedPatch() {
    auto patch = std::make_unique<DynamicSurface>(BSplineSurface::plane(8, 8, 3, 3, 100, 100), 31, 31);
    DynamicSurface& s = *patch;
    Points p = s.poles();
    for (Eigen::Index k = 0; k < p.rows(); ++k) {
        const double r2 = p(k, 0) * p(k, 0) + p(k, 1) * p(k, 1);
        p(k, 2) = 12.0 * std::exp(-r2 / (2 * 15.0 * 15.0));
    }
    s.setPoles(p);
    s.relax();  // the bump is the rest shape: only the tool flattens it
    std::vector<int> edge;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            if (i == 0 || j == 0 || i == 7 || j == 7) edge.push_back(i * 8 + j);
    s.holdPoles(edge);
    s.setSleep({false, 1e-6, 10});
    return patch;
}

/// How far from flat the mesh is within `radius` (in plan) of the middle: the RMS of the heights
/// about their mean.
double unevenness(const Points& d, double radius) {
    double sum = 0, sum2 = 0;
    int n = 0;
    for (Eigen::Index k = 0; k < d.rows(); ++k)
        if (std::hypot(d(k, 0), d(k, 1)) < radius) {
            sum += d(k, 2);
            sum2 += d(k, 2) * d(k, 2);
            ++n;
        }
    return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
}

int nearestTo(const Points& d, const Vec3& x) { return nearestPoint(d, x); }

}  // namespace

TEST(FlattenTool, PressesTheRegionFlatAsMuchDownAsUp) {
    auto patch = bumpedPatch();
    DynamicSurface& s = *patch;
    s.setTool("flatten");
    s.tool().set("radius", 25);
    s.tool().set("stiffness", 50);
    const int top = nearestTo(s.mesh(), Vec3(0, 0, 12));
    const double summit = s.mesh()(top, 2), before = unevenness(s.mesh(), 15);
    Cursor c;
    c.position = s.mesh().row(top).transpose();
    c.grab = true;
    s.setCursor(c);
    for (int k = 0; k < 1000; ++k) ASSERT_FALSE(s.step(5e-4).refused);
    EXPECT_GT(s.tool().read("selected"), 20);
    // The crown (a 15 mm circle inside the 25 mm radius) comes much closer to a plane: its top pressed
    // down, its foot pulled up.
    const double after = unevenness(s.mesh(), 15);
    EXPECT_LT(after, 0.5 * before) << before << " -> " << after;
    EXPECT_LT(s.mesh()(top, 2), summit - 1.0);
    ASSERT_TRUE(s.mesh().allFinite());
}

TEST(FlattenTool, PushesNothingOutsideItsRadius) {
    auto patch = bumpedPatch();
    DynamicSurface& s = *patch;
    auto tool = makeTool("flatten");
    tool->set("radius", 20);
    tool->setFalloff(Falloff::Constant);
    MeshView view{s.mesh(), 31, 31, 100.0 / 30, 100.0 / 30};
    Cursor c;
    c.position = s.mesh().row(nearestTo(s.mesh(), Vec3(10, 0, 12))).transpose();
    tool->grab(view, c);
    Points f = Points::Zero(s.mesh().rows(), 3);
    tool->apply(view, c, 1.0, f);  // (past the ramp)
    int pushed = 0;
    for (Eigen::Index k = 0; k < f.rows(); ++k) {
        const double dist = (s.mesh().row(k).transpose() - c.position).norm();
        if (dist >= 20) {
            EXPECT_EQ(f.row(k).norm(), 0.0) << k;
        }
        if (f.row(k).norm() > 0) ++pushed;
    }
    EXPECT_GT(pushed, 10);
    EXPECT_LE(double(pushed), tool->read("selected"));
}

TEST(FlattenTool, ThePlaneFollowsTheCursorAlongTheNormalOnly) {
    auto patch = bumpedPatch();
    DynamicSurface& s = *patch;
    auto tool = makeTool("flatten");
    MeshView view{s.mesh(), 31, 31, 100.0 / 30, 100.0 / 30};
    Cursor c;
    c.position = s.mesh().row(nearestTo(s.mesh(), Vec3(0, 0, 12))).transpose();  // the summit: normal z
    tool->grab(view, c);
    Points f = Points::Zero(s.mesh().rows(), 3);
    auto forceAt = [&](const Vec3& cursor) {
        f.setZero();
        Cursor moved = c;
        moved.position = cursor;
        return Vec3(tool->apply(view, moved, 1.0, f).force);
    };
    const Vec3 still = forceAt(c.position);
    // As much down as up: at the grab the forces on the surface add up to nothing.
    EXPECT_GT(f.rowwise().norm().sum(), 1.0);
    EXPECT_LT(still.norm(), 1e-9 * f.rowwise().norm().sum());
    EXPECT_LT((forceAt(c.position + Vec3(7, -4, 0)) - still).norm(), 1e-9 * (1 + still.norm()));  // sideways: the same
    const Vec3 raised = forceAt(c.position + Vec3(0, 0, 3));
    // Raised 3 mm, the plane pulls every selected point up by k w (3 + its depth): the cursor feels it down.
    EXPECT_LT(raised.z(), still.z() - 1.0);
    EXPECT_LT(std::hypot(raised.x(), raised.y()), 1e-9 * raised.norm());  // along the normal only
}

TEST(FlattenTool, ItsFalloffWeighsTheRimLess) {
    auto patch = bumpedPatch();
    DynamicSurface& s = *patch;
    MeshView view{s.mesh(), 31, 31, 100.0 / 30, 100.0 / 30};
    Cursor c;
    c.position = s.mesh().row(nearestTo(s.mesh(), Vec3(0, 0, 12))).transpose();
    // The weights the haptic loop renders the law with (their sum): every selected point weighs 1
    // with the constant falloff, less toward the rim with the others.
    auto weights = [&](Falloff falloff) {
        auto tool = makeTool("flatten");
        tool->set("radius", 25);
        tool->setFalloff(falloff);
        tool->grab(view, c);
        HapticEstimate e;
        tool->describe(view, Reaction{}, e);
        EXPECT_EQ(e.kind, EstimateKind::Linear);
        return std::make_pair(e.weightSum, tool->read("selected"));
    };
    const auto [constant, all] = weights(Falloff::Constant);
    EXPECT_DOUBLE_EQ(constant, all);
    EXPECT_LT(weights(Falloff::Spherical).first, 0.8 * all);
    EXPECT_LT(weights(Falloff::Conical).first, 0.8 * all);
    EXPECT_EQ(weights(Falloff::Spherical).second, all);
    EXPECT_THROW(makeTool("rope")->setFalloff(Falloff::Conical), std::invalid_argument);
}
