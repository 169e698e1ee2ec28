#include "leglab/model/kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace leglab {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void ExpectNear(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol) {
  EXPECT_LE((actual - expected).lpNorm<Eigen::Infinity>(), tol)
      << "actual " << actual.transpose() << " expected " << expected.transpose();
}

// Hand-worked poses from ers210a.md's vectors: u + w = (-6.08, 0.5, -130).
TEST(Kinematics, ForwardByHand) {
  const LegGeometry g = LegGeometry::Ers210aFrontLeft();
  ExpectNear(ForwardKinematics(g, {0, 0, 0}), {53.42, 59.7, -130.0}, 1e-12);
  // Rotator +90: the leg points forward, (x, z) -> (-z, x).
  ExpectNear(ForwardKinematics(g, {90 * kDeg, 0, 0}), {59.5 + 130.0, 59.7, -6.08}, 1e-12);
  // Abductor +90: the leg points outward (+y for a left leg), (y, z) -> (-z, y).
  ExpectNear(ForwardKinematics(g, {0, 90 * kDeg, 0}), {53.42, 59.2 + 130.0, 0.5}, 1e-12);
  // Knee +90: the lower leg swings back and up, w -> (wz, 0, -wx) = (-66, 0, 18.88).
  ExpectNear(ForwardKinematics(g, {0, 0, 90 * kDeg}), {59.5 + 12.8 - 66.0, 59.7, -64.0 + 18.88},
             1e-12);
}

TEST(Kinematics, RoundTripOverAGridOfTheWorkspace) {
  const LegGeometry g = LegGeometry::Ers210aFrontLeft();
  int checked = 0, other_branch = 0;
  // The knee's lower limit (-27 deg) is within 0.3 deg of the straight leg (-27.3 deg), where
  // the two knee branches meet; stay a degree inside every limit.
  for (double q1 = -116.0; q1 <= 116.0; q1 += 8.0) {
    for (double q2 = -10.0; q2 <= 88.0; q2 += 7.0) {
      for (double q3 = -26.0; q3 <= 146.0; q3 += 8.6) {
        const Eigen::Vector3d q = Eigen::Vector3d(q1, q2, q3) * kDeg;
        const Eigen::Vector3d foot = ForwardKinematics(g, q);
        const Eigen::Vector3d solved = InverseKinematics(g, foot);
        ExpectNear(ForwardKinematics(g, solved), foot, 1e-9);
        // Where two abductor branches are inside the limits IK returns the one whose rotator is
        // nearer zero: the original angles, or another solution with a smaller rotator.
        if ((solved - q).lpNorm<Eigen::Infinity>() > 1e-9) {
          EXPECT_LT(std::abs(solved[kRotator]), std::abs(q[kRotator])) << q.transpose() / kDeg;
          EXPECT_GT(q[kAbductor], 60 * kDeg) << q.transpose() / kDeg;
          ++other_branch;
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 5000);
  EXPECT_LT(other_branch, checked / 20);  // a corner of the joint space
}

TEST(Kinematics, OutOfReachNamesThePointAndTheReason) {
  const LegGeometry g = LegGeometry::Ers210aFrontLeft();
  try {
    InverseKinematics(g, {59.5, 59.2, -200.0});  // 200 mm below the shoulder; the leg is 134
    FAIL() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("(59.5, 59.2, -200)"), std::string::npos) << what;
    EXPECT_NE(what.find("workspace"), std::string::npos) << what;
  }
}

TEST(Kinematics, OutsideTheJointLimitsNamesTheJoint) {
  const LegGeometry g = LegGeometry::Ers210aFrontLeft();
  // Abductor -40 deg (limit -11): reachable by the links, not by the joint.
  const Eigen::Vector3d inward = ForwardKinematics(g, Eigen::Vector3d(10, -40, 30) * kDeg);
  try {
    InverseKinematics(g, inward);
    FAIL() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("abductor"), std::string::npos) << e.what();
  }
  // Rotator 150 deg (limit 117).
  const Eigen::Vector3d behind = ForwardKinematics(g, Eigen::Vector3d(150, 10, 30) * kDeg);
  EXPECT_THROW(InverseKinematics(g, behind), std::domain_error);
  EXPECT_THROW(InverseKinematics(g, {NAN, 0, 0}), std::domain_error);
}

}  // namespace
}  // namespace leglab
