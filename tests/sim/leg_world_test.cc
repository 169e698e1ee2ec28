#include "leglab/sim/leg_world.h"

#include <gtest/gtest.h>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "temp_urdf.h"

namespace leglab::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
const std::string kUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";
const std::string kHindUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a_hind/leg.urdf";

// An ERS-210A left leg written out by hand from the robot notes (ers210a.md), independent of
// the URDF: the CMPack'02 vectors, mm, and the joint axes in the body frame at q = 0.
struct HandLeg {
  std::string name;
  std::string urdf;
  Eigen::Vector3d shoulder;   // body centre -> J1/J2
  Eigen::Vector3d upper_leg;  // J1/J2 -> knee
  Eigen::Vector3d lower_leg;  // knee -> ball of the foot
  std::array<Eigen::Vector3d, kLegJoints> axes;
  Eigen::Vector3d foot_at_zero;  // shoulder + upper_leg + lower_leg, summed by hand
  // Which way the paw moves along x (+1 forward, -1 backward) when the rotator, resp. the
  // knee, turns positive from q = 0.
  double rotator_paw_dx_sign;
  double knee_paw_dx_sign;
};

// Rotator + swings the front paw forward (axis -y); abductor + outward (+x); knee + flexes
// (+y), swinging the paw backward.
const HandLeg kFrontLeg{
    "Front",
    kUrdf,
    {59.5, 59.2, 0.0},
    {12.8, 0.5, -64.0},
    {-18.88, 0.0, -66.0},
    {-Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()},
    {59.5 + 12.8 - 18.88, 59.2 + 0.5 + 0.0, 0.0 - 64.0 - 66.0},
    +1.0,
    -1.0};

// The hind leg mirrors x: its axes about y flip. Rotator + swings the hind paw backward (+y);
// abductor + outward (+x); knee + flexes (-y), swinging the paw forward.
const HandLeg kHindLeg{
    "Hind",
    kHindUrdf,
    {-59.5, 59.2, 0.0},
    {-12.8, 0.5, -64.0},
    {29.36, 0.0, -70.88},
    {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()},
    {-59.5 - 12.8 + 29.36, 59.2 + 0.5 + 0.0, 0.0 - 64.0 - 70.88},
    -1.0,
    +1.0};

//   foot = shoulder + R(a1, q1) R(a2, q2) (upper_leg + R(a3, q3) lower_leg), mm.
Eigen::Vector3d HandFootMm(const HandLeg& leg, const LegAngles& q_rad) {
  const auto turn = [&leg](int joint, double angle) {
    return Eigen::AngleAxisd(angle, leg.axes[joint]);
  };
  return leg.shoulder +
         turn(kRotator, q_rad[0]) *
             (turn(kAbductor, q_rad[1]) * (leg.upper_leg + turn(kKnee, q_rad[2]) * leg.lower_leg));
}

Eigen::Vector3d ToEigenVector(const std::array<double, 3>& v) {
  return Eigen::Vector3d(v[0], v[1], v[2]);
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

// ---- Front and hind: the URDF against the hand kinematics ----------------------------------

// Each leg on each engine: both place the bodies from the same description, DART through its
// own joint chain.
struct KinematicsCase {
  HandLeg leg;
  PhysicsEngine engine = PhysicsEngine::kOde;
};

// gtest prints a failing test's parameter with this.
void PrintTo(const KinematicsCase& c, std::ostream* out) {
  *out << c.leg.name << " leg on " << kPhysicsEngineNames[static_cast<size_t>(c.engine)];
}

class LegKinematicsTest : public ::testing::TestWithParam<KinematicsCase> {};

TEST_P(LegKinematicsTest, ReadsJointsAndLimitsFromTheUrdf) {
  const LegWorld world(GetParam().leg.urdf, {}, GetParam().engine);
  const double limits_deg[3][2] = {{-117, 117}, {-11, 89}, {-27, 147}};
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_EQ(world.joint(j).name, kLegJointNames[j]);
    EXPECT_NEAR(world.joint(j).lower_rad, limits_deg[j][0] * kDeg, 1e-9);
    EXPECT_NEAR(world.joint(j).upper_rad, limits_deg[j][1] * kDeg, 1e-9);
    EXPECT_DOUBLE_EQ(world.joint(j).effort_nm, 5.45);
  }
  EXPECT_EQ(world.AnglesRad(), (LegAngles{0.0, 0.0, 0.0}));
}

TEST_P(LegKinematicsTest, FootAtZeroIsTheSumOfTheLinkVectors) {
  const auto& [leg, physics] = GetParam();
  const LegWorld world(leg.urdf, {}, physics);
  EXPECT_LT((FootMm(world) - leg.foot_at_zero).norm(), 1e-9);
  EXPECT_LT((HandFootMm(leg, LegAngles{}) - leg.foot_at_zero).norm(), 1e-12);
}

TEST_P(LegKinematicsTest, FootFromBodyPosesMatchesHandKinematicsAtRandomAngles) {
  const auto& [leg, physics] = GetParam();
  LegWorld world(leg.urdf, {}, physics);
  std::mt19937_64 engine(2024);
  for (int trial = 0; trial < 200; ++trial) {
    const LegAngles q = RandomAnglesRad(world, engine);
    world.SetConfigurationRad(q);
    // The bodies are placed from the URDF's transforms: only round-off separates the two.
    EXPECT_LT((FootMm(world) - HandFootMm(leg, q)).norm(), 1e-9)
        << "q = " << q[0] << ", " << q[1] << ", " << q[2] << " rad";
  }
}

TEST_P(LegKinematicsTest, HingeAngleEqualsUrdfJointAngle) {
  LegWorld world(GetParam().leg.urdf, {}, GetParam().engine);
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

// ODE's hinge sign depends on attach order and axis direction, DART's on its joint's frames:
// drive each joint alone with its motor and check that the angle the engine reports grows, and that
// the foot lands where the hand kinematics puts it for that angle (so positive means what the URDF
// says).
TEST_P(LegKinematicsTest, MotorTurnsEachJointTheUrdfWay) {
  const auto& [leg, physics] = GetParam();
  for (int j = 0; j < kLegJoints; ++j) {
    LegWorld world(leg.urdf, {}, physics);
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
    EXPECT_LT((FootMm(world) - HandFootMm(leg, angles)).norm(), 0.1) << kLegJointNames[j];
    EXPECT_GT((FootMm(world) - HandFootMm(leg, start)).norm(), 5.0) << kLegJointNames[j];
  }
}

// The signs the robot notes give, read off the foot: rotator + swings the front paw forward and
// the hind paw backward, abductor + moves the paw outward (+y, left legs), knee + swings the
// front paw backward and the hind paw forward.
TEST_P(LegKinematicsTest, PositiveAnglesMoveThePawTheDocumentedWay) {
  const auto& [leg, physics] = GetParam();
  LegWorld world(leg.urdf, {}, physics);
  const Eigen::Vector3d at_zero = FootMm(world);
  const auto moved = [&world, &at_zero](const LegAngles& q) -> Eigen::Vector3d {
    world.SetConfigurationRad(q);
    return FootMm(world) - at_zero;
  };
  EXPECT_GT(leg.rotator_paw_dx_sign * moved({0.3, 0.0, 0.0}).x(), 10.0);
  EXPECT_GT(moved({0.0, 0.3, 0.0}).y(), 10.0);
  EXPECT_GT(leg.knee_paw_dx_sign * moved({0.0, 0.0, 0.3}).x(), 10.0);
}

// Each leg on each engine this build has (DART's cases not registered without it).
std::vector<KinematicsCase> KinematicsCases() {
  std::vector<KinematicsCase> cases{{kFrontLeg, PhysicsEngine::kOde},
                                    {kHindLeg, PhysicsEngine::kOde}};
  if (BuiltWithDart()) {
    cases.push_back({kFrontLeg, PhysicsEngine::kDart});
    cases.push_back({kHindLeg, PhysicsEngine::kDart});
  }
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Legs, LegKinematicsTest, ::testing::ValuesIn(KinematicsCases()),
                         [](const ::testing::TestParamInfo<KinematicsCase>& param_info) {
                           return param_info.param.leg.name +
                                  (param_info.param.engine == PhysicsEngine::kDart ? "Dart" : "");
                         });

// ---- The front leg's physics -------------------------------------------------------------

class EngineTest : public ::testing::TestWithParam<PhysicsEngine> {};

// The unpowered leg comes to rest with its knee on the -30 deg stop, so for a free swing the
// test moves the knee and abductor stops out of the way.
TEST_P(EngineTest, PassiveSwingNeverGainsEnergy) {
  const TempUrdf wide_stops(kUrdf, Edits{{R"(lower="-0.4712388980")", R"(lower="-2.0943951024")"},
                                         {R"(lower="-0.1919862177")", R"(lower="-0.6981317008")"}});
  LegWorld world(wide_stops.path(), {}, GetParam());
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
  // Both engines integrate semi-implicitly (symplectic Euler): the energy wobbles by O(dt)
  // around a slowly falling mean. Allow 1 % of the peak kinetic energy.
  EXPECT_LE(highest - initial, 0.01 * peak_kinetic)
      << "initial " << initial << " J, peak kinetic " << peak_kinetic << " J";
  RecordProperty("energy_gain_over_peak_kinetic",
                 std::to_string((highest - initial) / peak_kinetic));
}

// A hard swing against the real stops stays sound and loses energy in the inelastic hits.
TEST_P(EngineTest, PassiveSwingIntoTheStopsStaysSound) {
  LegWorld world(kUrdf, {}, GetParam());
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
      // Stops 3 deg beyond the limits, with a soft stop's penetration of a fraction of one.
      ASSERT_GE(angles[j], world.joint(j).lower_rad - 4.0 * kDeg) << kLegJointNames[j];
      ASSERT_LE(angles[j], world.joint(j).upper_rad + 4.0 * kDeg) << kLegJointNames[j];
    }
  }
  EXPECT_LE(highest - initial, 0.01 * peak_kinetic);
  EXPECT_LT(world.MechanicalEnergyJ(), initial - 0.5 * peak_kinetic);
}

// The leg as a compound pendulum: abductor and knee held at 0 by their motors, the rotator
// free. About its hanging rest angle, a swing of amplitude A has the period
// 4 sqrt(I / (M g d)) K(sin(A / 2)) (K the complete elliptic integral of the first kind), with
// the moment of inertia I about the rotator's axis, the mass M and the centre of mass's
// distance d from the axis summed here from the description's bodies, not from either engine.
TEST_P(EngineTest, RotatorSwingHasTheCompoundPendulumsPeriod) {
  LegWorld world(kUrdf, {}, GetParam());
  const LegDescription& leg = world.description();
  const Eigen::Vector3d axis = ToEigenVector(leg.joints[kRotator].axis);
  const Eigen::Vector3d pivot = ToEigenVector(leg.joints[kRotator].position_m);
  double mass = 0.0;
  double inertia = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  // sum of m (c - pivot)
  for (const BodyDescription& body : leg.bodies) {
    // At q = 0 every link frame is parallel to the root's (the URDF's joints have rpy 0), so
    // a link's origin is the sum of the joint origins above it.
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();
    for (int link = body.link; link > 0; link = leg.links[link].parent) {
      ASSERT_EQ(leg.links[link].origin.rotation, RigidTransform{}.rotation);
      origin += ToEigenVector(leg.links[link].origin.translation_m);
    }
    const Eigen::Vector3d r = origin + ToEigenVector(body.com_m) - pivot;
    Eigen::Matrix3d about_com;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) about_com(i, j) = body.inertia_kg_m2[i][j];
    }
    mass += body.mass_kg;
    moment += body.mass_kg * r;
    inertia += axis.dot(about_com * axis) + body.mass_kg * r.cross(axis).squaredNorm();
  }
  const Eigen::Vector3d off_axis = moment / mass - axis.dot(moment / mass) * axis;
  const double d = off_axis.norm();
  // The rest angle: the turn about the axis that puts the centre of mass straight below it.
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  const Eigen::Vector3d u = off_axis / d;
  const double rest = std::atan2(u.cross(down).dot(axis), u.dot(down));
  const double amplitude = 20.0 * kDeg;
  const double expected_s = 4.0 * std::sqrt(inertia / (mass * LegWorld::kGravityMPerS2 * d)) *
                            std::comp_ellint_1(std::sin(amplitude / 2.0));

  world.SetConfigurationRad({rest + amplitude, 0.0, 0.0});
  std::vector<double> upward_crossings_s;
  double previous = amplitude;
  for (int step = 1; step <= 4000; ++step) {  // 4 s at 1 ms
    world.SetMotor(kRotator, 0.0, 0.0);
    world.SetMotor(kAbductor, 0.0, 5.45);
    world.SetMotor(kKnee, 0.0, 5.45);
    world.Step(0.001);
    const double angle = world.AnglesRad()[kRotator] - rest;
    if (previous < 0.0 && angle >= 0.0) {
      upward_crossings_s.push_back(0.001 * (step - angle / (angle - previous)));
    }
    previous = angle;
    ASSERT_LT(std::abs(world.AnglesRad()[kKnee]), 1e-3);
  }
  ASSERT_GE(upward_crossings_s.size(), 4u);
  const double period_s = (upward_crossings_s.back() - upward_crossings_s.front()) /
                          static_cast<double>(upward_crossings_s.size() - 1);
  // Symplectic Euler at 1 ms on a period of about 0.6 s: a relative phase error of order
  // (w dt)^2 / 24, about 4e-6; the held joints' motors are constraints, not springs.
  EXPECT_NEAR(period_s, expected_s, 1e-4 * expected_s) << "rest angle " << rest / kDeg << " deg";
  RecordProperty("period_s", std::to_string(period_s));
  RecordProperty("expected_period_s", std::to_string(expected_s));
}

// The engines this build has (DART's cases not registered without it).
std::vector<PhysicsEngine> BuiltEngines() {
  if (BuiltWithDart()) return {PhysicsEngine::kOde, PhysicsEngine::kDart};
  return {PhysicsEngine::kOde};
}

INSTANTIATE_TEST_SUITE_P(Engines, EngineTest, ::testing::ValuesIn(BuiltEngines()),
                         [](const ::testing::TestParamInfo<PhysicsEngine>& param_info) {
                           return std::string(
                               kPhysicsEngineNames[static_cast<size_t>(param_info.param)]);
                         });

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

// A build without DART refuses the engine in one line naming the key (sim_config_test.cc: the
// config's check).
TEST(LegWorldTest, DartInABuildWithoutItIsRefusedNamingTheKey) {
  if (BuiltWithDart()) GTEST_SKIP() << "this build has DART";
  try {
    const LegWorld world(kUrdf, {}, PhysicsEngine::kDart);
    ADD_FAILURE() << "a build without DART built a DART world";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("sim.engine: dart, but this build", 0), 0u)
        << error.what();
  }
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

// A mass LoadLegDescription refuses (1e-30 kg) makes ODE fail an internal assertion mid-step;
// its message comes out as an exception instead of abort(), and ODE stays usable afterwards.
TEST(LegWorldTest, OdeFailureThrowsItsMessageInsteadOfAborting) {
  LegDescription leg = LoadLegDescription(kUrdf);
  leg.bodies[1].mass_kg = 1e-30;  // upper_leg
  std::string message = "no error";
  try {
#if defined(__SANITIZE_ADDRESS__)
    // ODE's step loses the job list it allocated when the error unwinds through it, and a
    // broken world is left unfreed on purpose (OdeWorld::Release): not leaks of this test's.
    const __lsan::ScopedDisabler leaks_of_the_failed_step;
#endif
    LegWorld world(leg);
    world.SetConfigurationRad({40.0 * kDeg, 10.0 * kDeg, 30.0 * kDeg});
    for (int j = 0; j < kLegJoints; ++j) world.SetMotor(j, 1.0, 5.45);
    for (int step = 0; step < 3000; ++step) world.Step(0.001);
  } catch (const std::runtime_error& error) {
    message = error.what();
  }
  EXPECT_NE(message.find("ODE internal error"), std::string::npos) << message;
  EXPECT_NE(message.find("assertion"), std::string::npos) << message;
  LegWorld sound(kUrdf);
  sound.SetConfigurationRad({40.0 * kDeg, 10.0 * kDeg, 30.0 * kDeg});
  for (int step = 0; step < 100; ++step) sound.Step(0.001);
  EXPECT_TRUE(sound.StateProblem().empty()) << sound.StateProblem();
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
