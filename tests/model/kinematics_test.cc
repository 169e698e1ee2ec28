#include "leglab/model/kinematics.h"
#include "test_legs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace leglab {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

void ExpectNear(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol) {
  EXPECT_LE((actual - expected).lpNorm<Eigen::Infinity>(), tol)
      << "actual " << actual.transpose() << " expected " << expected.transpose();
}

// Hand-worked poses from ers210a.md's vectors: u + w = (-6.08, 0.5, -130).
TEST(Kinematics, ForwardByHand) {
  const LegGeometry g = testing::FrontLeftLeg();
  ExpectNear(ForwardKinematics(g, {0, 0, 0}), {53.42, 59.7, -130.0}, 1e-12);
  // Rotator +90: the leg points forward, (x, z) -> (-z, x).
  ExpectNear(ForwardKinematics(g, {90 * kDeg, 0, 0}), {59.5 + 130.0, 59.7, -6.08}, 1e-12);
  // Abductor +90: the leg points outward (+y for a left leg), (y, z) -> (-z, y).
  ExpectNear(ForwardKinematics(g, {0, 90 * kDeg, 0}), {53.42, 59.2 + 130.0, 0.5}, 1e-12);
  // Knee +90: the lower leg swings back and up, w -> (wz, 0, -wx) = (-66, 0, 18.88).
  ExpectNear(ForwardKinematics(g, {0, 0, 90 * kDeg}), {59.5 + 12.8 - 66.0, 59.7, -64.0 + 18.88},
             1e-12);
}

// The hind leg mirrors x: rotator about +y (+ swings the paw backward), knee about -y (+
// swings it forward). u + w = (16.56, 0.5, -134.88).
TEST(Kinematics, HindLegForwardByHand) {
  const LegGeometry g = testing::HindLeftLeg();
  ExpectNear(ForwardKinematics(g, {0, 0, 0}), {-42.94, 59.7, -134.88}, 1e-12);
  // Rotator +90 about +y: (x, z) -> (z, -x), the leg points backward.
  ExpectNear(ForwardKinematics(g, {90 * kDeg, 0, 0}), {-59.5 - 134.88, 59.7, -16.56}, 1e-12);
  // Abductor +90 about +x: outward, as for the front leg.
  ExpectNear(ForwardKinematics(g, {0, 90 * kDeg, 0}), {-42.94, 59.2 + 134.88, 0.5}, 1e-12);
  // Knee +90 about -y: w -> (-wz, 0, wx) = (70.88, 0, 29.36), the paw swings forward and up.
  ExpectNear(ForwardKinematics(g, {0, 0, 90 * kDeg}), {-59.5 - 12.8 + 70.88, 59.7, -64.0 + 29.36},
             1e-12);
}

// Round trip of IK over a grid a degree inside every limit (the front knee's lower limit is
// within 0.3 deg of the straight leg, where its two branches meet): the solution always puts
// the foot back, and where it is not the original angles `other_branch(q, solved)` checks it.
// Returns how many grid points were checked and how many came back as the original angles.
template <typename OtherBranch>
std::pair<int, int> RoundTripGrid(const LegGeometry& g, OtherBranch other_branch) {
  int checked = 0, exact = 0;
  for (double q1 = -116.0; q1 <= 116.0; q1 += 8.0) {
    for (double q2 = -10.0; q2 <= 88.0; q2 += 7.0) {
      for (double q3 = -26.0; q3 <= 146.0; q3 += 8.6) {
        const Eigen::Vector3d q = Eigen::Vector3d(q1, q2, q3) * kDeg;
        const Eigen::Vector3d foot = ForwardKinematics(g, q);
        const Eigen::Vector3d solved = InverseKinematics(g, foot);
        ExpectNear(ForwardKinematics(g, solved), foot, 1e-9);
        if ((solved - q).lpNorm<Eigen::Infinity>() > 1e-9) {
          other_branch(q, solved);
        } else {
          ++exact;
        }
        ++checked;
      }
    }
  }
  return {checked, exact};
}

TEST(Kinematics, HindLegRoundTripOverAGrid) {
  // Another solution is returned only if its rotator is nearer zero.
  const auto [checked, exact] = RoundTripGrid(
      testing::HindLeftLeg(), [](const Eigen::Vector3d& q, const Eigen::Vector3d& solved) {
        EXPECT_LT(std::abs(solved[kRotator]), std::abs(q[kRotator])) << q.transpose() / kDeg;
      });
  EXPECT_GT(checked, 5000);
  EXPECT_GT(exact, checked * 9 / 10);
}

// The Jacobian against central differences of ForwardKinematics, on both legs over a grid, and
// by hand at q = 0 for the front leg, from the quarter turns of ForwardByHand (u + w = (-6.08,
// 0.5, -130), w = (-18.88, 0, -66)): the rotator turns the whole leg's (x, z) towards (-z, x),
// the abductor its (y, z) towards (-z, y), the knee only the lower leg's (x, z) towards (z, -x).
TEST(Kinematics, FootJacobianByHandAndByCentralDifferences) {
  const Eigen::Matrix3d at_zero = FootJacobian(testing::FrontLeftLeg(), Eigen::Vector3d::Zero());
  ExpectNear(at_zero.col(kRotator), {130.0, 0.0, -6.08}, 1e-12);
  ExpectNear(at_zero.col(kAbductor), {0.0, 130.0, 0.5}, 1e-12);
  ExpectNear(at_zero.col(kKnee), {-66.0, 0.0, 18.88}, 1e-12);
  for (const LegGeometry& g : {testing::FrontLeftLeg(), testing::HindLeftLeg()}) {
    for (double q1 = -100.0; q1 <= 100.0; q1 += 40.0) {
      for (double q2 = -10.0; q2 <= 85.0; q2 += 19.0) {
        for (double q3 = -20.0; q3 <= 140.0; q3 += 32.0) {
          const Eigen::Vector3d q = Eigen::Vector3d(q1, q2, q3) * kDeg;
          const Eigen::Matrix3d jacobian = FootJacobian(g, q);
          constexpr double kH = 1e-6;
          for (int j = 0; j < 3; ++j) {
            const Eigen::Vector3d dq = Eigen::Vector3d::Unit(j) * kH;
            const Eigen::Vector3d central =
                (ForwardKinematics(g, q + dq) - ForwardKinematics(g, q - dq)) / (2.0 * kH);
            ExpectNear(jacobian.col(j), central, 1e-5);
          }
        }
      }
    }
  }
}

TEST(Kinematics, ValidateLegGeometryNamesTheItem) {
  EXPECT_NO_THROW(ValidateLegGeometry(testing::FrontLeftLeg()));
  EXPECT_NO_THROW(ValidateLegGeometry(testing::HindLeftLeg()));
  auto message = [](const LegGeometry& g) {
    try {
      ValidateLegGeometry(g);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  LegGeometry g = testing::FrontLeftLeg();
  g.axes[kAbductor] = Eigen::Vector3d::UnitY();
  EXPECT_NE(message(g).find("abductor axis"), std::string::npos) << message(g);
  g = testing::FrontLeftLeg();
  g.axes[kKnee] = Eigen::Vector3d(0.0, 2.0, 0.0);
  EXPECT_NE(message(g).find("knee axis"), std::string::npos) << message(g);
  g = testing::FrontLeftLeg();
  g.limits[kRotator] = {1.0, -1.0};
  EXPECT_NE(message(g).find("rotator limits"), std::string::npos) << message(g);
  g = testing::FrontLeftLeg();
  g.lower_leg_mm.x() = NAN;
  EXPECT_NE(message(g).find("lower-leg"), std::string::npos) << message(g);
}

TEST(Kinematics, RoundTripOverAGridOfTheWorkspace) {
  // Where two abductor branches are inside the limits IK returns the one whose rotator is
  // nearer zero: the original angles, or another solution with a smaller rotator.
  const auto [checked, exact] = RoundTripGrid(
      testing::FrontLeftLeg(), [](const Eigen::Vector3d& q, const Eigen::Vector3d& solved) {
        EXPECT_LT(std::abs(solved[kRotator]), std::abs(q[kRotator])) << q.transpose() / kDeg;
        EXPECT_GT(q[kAbductor], 60 * kDeg) << q.transpose() / kDeg;
      });
  EXPECT_GT(checked, 5000);
  EXPECT_LT(checked - exact, checked / 20);  // a corner of the joint space
}

TEST(Kinematics, OutOfReachNamesThePointAndTheReason) {
  const LegGeometry g = testing::FrontLeftLeg();
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
  const LegGeometry g = testing::FrontLeftLeg();
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
