// Robots own their geometry: the kinematics the experiments use is read from each robot's URDF,
// and agrees with an independent forward kinematics of that URDF (ODE's body poses in
// sim::LegWorld) and with the published CMPack vectors.
#include "leglab/experiments/robot.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "leglab/core/units.h"
#include "leglab/experiments/config.h"
#include "leglab/sim/leg_world.h"

namespace leglab::experiments {
namespace {

std::string Urdf(const std::string& robot) {
  return std::string(LEGLAB_SOURCE_DIR) + "/robots/" + robot + "/leg.urdf";
}

struct Published {
  const char* robot;
  Eigen::Vector3d shoulder, upper, lower;
  double rotator_axis_y, knee_axis_y;
};

// ../shared/ers210a.md: the hind leg mirrors x, so its y axes flip.
const Published kLegs[] = {
    {"ers210a", {59.5, 59.2, 0.0}, {12.8, 0.5, -64.0}, {-18.88, 0.0, -66.0}, -1.0, 1.0},
    {"ers210a_hind", {-59.5, 59.2, 0.0}, {-12.8, 0.5, -64.0}, {29.36, 0.0, -70.88}, 1.0, -1.0},
};

void PrintTo(const Published& leg, std::ostream* out) { *out << leg.robot; }

class RobotTest : public ::testing::TestWithParam<Published> {};

TEST_P(RobotTest, GeometryIsThePublishedOne) {
  const Published& p = GetParam();
  const Robot robot = LoadRobot(Urdf(p.robot));
  const LegGeometry& g = robot.geometry;
  EXPECT_EQ(g.shoulder_mm, p.shoulder);  // exact: decimal metres rounded to the nanometre
  EXPECT_EQ(g.upper_leg_mm, p.upper);
  EXPECT_EQ(g.lower_leg_mm, p.lower);
  EXPECT_EQ(g.axes[kRotator], Eigen::Vector3d(0.0, p.rotator_axis_y, 0.0));
  EXPECT_EQ(g.axes[kAbductor], Eigen::Vector3d::UnitX());
  EXPECT_EQ(g.axes[kKnee], Eigen::Vector3d(0.0, p.knee_axis_y, 0.0));
  const double limits_deg[kLegJoints][2] = {{-117, 117}, {-11, 89}, {-27, 147}};
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_NEAR(RadToDeg(g.limits[j].lower_rad), limits_deg[j][0], 1e-8) << kLegJointNames[j];
    EXPECT_NEAR(RadToDeg(g.limits[j].upper_rad), limits_deg[j][1], 1e-8) << kLegJointNames[j];
  }
  EXPECT_EQ(g.OutwardSign(), 1.0);  // both are left legs
}

TEST_P(RobotTest, ForwardKinematicsAgreesWithTheSimulatedLeg) {
  const Robot robot = LoadRobot(Urdf(GetParam().robot));
  sim::LegWorld world(robot.urdf_path);
  std::mt19937_64 engine(42);
  for (int trial = 0; trial < 200; ++trial) {
    LegAngles q{};
    for (int j = 0; j < kLegJoints; ++j) {
      const JointLimits& lim = robot.geometry.limits[j];
      q[j] = std::uniform_real_distribution<double>(lim.lower_rad, lim.upper_rad)(engine);
    }
    world.SetConfigurationRad(q);
    const std::array<double, 3> foot = world.LinkOriginMm("foot");
    const Eigen::Vector3d model = ForwardKinematics(robot.geometry, {q[0], q[1], q[2]});
    EXPECT_LT((model - Eigen::Vector3d(foot[0], foot[1], foot[2])).norm(), 1e-6)
        << GetParam().robot << " trial " << trial;
  }
}

INSTANTIATE_TEST_SUITE_P(Robots, RobotTest, ::testing::ValuesIn(kLegs),
                         [](const ::testing::TestParamInfo<Published>& leg) {
                           return std::string(leg.param.robot);
                         });

TEST(Robot, ALegTheKinematicsCannotSolveIsBadInput) {
  // The front leg with its knee turned about z: read, and refused by name.
  const std::string path = ::testing::TempDir() + "/leglab_robot_test_twisted.urdf";
  std::string text;
  {
    std::ifstream in(Urdf("ers210a"));
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string knee_axis = "<axis xyz=\"0 1 0\"/>";
  ASSERT_NE(text.find(knee_axis), std::string::npos);
  text.replace(text.find(knee_axis), knee_axis.size(), "<axis xyz=\"0 0 1\"/>");
  std::ofstream(path) << text;
  try {
    LoadRobot(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("knee axis"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadRobot("/nonexistent/leg.urdf"), InputError);
}

}  // namespace
}  // namespace leglab::experiments
