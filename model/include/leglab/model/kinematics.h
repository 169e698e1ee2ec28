#pragma once

#include <Eigen/Core>
#include <array>

#include "leglab/core/leg.h"

namespace leglab {

/// Lower and upper limit of one joint, radians.
struct JointLimits {
  double lower_rad = 0.0;
  double upper_rad = 0.0;
};

/// Geometry of one ERS-210A leg (../shared/ers210a.md), all vectors in the body frame at
/// q = 0 (x forward, y left, z up), millimetres.
///
/// The chain is J1 rotator about -y (+ swings the paw forward), J2 abductor about x after J1
/// (+ moves a left leg outward), J3 knee about y of the upper-leg frame (+ flexes the knee,
/// swinging the paw backward):
///   foot = shoulder + Ry(-q1) Rx(q2) (upper_leg + Ry(q3) lower_leg).
struct LegGeometry {
  Eigen::Vector3d shoulder_mm;        ///< body centre -> shoulder (J1/J2 axes' intersection)
  Eigen::Vector3d upper_leg_mm;       ///< shoulder -> knee
  Eigen::Vector3d lower_leg_mm;       ///< knee -> centre of the ball of the foot
  std::array<JointLimits, 3> limits;  ///< software limits, indexed by LegJoint

  /// The left front leg of the ERS-210A (CMPack'02 vectors, software joint limits).
  static LegGeometry Ers210aFrontLeft();
};

/// Foot position (centre of the ball of the foot) in the body frame, mm, for joint angles
/// `q_rad` = (rotator, abductor, knee) in radians. Limits are not checked.
Eigen::Vector3d ForwardKinematics(const LegGeometry& geometry, const Eigen::Vector3d& q_rad);

/// Joint angles (rotator, abductor, knee), radians, that put the foot at `foot_mm` (body frame).
/// Closed form: the knee from the shoulder-foot distance, the abductor from the lateral
/// component, the rotator from the remaining sagittal angle. The knee and the abductor have two
/// branches each; of the (up to four) solutions inside the limits the one with the rotator
/// nearest zero is returned. (On the ERS-210A the second knee branch is always beyond the
/// knee's lower limit; both abductor branches are inside the limits only with the abductor
/// near its upper limit and the knee flexed.)
/// Throws std::domain_error naming the point and the reason when the point is out of reach
/// or needs an angle outside the joint limits (tolerance 1e-9 rad).
Eigen::Vector3d InverseKinematics(const LegGeometry& geometry, const Eigen::Vector3d& foot_mm);

}  // namespace leglab
