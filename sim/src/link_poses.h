#pragma once

// Eigen views of a LegDescription's plain-array frames, and the link poses they give for a set
// of joint angles. Private to leglab::sim: shared by the description (joint frames at q = 0)
// and LegWorld (placing the ODE bodies).

#include <array>
#include <vector>

#include <Eigen/Geometry>

#include "leglab/core/leg.h"
#include "leglab/sim/leg_description.h"

namespace leglab::sim {

inline Eigen::Vector3d ToEigen(const std::array<double, 3>& v) {
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

inline std::array<double, 3> ToArray(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

inline Eigen::Matrix3d ToEigen(const std::array<std::array<double, 3>, 3>& m) {
  Eigen::Matrix3d matrix;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      matrix(i, j) = m[i][j];
    }
  }
  return matrix;
}

inline std::array<std::array<double, 3>, 3> ToRowMajor(const Eigen::Matrix3d& m) {
  std::array<std::array<double, 3>, 3> matrix{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      matrix[i][j] = m(i, j);
    }
  }
  return matrix;
}

inline Eigen::Isometry3d ToEigen(const RigidTransform& transform) {
  Eigen::Isometry3d isometry = Eigen::Isometry3d::Identity();
  isometry.linear() = ToEigen(transform.rotation);
  isometry.translation() = ToEigen(transform.translation_m);
  return isometry;
}

inline RigidTransform ToRigidTransform(const Eigen::Isometry3d& isometry) {
  return RigidTransform{ToRowMajor(isometry.linear()),
                        ToArray(Eigen::Vector3d(isometry.translation()))};
}

/// Pose of every link of `links` (LegDescription::links, depth-first) in the root frame for
/// the joint angles `q_rad` (rad, LegJoint order), from the description alone.
std::vector<Eigen::Isometry3d> LinkPoses(const std::vector<LinkDescription>& links,
                                         const LegAngles& q_rad);

}  // namespace leglab::sim
