// The Novint Falcon's kinematics (a delta mechanism; R. E. Stamper's analysis, with the
// dimensions libnifalcon measured): the three motor angles from the encoder counts, the tip's
// position from the angles (Newton on the closed-form inverse), and the motor torques that make a
// force at the tip (tau = J^-T F, J the angles' Jacobian). Metres and radians, in the device's own
// frame (z away from the user, the workspace centred near z = 0.11 m). No allocation: the haptic
// thread runs it.
#pragma once
#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace hs::falcon {

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

/// One arm's three joint angles (motor, knee, shin twist) at a tip position.
struct ArmAngles {
    Vec3d motor = Vec3d::Zero();  ///< theta1 of arms 1..3: what the encoders measure
    Vec3d knee = Vec3d::Zero();   ///< theta2
    Vec3d twist = Vec3d::Zero();  ///< theta3
};

/// Motor angle (radians) from an encoder count, and back: 320 slots read in quadrature on a
/// 14.25 mm shaft driving a 110 mm arm drum, 35 degrees at count 0.
double angleOfCount(std::int16_t count);
double countOfAngle(double angle);

/// The joint angles at tip position p; false where p is out of the mechanism's reach.
bool inverseKinematics(const Vec3d& p, ArmAngles& out);
/// d(motor angles)/d(position) at `a` (the angles at some p).
Mat3d jacobian(const ArmAngles& a);
/// The tip position whose motor angles are `motor`, by Newton from `start` (the last position: one
/// or two iterations in the haptic loop); false if it does not converge (|angle error| > 1e-9).
bool forwardKinematics(const Vec3d& motor, const Vec3d& start, Vec3d& out);
/// Motor torques (N m) that push the tip with force f (N) at tip position p; false out of reach.
bool motorTorques(const Vec3d& p, const Vec3d& f, Vec3d& torques);

}  // namespace hs::falcon
