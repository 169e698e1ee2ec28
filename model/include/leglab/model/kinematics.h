#pragma once

#include <Eigen/Core>
#include <array>

#include "leglab/core/leg.h"

namespace leglab {

/// Lower and upper limit of one joint, radians.
struct JointLimits {
  double lower_rad = 0.0;
  double upper_rad = 0.0;

  friend bool operator==(const JointLimits&, const JointLimits&) = default;
};

/// Geometry of one three-joint leg (rotator, abductor, knee), all vectors in the body frame at
/// q = 0 (x forward, y left, z up), millimetres. It comes from the robot's URDF (see
/// robots/<name>/); no code here names a robot.
///
/// The chain is J1 rotator about +-y, J2 abductor about +-x after J1, J3 knee about +-y of the
/// upper-leg frame, with J1 and J2 meeting at the shoulder (the ERS-210A's legs; a hind leg
/// mirrors x, which flips the y axes, and a right leg mirrors y, which flips the x axis):
///   foot = shoulder + R(a1, q1) R(a2, q2) (upper_leg + R(a3, q3) lower_leg),
/// where R(a, q) turns by q about the unit axis a.
struct LegGeometry {
  Eigen::Vector3d shoulder_mm;   ///< body centre -> shoulder (J1/J2 axes' intersection)
  Eigen::Vector3d upper_leg_mm;  ///< shoulder -> knee
  Eigen::Vector3d lower_leg_mm;  ///< knee -> centre of the ball of the foot
  /// Each joint's unit axis at q = 0, indexed by LegJoint: rotator and knee +-y, abductor +-x.
  std::array<Eigen::Vector3d, kLegJoints> axes;
  std::array<JointLimits, kLegJoints> limits;  ///< software limits, indexed by LegJoint

  /// The direction of "outward" along the body's y axis: +1 for a left leg (shoulder at
  /// y > 0), -1 for a right one.
  double OutwardSign() const { return shoulder_mm.y() < 0.0 ? -1.0 : 1.0; }
};

/// Throws std::invalid_argument naming the item unless every vector is finite, the rotator
/// and knee axes are +-y and the abductor's +-x (within 1e-9), and every joint's limits are
/// finite with lower < upper.
void ValidateLegGeometry(const LegGeometry& geometry);

/// Foot position (centre of the ball of the foot) in the body frame, mm, for joint angles
/// `q_rad` = (rotator, abductor, knee) in radians. Limits are not checked.
Eigen::Vector3d ForwardKinematics(const LegGeometry& geometry, const Eigen::Vector3d& q_rad);

/// d ForwardKinematics / d q at `q_rad`, mm/rad: column j is how the foot moves per radian of
/// joint j (rotator, abductor, knee). `geometry` must be valid (ValidateLegGeometry).
Eigen::Matrix3d FootJacobian(const LegGeometry& geometry, const Eigen::Vector3d& q_rad);

/// Joint angles (rotator, abductor, knee), radians, that put the foot at `foot_mm` (body frame).
/// Closed form: the knee from the shoulder-foot distance, the abductor from the lateral
/// component, the rotator from the remaining sagittal angle. The knee and the abductor have two
/// branches each; of the (up to four) solutions inside the limits the one with the rotator
/// nearest zero is returned. (On the ERS-210A's front leg the second knee branch is always
/// beyond the knee's lower limit; both abductor branches are inside the limits only with the
/// abductor near its upper limit and the knee flexed.) `geometry` must be valid
/// (ValidateLegGeometry).
/// Throws std::domain_error naming the point and the reason when the point is out of reach
/// or needs an angle outside the joint limits (tolerance 1e-9 rad).
Eigen::Vector3d InverseKinematics(const LegGeometry& geometry, const Eigen::Vector3d& foot_mm);

}  // namespace leglab
