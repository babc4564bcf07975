// Nearest points (point_tree.hpp) and closest points on a surface (surface_projection.hpp): both
// against brute force on seeded clouds, flat and off the cloud; no allocation per query; bad
// clouds refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "geometry/point_tree.hpp"
#include "geometry/surface_projection.hpp"

using namespace hs;

long allocationCount();  // test_core.cpp

namespace {

Points cloud(int n, unsigned seed, double flatness) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-100, 100);
    Points p(n, 3);
    for (int i = 0; i < n; ++i) p.row(i) << u(rng), u(rng), flatness * u(rng);
    return p;
}

Eigen::Index bruteNearest(const Points& p, const Vec3& x, double& d2) {
    Eigen::Index best = 0;
    d2 = (p.row(0).transpose() - x).squaredNorm();
    for (Eigen::Index i = 1; i < p.rows(); ++i) {
        const double d = (p.row(i).transpose() - x).squaredNorm();
        if (d < d2) d2 = d, best = i;
    }
    return best;
}

// A 400 mm patch of 12 x 12 poles with a smooth bump and a wave.
BSplineSurface wavy() {
    BSplineSurface s = BSplineSurface::plane(12, 12, 3, 3, 400, 400);
    Points& P = s.mutablePoles();
    for (Eigen::Index i = 0; i < P.rows(); ++i)
        P(i, 2) = 30 * std::exp(-(P(i, 0) * P(i, 0) + P(i, 1) * P(i, 1)) / 8000) + 5 * std::sin(P(i, 0) / 40);
    return s;
}

}  // namespace

TEST(PointTree, FindsWhatBruteForceFinds) {
    for (double flatness : {1.0, 0.01}) {
        const Points p = cloud(5000, 7, flatness);
        const PointTree tree(p);
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> u(-150, 150);
        for (int q = 0; q < 2000; ++q) {
            const Vec3 x(u(rng), u(rng), u(rng));  // on, near and far off the cloud
            double d2 = 0, b2 = 0;
            const Eigen::Index i = tree.nearest(x, d2);
            bruteNearest(p, x, b2);
            ASSERT_DOUBLE_EQ(d2, b2) << "query " << q << " flatness " << flatness;
            EXPECT_DOUBLE_EQ((p.row(i).transpose() - x).squaredNorm(), d2);
        }
    }
}

TEST(PointTree, SmallCloudsAndDuplicates) {
    Points one(1, 3);
    one << 1, 2, 3;
    double d2 = 0;
    EXPECT_EQ(PointTree(one).nearest(Vec3(1, 2, 4), d2), 0);
    EXPECT_DOUBLE_EQ(d2, 1.0);
    Points same = Points::Constant(100, 3, 5.0);  // a scan with every point on one spot
    const PointTree tree(same);
    const Eigen::Index i = tree.nearest(Vec3(0, 0, 0), d2);
    EXPECT_DOUBLE_EQ(d2, 75.0);
    EXPECT_EQ(tree.point(i), Vec3(5, 5, 5));
    EXPECT_EQ(tree.nearest(Vec3(0, 0, 0), d2), i);  // the same answer each time
}

TEST(PointTree, RefusesBadCloudsByName) {
    EXPECT_THROW(PointTree(Points(0, 3), "target"), std::invalid_argument);
    Points p = cloud(10, 1, 1.0);
    p(4, 1) = std::nan("");
    try {
        PointTree tree(p, "target");
        FAIL() << "a NaN was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("target"), std::string::npos);
    }
    p(4, 1) = 2e9;
    EXPECT_THROW(PointTree(p, "target"), std::invalid_argument);
}

TEST(PointTree, QueriesAllocateNothing) {
    const PointTree tree(cloud(20000, 3, 0.05));
    double d2 = 0, sum = 0;
    const long before = allocationCount();
    for (int q = 0; q < 1000; ++q) sum += static_cast<double>(tree.nearest(Vec3(q * 0.1 - 50, 20, 3), d2));
    EXPECT_EQ(allocationCount() - before, 0);
    EXPECT_GT(sum, 0);
}

TEST(SurfaceProjection, FootIsPerpendicularAndNearestOfADenseSampling) {
    const BSplineSurface s = wavy();
    const SurfaceProjection projection(s);
    // A dense sampling (about 1 mm apart) as the reference: no point of it may be nearer.
    const int n = 401;
    Points dense(n * n, 3);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) dense.row(i * n + j) = s.evaluate(double(i) / (n - 1), double(j) / (n - 1), 0).s.transpose();
    const PointTree reference(dense);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> xy(-190, 190), z(-40, 60);
    int inside = 0;
    for (int q = 0; q < 500; ++q) {
        const Vec3 x(xy(rng), xy(rng), z(rng));
        const SurfaceFoot f = projection.project(x);
        double d2 = 0;
        reference.nearest(x, d2);
        EXPECT_LE(std::abs(f.distance), std::sqrt(d2) + 1e-9) << q;  // never farther than a sample
        EXPECT_NEAR((x - f.point).norm(), std::abs(f.distance), 1e-9);
        EXPECT_NEAR((s.evaluate(f.u, f.v, 0).s - f.point).norm(), 0, 1e-9);
        if (!f.beyondEdge) {
            ++inside;
            const SurfaceDerivatives d = s.evaluate(f.u, f.v, 1);  // x - foot is along the normal
            EXPECT_NEAR((x - f.point).dot(d.su.normalized()), 0, 1e-5);
            EXPECT_NEAR((x - f.point).dot(d.sv.normalized()), 0, 1e-5);
            EXPECT_EQ(f.distance >= 0, (x - f.point).dot(f.normal) >= 0);
        }
    }
    EXPECT_GT(inside, 400);
}

TEST(SurfaceProjection, PointsBeyondAnEdgeAreSaidToBe) {
    const SurfaceProjection projection(BSplineSurface::plane(6, 6, 3, 3, 100, 100));
    const SurfaceFoot over = projection.project(Vec3(10, -20, 3));
    EXPECT_FALSE(over.beyondEdge);
    EXPECT_NEAR(over.distance, 3, 1e-9);
    EXPECT_NEAR(projection.project(Vec3(10, -20, -2)).distance, -2, 1e-9);
    const SurfaceFoot beyond = projection.project(Vec3(60, 0, 1));  // 10 mm past the edge x = 50
    EXPECT_TRUE(beyond.beyondEdge);
    EXPECT_NEAR(beyond.point.x(), 50, 1e-9);
    EXPECT_THROW(SurfaceProjection(BSplineSurface::plane(6, 6, 3, 3, 100, 100), 0), std::invalid_argument);
}

TEST(SurfaceProjection, ProjectingAllocatesNothing) {
    const SurfaceProjection projection(wavy());
    double sum = 0;
    const long before = allocationCount();
    for (int q = 0; q < 200; ++q) sum += projection.project(Vec3(q - 100.0, 0.5 * q - 50, 10)).distance;
    EXPECT_EQ(allocationCount() - before, 0);
    EXPECT_TRUE(std::isfinite(sum));
}
