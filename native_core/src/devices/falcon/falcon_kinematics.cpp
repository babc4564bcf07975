#include "devices/falcon/falcon_kinematics.hpp"

#include <cmath>

#include <Eigen/LU>

namespace hs::falcon {

namespace {
// Mechanism dimensions (m), as libnifalcon's FalconGeometry.h gives them from Stamper's figure.
constexpr double kA = 0.060, kB = 0.1025, kC = 0.014, kD = 0.01125, kE = kD, kF = -0.025;
constexpr double kR = 0.037233758, kS = -0.027330909;
constexpr double kPi = 3.14159265358979323846;
constexpr double kOffset = kPi / 12;  // each arm 15 degrees off the desk plane
constexpr std::array<double, 3> kPhi = {kPi / 2 + kOffset, -kPi / 6 + kOffset, -5 * kPi / 6 + kOffset};
// Encoder: 320 slots in quadrature (1280 counts a turn) on the 14.25 mm motor shaft, which drives
// the 110 mm drum of the arm; 35 degrees at count 0.
constexpr double kDegreesPerCount = (0.01425 / 0.110) * 360.0 / (4 * 320.0);
constexpr double kAngleAtZero = 35.0;
}  // namespace

double angleOfCount(std::int16_t count) { return (count * kDegreesPerCount + kAngleAtZero) * kPi / 180.0; }
double countOfAngle(double angle) { return (angle * 180.0 / kPi - kAngleAtZero) / kDegreesPerCount; }

bool inverseKinematics(const Vec3d& p, ArmAngles& out) {
    for (int i = 0; i < 3; ++i) {
        const double cp = std::cos(kPhi[static_cast<std::size_t>(i)]), sp = std::sin(kPhi[static_cast<std::size_t>(i)]);
        // the tip in the arm's frame (u along the arm's base, v across it, w = z)
        const double pu = -kR + cp * p.x() + sp * p.y();
        const double pv = -kS + cp * p.y() - sp * p.x();
        const double pw = p.z();
        const double c3 = (pv + kF) / kB;
        if (!(std::abs(c3) < 1)) return false;
        const double t3 = std::acos(c3), s3 = std::sin(t3);
        // theta1 from a quadratic in tan(theta1 / 2)
        const double common = pw * pw + pu * pu + 2 * kC * pu + kA * kA + kC * kC - kD * kD - kE * kE - kB * kB * s3 * s3 -
                              2 * kB * (kD + kE) * s3 - 2 * kD * kE;
        const double l0 = common - 2 * kA * pu - 2 * kA * kC;
        const double l1 = -4 * kA * pw;
        const double l2 = common + 2 * kA * pu + 2 * kA * kC;
        const double disc = l1 * l1 - 4 * l2 * l0;
        if (!(disc >= 0) || l2 == 0) return false;
        const double t1 = 2 * std::atan(-(std::sqrt(disc) + l1) / (2 * l2));
        const double c2 = -(kA * std::cos(t1) - kC - pu) / (kB * s3 + kD + kE);
        if (!(std::abs(c2) <= 1)) return false;
        out.motor[i] = t1;
        out.knee[i] = std::acos(c2);
        out.twist[i] = t3;
    }
    return true;
}

Mat3d jacobian(const ArmAngles& a) {
    // Stamper: J_I theta1' = J_F p', J_F's rows from each arm's knee and twist, J_I diagonal.
    Mat3d jf, ji = Mat3d::Zero();
    for (int i = 0; i < 3; ++i) {
        const double cp = std::cos(kPhi[static_cast<std::size_t>(i)]), sp = std::sin(kPhi[static_cast<std::size_t>(i)]);
        const double c2 = std::cos(a.knee[i]), s2 = std::sin(a.knee[i]), c3 = std::cos(a.twist[i]), s3 = std::sin(a.twist[i]);
        jf.row(i) << c2 * s3 * cp - c3 * sp, c3 * cp + c2 * s3 * sp, s2 * s3;
        ji(i, i) = kA * std::sin(a.knee[i] - a.motor[i]) * s3;
    }
    return ji.inverse() * jf;
}

bool forwardKinematics(const Vec3d& motor, const Vec3d& start, Vec3d& out) {
    Vec3d p = start;
    ArmAngles a;
    for (int it = 0; it < 50; ++it) {
        if (!inverseKinematics(p, a)) {
            if (it == 0) {  // a start out of reach: from the middle of the workspace
                p = Vec3d(0, 0, 0.11);
                continue;
            }
            return false;
        }
        const Vec3d err = motor - a.motor;
        if (err.cwiseAbs().maxCoeff() <= 1e-12) {
            out = p;
            return true;
        }
        const Mat3d j = jacobian(a);
        Vec3d step = j.partialPivLu().solve(err);
        // damped: a step that leaves the reach is halved until it does not
        for (int h = 0; h < 20 && !inverseKinematics(p + step, a); ++h) step *= 0.5;
        p += step;
    }
    if (inverseKinematics(p, a) && (motor - a.motor).cwiseAbs().maxCoeff() <= 1e-9) {
        out = p;
        return true;
    }
    return false;
}

bool motorTorques(const Vec3d& p, const Vec3d& f, Vec3d& torques) {
    ArmAngles a;
    if (!inverseKinematics(p, a)) return false;
    // virtual work: tau . theta1' = f . p' for every p', theta1' = J p'  =>  J^T tau = f
    torques = jacobian(a).transpose().partialPivLu().solve(f);
    return torques.allFinite();
}

}  // namespace hs::falcon
