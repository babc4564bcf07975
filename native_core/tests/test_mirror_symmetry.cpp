// Mirror symmetry: a stroke on one side acts mirrored on the other, in every integrator, and the
// net stays exactly symmetric; no allocation while stepping; clear errors for what is not symmetric.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "solvers/dynamic_surface.hpp"
#include "pulled_steps.hpp"

using namespace hs;


namespace {

constexpr int kN = 9;  // 9 x 9 poles: the middle row lies on the plane

struct Scheme {
    const char* name;
    IntegratorKind kind;
    int timeOrder;
    double dt;
};

void PrintTo(const Scheme& scheme, std::ostream* os) { *os << scheme.name; }

class MirrorSymmetryTest : public ::testing::TestWithParam<Scheme> {};

/// A 100 x 100 plane (u along x) made symmetric in x = 0, stepped by `scheme`, never sleeping.
std::unique_ptr<DynamicSurface> symmetricPlane(const Scheme& scheme) {
    auto made = std::make_unique<DynamicSurface>(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 31, 31);
    DynamicSurface& s = *made;
    SolverSettings solver = s.solver();
    solver.kind = scheme.kind;
    solver.timeOrder = scheme.timeOrder;
    s.setSolver(solver);
    s.setSleep({false, 1e-6, 10});
    s.setSymmetry(0, Vec3(0, 0, 0), Vec3(1, 0, 0));
    return made;
}

/// Largest distance between a pole's mirror image in x = 0 and its partner (i, j) <-> (n-1-i, j).
double asymmetry(const Points& p) {
    double worst = 0;
    for (int i = 0; i < kN; ++i)
        for (int j = 0; j < kN; ++j) {
            Vec3 m = p.row(i * kN + j).transpose();
            m.x() = -m.x();
            worst = std::max(worst, (m - p.row((kN - 1 - i) * kN + j).transpose()).norm());
        }
    return worst;
}

}  // namespace

TEST_P(MirrorSymmetryTest, AStrokeOnOneSideActsMirroredAndTheNetStaysExactlySymmetric) {
    const Scheme setup = GetParam();
    auto made = symmetricPlane(setup);
    DynamicSurface& s = *made;
    Cursor c;
    c.position = Vec3(25, 10, 0);  // off the plane: only the mirrored tool reaches x = -25
    c.grab = true;
    for (int k = 0; k < 300; ++k) {
        c.position.z() = 20.0 * std::min(1.0, k / 150.0);
        c.position.y() = 10.0 - 10.0 * k / 300.0;
        s.setCursor(c);
        const StepReport r = s.step(setup.dt);
        ASSERT_FALSE(r.refused) << setup.name << ": " << r.reason;
        ASSERT_EQ(asymmetry(s.poles()), 0.0) << setup.name << " step " << k;
    }
    const int here = 23 * s.h() + 15, there = (s.g() - 1 - 23) * s.h() + 15;  // mirror partners on the mesh
    const double lifted = s.mesh()(here, 2), mirrored = s.mesh()(there, 2);
    EXPECT_GT(lifted, 3.0) << setup.name;
    // (the mesh is A p: the same sums in another order, so equal to rounding)
    EXPECT_NEAR(mirrored, lifted, 1e-12 * s.size()) << setup.name;
    EXPECT_NEAR(s.mesh()(there, 0), -s.mesh()(here, 0), 1e-12 * s.size()) << setup.name;
    EXPECT_TRUE(std::isfinite(s.kineticEnergy()));
}

TEST_P(MirrorSymmetryTest, SteppingWithSymmetryDoesNotAllocate) {
    const Scheme setup = GetParam();
    auto made = symmetricPlane(setup);
    DynamicSurface& s = *made;
    EXPECT_EQ(allocationsWhilePulling(s, setup.dt, Vec3(20, 0, 0)), 0) << setup.name;
}

INSTANTIATE_TEST_SUITE_P(Integrators, MirrorSymmetryTest,
                         ::testing::Values(Scheme{"explicit", IntegratorKind::Explicit, 2, 1e-3},
                                           Scheme{"implicit CG", IntegratorKind::ImplicitCG, 2, 1e-3},
                                           Scheme{"local/global BDF2", IntegratorKind::LocalGlobal, 2, 1e-3},
                                           Scheme{"local/global Verlet", IntegratorKind::LocalGlobal, 2, 2e-4}),
                         [](const auto& param) {
                             std::string n = param.param.name;
                             for (char& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return n;
                         });

TEST(MirrorSymmetry, AStrokeOnThePlaneStaysInIt) {
    // Pulled sideways on the plane, the mirrored tool pulls back: the plane's row stays on it.
    auto made = symmetricPlane({"default", IntegratorKind::LocalGlobal, 2, 1e-3});
    DynamicSurface& s = *made;
    Cursor c;
    c.grab = true;
    for (int k = 0; k < 200; ++k) {
        c.position = Vec3(15.0 * k / 200, 0, 10.0 * k / 200);
        s.setCursor(c);
        s.step(1e-3);
    }
    for (int j = 0; j < kN; ++j) EXPECT_EQ(s.poles()((kN / 2) * kN + j, 0), 0.0);
    EXPECT_GT(s.poles()((kN / 2) * kN + kN / 2, 2), 2.0);
}

TEST(MirrorSymmetry, PointForcesAndNewNetsAreMirroredToo) {
    auto made = symmetricPlane({"default", IntegratorKind::LocalGlobal, 2, 1e-3});
    DynamicSurface& s = *made;
    s.setPointForce(s.meshIndexAt(0.8, 0.3), Vec3(2, 1, 5));
    for (int k = 0; k < 100; ++k) s.step(1e-3);
    EXPECT_EQ(asymmetry(s.poles()), 0.0);
    EXPECT_GT(s.mesh()(4 * s.h() + 9, 2), 0.0);  // the far side, moved by the mirrored force
    Points p = s.poles();
    p(3, 2) += 1.0;  // an asymmetric net (an old file): put symmetric at once
    s.setPoles(p);
    EXPECT_EQ(asymmetry(s.poles()), 0.0);
    EXPECT_NEAR(s.poles()(3, 2) - s.poles()((kN - 1 - 0) * kN + 3, 2), 0.0, 0.0);
    const auto sym = s.symmetry();
    EXPECT_EQ(sym.direction(), 0);
    s.setSymmetry(-1, Vec3::Zero(), Vec3::UnitX());
    EXPECT_TRUE(s.symmetry().empty());
}

TEST(MirrorSymmetry, WhatIsNotSymmetricIsRefusedByName) {
    DynamicSurface s(BSplineSurface::plane(kN, kN, 3, 3, 100, 100), 20, 20);
    auto expectError = [&](auto call, const std::string& text) {
        try {
            call();
            FAIL() << "no error, expected " << text;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
        EXPECT_TRUE(s.symmetry().empty());
    };
    expectError([&] { s.setSymmetry(0, Vec3(10, 0, 0), Vec3(1, 0, 0)); }, "symmetry: the surface is not symmetric");
    expectError([&] { s.setSymmetry(1, Vec3(0, 0, 0), Vec3(1, 0, 0)); }, "symmetry: the surface is not symmetric");
    expectError([&] { s.setSymmetry(2, Vec3(0, 0, 0), Vec3(1, 0, 0)); }, "symmetry: direction");
    expectError([&] { s.setSymmetry(0, Vec3(0, 0, 0), Vec3(0, 0, 0)); }, "normal");
    s.holdPoles({0, 1});
    expectError([&] { s.setSymmetry(0, Vec3(0, 0, 0), Vec3(1, 0, 0)); }, "indices: the held poles must be symmetric");
    s.holdPoles({0, 1, (kN - 1) * kN, (kN - 1) * kN + 1});
    s.setSymmetry(0, Vec3(0, 0, 0), Vec3(1, 0, 0));
    try {
        s.holdPoles({2});
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("pole 2 is held, its mirror image"), std::string::npos) << e.what();
    }
    // Knots that are not symmetric.
    std::vector<double> ku = {0, 0, 0, 0, 0.3, 1, 1, 1, 1};
    DynamicSurface t(BSplineSurface(5, 4, 3, 3, ku, clampedUniformKnots(4, 3), BSplineSurface::plane(5, 4, 3, 3, 1, 1).poles(), {}), 10, 10);
    try {
        t.setSymmetry(0, Vec3(0, 0, 0), Vec3(1, 0, 0));
        FAIL() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("knots along u are not symmetric"), std::string::npos) << e.what();
    }
}
