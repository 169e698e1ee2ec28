#include "leglab/model/trajectories.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "test_legs.h"

namespace leglab {
namespace {

TEST(StepTest, Equation1) {
  const std::vector<double> r = StepTestRequests(40.0);
  ASSERT_EQ(r.size(), 88u);
  for (int t = 0; t < 44; ++t) EXPECT_EQ(r[t], 40.0) << t;
  for (int t = 44; t < 88; ++t) EXPECT_EQ(r[t], 0.0) << t;
  const std::vector<double> odd = StepTestRequests(110.0, 5);  // t < 2.5: t = 0, 1, 2
  EXPECT_EQ(odd, (std::vector<double>{110.0, 110.0, 110.0, 0.0, 0.0}));
  EXPECT_THROW(StepTestRequests(40.0, 1), std::invalid_argument);
}

TEST(HalfEllipse, ShapeByHand) {
  HalfEllipseLocus locus;
  locus.length_mm = 40.0;
  locus.height_mm = 30.0;
  locus.ground_fraction = 0.5;
  locus.centre_mm = {10.0, 70.0, -110.0};
  locus.t_step_ticks = 88;
  const auto path = HalfEllipseFootPath(locus);
  ASSERT_EQ(path.size(), 88u);
  // Touch-down at the front, lift-off at the back after 44 ticks, on the ground in between
  // at a constant 40/44 mm per tick backward.
  EXPECT_NEAR((path[0] - Eigen::Vector3d(30.0, 70.0, -110.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((path[44] - Eigen::Vector3d(-10.0, 70.0, -110.0)).norm(), 0.0, 1e-12);
  for (int t = 1; t <= 44; ++t) {
    EXPECT_NEAR(path[t].x() - path[t - 1].x(), -40.0 / 44.0, 1e-12);
    EXPECT_EQ(path[t - 1].z(), -110.0);
  }
  // Top of the arc half way through the flight: the centre, 30 mm up.
  EXPECT_NEAR((path[66] - Eigen::Vector3d(10.0, 70.0, -80.0)).norm(), 0.0, 1e-12);
  // Every flight point lies on the ellipse ((x - 10)/20)^2 + ((z + 110)/30)^2 = 1.
  for (int t = 44; t < 88; ++t) {
    const double ex = (path[t].x() - 10.0) / 20.0, ez = (path[t].z() + 110.0) / 30.0;
    EXPECT_NEAR(ex * ex + ez * ez, 1.0, 1e-12) << t;
  }
}

TEST(HalfEllipse, RejectsBadParameters) {
  HalfEllipseLocus locus;
  locus.ground_fraction = 1.0;
  EXPECT_THROW(HalfEllipseFootPath(locus), std::invalid_argument);
  locus = {};
  locus.height_mm = -1.0;
  EXPECT_THROW(HalfEllipseFootPath(locus), std::invalid_argument);
}

TEST(JointTrajectory, InverseKinematicsOfEveryTick) {
  const LegGeometry g = testing::FrontLeftLeg();
  HalfEllipseLocus locus;
  locus.centre_mm = {70.0, 75.0, -115.0};
  const auto path = HalfEllipseFootPath(locus);
  const auto angles = JointTrajectoryDeg(g, path);
  ASSERT_EQ(angles.size(), path.size());
  for (size_t t = 0; t < path.size(); ++t) {
    const Eigen::Vector3d foot = ForwardKinematics(g, angles[t] * (std::numbers::pi / 180.0));
    EXPECT_LT((foot - path[t]).norm(), 1e-9) << t;
  }
}

TEST(JointTrajectory, UnreachableTickIsNamed) {
  const LegGeometry g = testing::FrontLeftLeg();
  std::vector<Eigen::Vector3d> path = {{60.0, 60.0, -120.0}, {60.0, 60.0, -300.0}};
  try {
    JointTrajectoryDeg(g, path);
    FAIL();
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("tick 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace leglab
