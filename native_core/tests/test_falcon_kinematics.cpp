// The Falcon's kinematics: counts and angles round trip, the Jacobian is the derivative of the
// inverse kinematics, the forward kinematics inverts it across the workspace, and the torques do
// the work the force does (virtual work), with no allocation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "device_session.hpp"
#include "devices/falcon/falcon_kinematics.hpp"

using namespace hs::falcon;

namespace {
/// Points across the workspace: a 60 mm cube around its middle.
std::vector<Vec3d> workspace(int n) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.03, 0.03);
    std::vector<Vec3d> out;
    for (int k = 0; k < n; ++k) out.emplace_back(u(rng), u(rng), 0.11 + u(rng));
    return out;
}
}  // namespace

TEST(FalconKinematics, CountsAndAnglesRoundTrip) {
    for (int c : {-32768, -1000, 0, 1, 1000, 32767}) {
        const auto count = static_cast<std::int16_t>(c);
        EXPECT_NEAR(countOfAngle(angleOfCount(count)), c, 1e-6);
    }
    EXPECT_NEAR(angleOfCount(0), 35.0 * 3.14159265358979323846 / 180, 1e-15);
}

TEST(FalconKinematics, TheWholeWorkspaceIsInReach) {
    ArmAngles a;
    for (const Vec3d& p : workspace(500)) ASSERT_TRUE(inverseKinematics(p, a)) << p.transpose();
    EXPECT_FALSE(inverseKinematics(Vec3d(0, 0, 1.0), a));  // a metre away
}

TEST(FalconKinematics, TheJacobianIsTheDerivativeOfTheMotorAngles) {
    for (const Vec3d& p : workspace(50)) {
        ArmAngles a, plus, minus;
        ASSERT_TRUE(inverseKinematics(p, a));
        const Mat3d j = jacobian(a);
        for (int k = 0; k < 3; ++k) {
            Vec3d h = Vec3d::Zero();
            h[k] = 1e-6;
            ASSERT_TRUE(inverseKinematics(p + h, plus) && inverseKinematics(p - h, minus));
            const Vec3d fd = (plus.motor - minus.motor) / 2e-6;
            EXPECT_LT((j.col(k) - fd).norm(), 1e-6 * std::max(1.0, fd.norm())) << p.transpose() << " column " << k;
        }
    }
}

TEST(FalconKinematics, ForwardKinematicsInvertsTheInverse) {
    for (const Vec3d& p : workspace(200)) {
        ArmAngles a;
        ASSERT_TRUE(inverseKinematics(p, a));
        Vec3d back;
        ASSERT_TRUE(forwardKinematics(a.motor, Vec3d(0, 0, 0.11), back)) << p.transpose();
        EXPECT_LT((back - p).norm(), 1e-10) << p.transpose();
        // from the encoder counts, as the device reports them: to the counts' resolution
        Vec3d fromCounts;
        Vec3d motor;
        for (int i = 0; i < 3; ++i) motor[i] = angleOfCount(static_cast<std::int16_t>(std::lround(countOfAngle(a.motor[i]))));
        ASSERT_TRUE(forwardKinematics(motor, back, fromCounts));
        EXPECT_LT((fromCounts - p).norm(), 2e-4);  // (a count is ~0.1 mm at the tip)
    }
}

TEST(FalconKinematics, TorquesDoTheWorkOfTheForce) {
    std::mt19937 rng(5);
    std::normal_distribution<double> n(0.0, 3.0);
    for (const Vec3d& p : workspace(50)) {
        const Vec3d f(n(rng), n(rng), n(rng));
        Vec3d tau;
        ASSERT_TRUE(motorTorques(p, f, tau));
        ArmAngles a;
        ASSERT_TRUE(inverseKinematics(p, a));
        const Vec3d velocity(n(rng), n(rng), n(rng));
        const Vec3d angular = jacobian(a) * velocity;
        EXPECT_NEAR(tau.dot(angular), f.dot(velocity), 1e-9 * f.norm() * velocity.norm());
    }
    Vec3d tau;
    EXPECT_FALSE(motorTorques(Vec3d(0, 0, 1.0), Vec3d(1, 0, 0), tau));
}

TEST(FalconKinematics, ATickDoesNotAllocate) {
    Vec3d p(0.01, -0.005, 0.105), out, tau;
    ArmAngles a;
    ASSERT_TRUE(inverseKinematics(p, a));
    const long before = allocationCount();
    for (int k = 0; k < 100; ++k) {
        forwardKinematics(a.motor, p, out);
        motorTorques(out, Vec3d(1, 2, 3), tau);
    }
    EXPECT_EQ(allocationCount() - before, 0);
}
