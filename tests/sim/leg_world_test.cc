#include "leglab/sim/leg_world.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "temp_urdf.h"

namespace leglab::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const std::string kUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";

// The ERS-210A front-left kinematics written out by hand from the robot notes, independent of
// the URDF and of leglab::model:
//   foot = shoulder + Ry(-q1) Rx(q2) (upper_leg + Ry(q3) lower_leg), mm.
Eigen::Vector3d HandFootMm(const LegAngles& q_rad) {
  const Eigen::Vector3d shoulder(59.5, 59.2, 0.0);
  const Eigen::Vector3d upper_leg(12.8, 0.5, -64.0);
  const Eigen::Vector3d lower_leg(-18.88, 0.0, -66.0);
  const auto ry = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()); };
  const auto rx = [](double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()); };
  return shoulder + ry(-q_rad[0]) * (rx(q_rad[1]) * (upper_leg + ry(q_rad[2]) * lower_leg));
}

Eigen::Vector3d FootMm(const LegWorld& world) {
  const auto foot = world.LinkOriginMm("foot");
  return Eigen::Vector3d(foot[0], foot[1], foot[2]);
}

LegAngles RandomAnglesRad(const LegWorld& world, std::mt19937_64& engine) {
  LegAngles q{};
  for (int j = 0; j < kLegJoints; ++j) {
    q[j] = std::uniform_real_distribution<double>(world.joint(j).lower_rad,
                                                  world.joint(j).upper_rad)(engine);
  }
  return q;
}

using testing::Edits;
using testing::TempUrdf;

template <typename Error>
std::string ErrorOf(const std::string& path) {
  try {
    LegWorld world(path);
  } catch (const Error& error) {
    return error.what();
  }
  return "no error";
}

template <typename Error>
std::string ErrorOf(const TempUrdf& urdf) {
  return ErrorOf<Error>(urdf.path());
}

TEST(LegWorldTest, ReadsJointsAndLimitsFromTheUrdf) {
  const LegWorld world(kUrdf);
  const double limits_deg[3][2] = {{-117, 117}, {-11, 89}, {-27, 147}};
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_EQ(world.joint(j).name, kLegJointNames[j]);
    EXPECT_NEAR(world.joint(j).lower_rad, limits_deg[j][0] * kDeg, 1e-9);
    EXPECT_NEAR(world.joint(j).upper_rad, limits_deg[j][1] * kDeg, 1e-9);
    EXPECT_DOUBLE_EQ(world.joint(j).effort_nm, 5.45);
  }
  EXPECT_EQ(world.AnglesRad(), (LegAngles{0.0, 0.0, 0.0}));
}

TEST(LegWorldTest, FootAtZeroIsTheSumOfTheLinkVectors) {
  const LegWorld world(kUrdf);
  // (59.5 + 12.8 - 18.88, 59.2 + 0.5 + 0, 0 - 64 - 66) mm.
  EXPECT_LT((FootMm(world) - Eigen::Vector3d(53.42, 59.7, -130.0)).norm(), 1e-9);
}

TEST(LegWorldTest, FootFromBodyPosesMatchesHandKinematicsAtRandomAngles) {
  LegWorld world(kUrdf);
  std::mt19937_64 engine(2024);
  for (int trial = 0; trial < 200; ++trial) {
    const LegAngles q = RandomAnglesRad(world, engine);
    world.SetConfigurationRad(q);
    EXPECT_LT((FootMm(world) - HandFootMm(q)).norm(), 0.1)
        << "q = " << q[0] << ", " << q[1] << ", " << q[2] << " rad";
  }
}

TEST(LegWorldTest, HingeAngleEqualsUrdfJointAngle) {
  LegWorld world(kUrdf);
  std::mt19937_64 engine(7);
  for (int trial = 0; trial < 50; ++trial) {
    const LegAngles q = RandomAnglesRad(world, engine);
    world.SetConfigurationRad(q);
    const LegAngles angles = world.AnglesRad();
    for (int j = 0; j < kLegJoints; ++j) {
      EXPECT_NEAR(angles[j], q[j], 1e-9) << kLegJointNames[j];
    }
  }
}

// ODE's hinge sign depends on attach order and axis direction: drive each joint alone with
// its motor and check that the angle ODE reports grows, and that the foot lands where the
// hand kinematics puts it for that angle (so positive means what the URDF says).
TEST(LegWorldTest, MotorTurnsEachJointTheUrdfWay) {
  for (int j = 0; j < kLegJoints; ++j) {
    LegWorld world(kUrdf);
    LegAngles start{0.0, 20.0 * kDeg, 30.0 * kDeg};
    world.SetConfigurationRad(start);
    for (int step = 0; step < 200; ++step) {  // 0.2 s at 1 rad/s
      for (int k = 0; k < kLegJoints; ++k) {
        world.SetMotor(k, k == j ? 1.0 : 0.0, 5.45);
      }
      world.Step(0.001);
    }
    const LegAngles angles = world.AnglesRad();
    EXPECT_NEAR(angles[j] - start[j], 0.2, 1e-3) << kLegJointNames[j];
    EXPECT_LT((FootMm(world) - HandFootMm(angles)).norm(), 0.1) << kLegJointNames[j];
    EXPECT_GT((FootMm(world) - HandFootMm(start)).norm(), 5.0) << kLegJointNames[j];
  }
}

// The unpowered leg comes to rest with its knee on the -30 deg stop, so for a free swing the
// test moves the knee and abductor stops out of the way.
TEST(LegWorldTest, PassiveSwingNeverGainsEnergy) {
  const TempUrdf wide_stops(kUrdf, Edits{{R"(lower="-0.4712388980")", R"(lower="-2.0943951024")"},
                                         {R"(lower="-0.1919862177")", R"(lower="-0.6981317008")"}});
  LegWorld world(wide_stops.path());
  world.SetConfigurationRad({40.0 * kDeg, 10.0 * kDeg, 30.0 * kDeg});
  const double initial = world.MechanicalEnergyJ();
  double highest = initial;
  double peak_kinetic = 0.0;
  LegAngles lowest{};
  for (int step = 0; step < 3000; ++step) {  // 3 s at 1 ms
    world.Step(0.001);
    highest = std::max(highest, world.MechanicalEnergyJ());
    peak_kinetic = std::max(peak_kinetic, world.KineticEnergyJ());
    const LegAngles angles = world.AnglesRad();
    for (int j = 0; j < kLegJoints; ++j) {
      lowest[j] = std::min(lowest[j], angles[j]);
    }
    ASSERT_TRUE(world.StateProblem().empty()) << world.StateProblem();
  }
  EXPECT_GT(peak_kinetic, 0.01);  // a real swing, J
  // Clear of the (moved) stops, so only integration is at work.
  EXPECT_GT(lowest[1], -40.0 * kDeg);
  EXPECT_GT(lowest[2], -120.0 * kDeg);
  // dWorldStep is semi-implicit Euler: its energy wobbles by O(dt) around a slowly falling
  // mean (about 0.35 % of the peak kinetic energy at 1 ms, measured). Allow 1 %.
  EXPECT_LE(highest - initial, 0.01 * peak_kinetic)
      << "initial " << initial << " J, peak kinetic " << peak_kinetic << " J";
  RecordProperty("energy_gain_over_peak_kinetic",
                 std::to_string((highest - initial) / peak_kinetic));
}

// A hard swing against the real stops stays sound and loses energy in the inelastic hits.
TEST(LegWorldTest, PassiveSwingIntoTheStopsStaysSound) {
  LegWorld world(kUrdf);
  world.SetConfigurationRad({90.0 * kDeg, 60.0 * kDeg, 120.0 * kDeg});
  const double initial = world.MechanicalEnergyJ();
  double highest = initial;
  double peak_kinetic = 0.0;
  for (int step = 0; step < 3000; ++step) {
    world.Step(0.001);
    highest = std::max(highest, world.MechanicalEnergyJ());
    peak_kinetic = std::max(peak_kinetic, world.KineticEnergyJ());
    ASSERT_TRUE(world.StateProblem().empty()) << world.StateProblem();
    const LegAngles angles = world.AnglesRad();
    for (int j = 0; j < kLegJoints; ++j) {
      // Stops 3 deg beyond the limits, with ODE's soft-stop penetration of a fraction of one.
      ASSERT_GE(angles[j], world.joint(j).lower_rad - 4.0 * kDeg) << kLegJointNames[j];
      ASSERT_LE(angles[j], world.joint(j).upper_rad + 4.0 * kDeg) << kLegJointNames[j];
    }
  }
  EXPECT_LE(highest - initial, 0.01 * peak_kinetic);
  EXPECT_LT(world.MechanicalEnergyJ(), initial - 0.5 * peak_kinetic);
}

// ---- Errors name the item --------------------------------------------------------------

// The URDF checks are LoadLegDescription's (leg_description_test.cc); the path constructor
// passes its errors on.
TEST(LegWorldTest, PathConstructorPassesOnTheDescriptionsErrors) {
  const std::string missing = ErrorOf<std::runtime_error>("/nonexistent/leg.urdf");
  EXPECT_NE(missing.find("/nonexistent/leg.urdf"), std::string::npos) << missing;
  const std::string knee = ErrorOf<std::invalid_argument>(
      TempUrdf(kUrdf, R"(joint name="knee")", R"(joint name="knie")"));
  EXPECT_NE(knee.find("joint 'knee' not found"), std::string::npos) << knee;
}

TEST(LegWorldTest, BuiltFromADescriptionAsFromItsUrdf) {
  const LegDescription leg = LoadLegDescription(kUrdf);
  LegWorld from_description(leg);
  LegWorld from_path(kUrdf);
  EXPECT_EQ(from_description.description().urdf_path, kUrdf);
  const LegAngles q{0.3, 0.4, 1.2};
  from_description.SetConfigurationRad(q);
  from_path.SetConfigurationRad(q);
  EXPECT_EQ(from_description.LinkOriginMm("foot"), from_path.LinkOriginMm("foot"));
  // At q = 0 the world puts the foot where the description says.
  from_description.SetConfigurationRad(LegAngles{});
  const auto foot_mm = from_description.LinkOriginMm("foot");
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(foot_mm[i], 1000.0 * leg.foot_position_m[i], 1e-9);
  }
}

TEST(LegWorldTest, DescriptionThatIsNotATreeIsRejected) {
  LegDescription leg = LoadLegDescription(kUrdf);
  leg.links[3].joint = kAbductor;  // the knee's link claims the abductor: two links, no knee
  try {
    LegWorld world(leg);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("joint 'abductor' must move exactly one link"),
              std::string::npos)
        << error.what();
  }
}

TEST(LegWorldTest, MassOdeRejectsNamesTheLink) {
  LegDescription leg = LoadLegDescription(kUrdf);
  leg.bodies[1].inertia_kg_m2[0][0] = -1.0;  // upper_leg; LoadLegDescription never gives this
  try {
    LegWorld world(leg);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("link 'upper_leg': ODE rejects"), std::string::npos)
        << error.what();
  }
}

TEST(LegWorldTest, UnknownLinkIsNamed) {
  const LegWorld world(kUrdf);
  try {
    world.LinkOriginMm("tail");
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'tail'"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace leglab::sim
