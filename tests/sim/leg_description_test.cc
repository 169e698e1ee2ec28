// LoadLegDescription: the URDF as plain data, checked. No physics engine is involved: these
// tests call no ODE function. The expected numbers are worked by hand from the CMPack'02
// vectors in the robot notes (ers210a.md), not read from the code under test.
#include "leglab/sim/leg_description.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "temp_urdf.h"

namespace leglab::sim {
namespace {

using testing::Edits;
using testing::TempUrdf;

const std::string kFrontUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";
const std::string kHindUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a_hind/leg.urdf";

using Vec = std::array<double, 3>;
using Mat = std::array<std::array<double, 3>, 3>;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

Vec Mm(const Vec& m) { return {1000.0 * m[0], 1000.0 * m[1], 1000.0 * m[2]}; }

double Distance(const Vec& a, const Vec& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

Vec Times(const Mat& m, const Vec& v) {
  Vec product{};
  for (int i = 0; i < 3; ++i) {
    product[i] = m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2];
  }
  return product;
}

Vec Scaled(double s, const Vec& v) { return {s * v[0], s * v[1], s * v[2]}; }

Vec Unit(const Vec& v) { return Scaled(1.0 / std::hypot(v[0], v[1], v[2]), v); }

const BodyDescription& BodyOfLink(const LegDescription& leg, const std::string& link) {
  const int index = leg.FindLink(link);
  EXPECT_GE(index, 0) << link;
  return leg.bodies.at(leg.links.at(index).body);
}

template <typename Error>
std::string ErrorOf(const std::string& path) {
  try {
    LoadLegDescription(path);
  } catch (const Error& error) {
    return error.what();
  }
  return "no error";
}

template <typename Error>
std::string ErrorOf(const TempUrdf& urdf) {
  return ErrorOf<Error>(urdf.path());
}

// ---- The front leg at q = 0 ---------------------------------------------------------------

TEST(LegDescriptionTest, FrontLegJointsAndFootAtZero) {
  const LegDescription leg = LoadLegDescription(kFrontUrdf);
  EXPECT_EQ(leg.urdf_path, kFrontUrdf);
  EXPECT_EQ(leg.robot_name, "ers210a_front_left_leg");
  // shoulder = (59.5, 59.2, 0); knee = shoulder + upper leg (12.8, 0.5, -64);
  // foot = knee + lower leg (-18.88, 0, -66), mm.
  const Vec shoulder{59.5, 59.2, 0.0};
  const Vec knee{59.5 + 12.8, 59.2 + 0.5, 0.0 - 64.0};
  const Vec foot{59.5 + 12.8 - 18.88, 59.2 + 0.5 + 0.0, 0.0 - 64.0 - 66.0};
  const std::array<Vec, kLegJoints> positions{shoulder, shoulder, knee};
  // Rotator + swings the paw forward (about -y), abductor + outward (+x), knee + flexes (+y).
  const std::array<Vec, kLegJoints> axes{Vec{0, -1, 0}, Vec{1, 0, 0}, Vec{0, 1, 0}};
  for (int j = 0; j < kLegJoints; ++j) {
    const JointDescription& joint = leg.joints[j];
    EXPECT_EQ(joint.name, kLegJointNames[j]);
    EXPECT_LT(Distance(Mm(joint.position_m), positions[j]), 1e-9) << joint.name;
    EXPECT_LT(Distance(joint.axis, axes[j]), 1e-12) << joint.name;
  }
  EXPECT_LT(Distance(Mm(leg.foot_position_m), foot), 1e-9);
}

TEST(LegDescriptionTest, FrontLegLimitsAndRatings) {
  const LegDescription leg = LoadLegDescription(kFrontUrdf);
  const double limits_deg[kLegJoints][2] = {{-117, 117}, {-11, 89}, {-27, 147}};
  for (int j = 0; j < kLegJoints; ++j) {
    const JointDescription& joint = leg.joints[j];
    // The URDF gives radians to 10 decimals.
    EXPECT_NEAR(joint.lower_rad, limits_deg[j][0] * kDeg, 1e-9) << joint.name;
    EXPECT_NEAR(joint.upper_rad, limits_deg[j][1] * kDeg, 1e-9) << joint.name;
    EXPECT_DOUBLE_EQ(joint.effort_nm, 5.45) << joint.name;
    // 2.5 deg per 8 ms tick.
    EXPECT_NEAR(joint.velocity_rad_per_s, 2.5 * kDeg / 0.008, 1e-6) << joint.name;
  }
}

TEST(LegDescriptionTest, LinksDepthFirstWithFixedLinksRidingOnTheirParentsBody) {
  const LegDescription leg = LoadLegDescription(kFrontUrdf);
  const std::array<std::string, 5> names{"body", "rotator_housing", "upper_leg", "lower_leg",
                                         "foot"};
  const std::array<int, 5> parents{-1, 0, 1, 2, 3};
  const std::array<int, 5> joints{-1, kRotator, kAbductor, kKnee, -1};
  const std::array<int, 5> bodies{-1, 0, 1, 2, 2};
  ASSERT_EQ(leg.links.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(leg.links[i].name, names[i]);
    EXPECT_EQ(leg.links[i].parent, parents[i]) << names[i];
    EXPECT_EQ(leg.links[i].joint, joints[i]) << names[i];
    EXPECT_EQ(leg.links[i].body, bodies[i]) << names[i];
    EXPECT_EQ(leg.FindLink(names[i]), static_cast<int>(i));
  }
  EXPECT_EQ(leg.FindLink("tail"), -1);
  ASSERT_EQ(leg.bodies.size(), 3u);
  for (int b = 0; b < 3; ++b) {
    EXPECT_EQ(leg.bodies[b].link, b + 1);
  }
  // The foot frame sits at the end of the lower leg vector, in the lower leg's frame.
  EXPECT_LT(Distance(Mm(leg.links[4].in_body.translation_m), Vec{-18.88, 0.0, -66.0}), 1e-9);
  // The joint origins: shoulder, then none for the abductor, then the upper leg vector.
  EXPECT_LT(Distance(Mm(leg.links[1].origin.translation_m), Vec{59.5, 59.2, 0.0}), 1e-9);
  EXPECT_LT(Distance(Mm(leg.links[3].origin.translation_m), Vec{12.8, 0.5, -64.0}), 1e-9);
}

// ---- The hind leg at q = 0 ----------------------------------------------------------------

TEST(LegDescriptionTest, HindLegJointsAndFootAtZero) {
  const LegDescription leg = LoadLegDescription(kHindUrdf);
  EXPECT_EQ(leg.robot_name, "ers210a_hind_left_leg");
  // hip = (-59.5, 59.2, 0); knee = hip + upper leg (-12.8, 0.5, -64);
  // foot = knee + lower leg (29.36, 0, -70.88), mm.
  const Vec hip{-59.5, 59.2, 0.0};
  const Vec knee{-59.5 - 12.8, 59.2 + 0.5, 0.0 - 64.0};
  const Vec foot{-59.5 - 12.8 + 29.36, 59.2 + 0.5 + 0.0, 0.0 - 64.0 - 70.88};
  const std::array<Vec, kLegJoints> positions{hip, hip, knee};
  // Mirrored in x, the axes about y flip: rotator +y (+ swings the paw backward), abductor +x
  // (+ outward), knee -y (+ flexes, swinging the paw forward).
  const std::array<Vec, kLegJoints> axes{Vec{0, 1, 0}, Vec{1, 0, 0}, Vec{0, -1, 0}};
  for (int j = 0; j < kLegJoints; ++j) {
    const JointDescription& joint = leg.joints[j];
    EXPECT_EQ(joint.name, kLegJointNames[j]);
    EXPECT_LT(Distance(Mm(joint.position_m), positions[j]), 1e-9) << joint.name;
    EXPECT_LT(Distance(joint.axis, axes[j]), 1e-12) << joint.name;
  }
  EXPECT_LT(Distance(Mm(leg.foot_position_m), foot), 1e-9);
}

// The same servos: limits and ratings exactly the front leg's; the same stand-in masses.
TEST(LegDescriptionTest, HindLegHasTheFrontLegsLimitsRatingsAndMasses) {
  const LegDescription front = LoadLegDescription(kFrontUrdf);
  const LegDescription hind = LoadLegDescription(kHindUrdf);
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_EQ(hind.joints[j].lower_rad, front.joints[j].lower_rad) << kLegJointNames[j];
    EXPECT_EQ(hind.joints[j].upper_rad, front.joints[j].upper_rad) << kLegJointNames[j];
    EXPECT_EQ(hind.joints[j].effort_nm, front.joints[j].effort_nm) << kLegJointNames[j];
    EXPECT_EQ(hind.joints[j].velocity_rad_per_s, front.joints[j].velocity_rad_per_s)
        << kLegJointNames[j];
  }
  ASSERT_EQ(hind.bodies.size(), front.bodies.size());
  for (std::size_t b = 0; b < hind.bodies.size(); ++b) {
    EXPECT_EQ(hind.bodies[b].mass_kg, front.bodies[b].mass_kg);
  }
}

// ---- Masses ----------------------------------------------------------------------------------

// The root (body, 0.613 kg) is fixed to the world and belongs to no body; the three moving
// links carry the URDF's other masses.
TEST(LegDescriptionTest, LumpedMassEqualsTheSumOfTheUrdfMasses) {
  const LegDescription leg = LoadLegDescription(kFrontUrdf);
  double total_kg = 0.0;
  for (const BodyDescription& body : leg.bodies) {
    total_kg += body.mass_kg;
  }
  EXPECT_NEAR(total_kg, 0.05 + 0.073 + 0.073, 1e-15);
  EXPECT_DOUBLE_EQ(BodyOfLink(leg, "rotator_housing").mass_kg, 0.05);
  EXPECT_DOUBLE_EQ(BodyOfLink(leg, "upper_leg").mass_kg, 0.073);
  EXPECT_DOUBLE_EQ(BodyOfLink(leg, "lower_leg").mass_kg, 0.073);
}

// Give the foot frame a 10 g point-like mass: it joins the lower leg's body, which gains its
// mass, moves its centre of mass towards it and gains the parallel-axis terms.
TEST(LegDescriptionTest, FixedChildWithMassIsLumpedIntoItsMovingParent) {
  const TempUrdf urdf(kFrontUrdf, R"(<link name="foot"/>)",
                      R"(<link name="foot"><inertial><origin xyz="0 0 0"/><mass value="0.01"/>)"
                      R"(<inertia ixx="1e-07" ixy="0" ixz="0" iyy="1e-07" iyz="0" izz="1e-07"/>)"
                      R"(</inertial></link>)");
  const LegDescription leg = LoadLegDescription(urdf.path());
  const BodyDescription& lower = BodyOfLink(leg, "lower_leg");
  EXPECT_EQ(&BodyOfLink(leg, "foot"), &lower);
  EXPECT_NEAR(lower.mass_kg, 0.073 + 0.01, 1e-15);
  // Centres of mass in the lower leg's frame, m: its own (URDF <inertial> origin) and the
  // foot's (the foot_joint origin).
  const double x1 = -0.011001, z1 = -0.038457, m1 = 0.073;
  const double x2 = -0.01888, z2 = -0.066, m2 = 0.01;
  const double cx = (m1 * x1 + m2 * x2) / (m1 + m2);
  const double cz = (m1 * z1 + m2 * z2) / (m1 + m2);
  EXPECT_LT(Distance(lower.com_m, Vec{cx, 0.0, cz}), 1e-15);
  // About y: the lower leg's rod inertia is turned about y only, so its iyy is unchanged;
  // add the foot's and both parallel-axis terms m d^2 (d in the x-z plane).
  const double iyy = 3.12954e-05 + 1e-07 + m1 * ((x1 - cx) * (x1 - cx) + (z1 - cz) * (z1 - cz)) +
                     m2 * ((x2 - cx) * (x2 - cx) + (z2 - cz) * (z2 - cz));
  EXPECT_NEAR(lower.inertia_kg_m2[1][1], iyy, 1e-15);
  // The pieces lie in the x-z plane: no xy or yz products.
  EXPECT_NEAR(lower.inertia_kg_m2[0][1], 0.0, 1e-18);
  EXPECT_NEAR(lower.inertia_kg_m2[1][2], 0.0, 1e-18);
}

// Each leg segment is a rod of radius 12 mm along the segment with its centre of mass 40 mm
// down it: the inertia about the segment axis is m r^2 / 2, across it m (3 r^2 + L^2) / 12.
struct Segment {
  const char* link;
  Vec vector_mm;  // the segment, from its joint, robot notes
};

void ExpectRodAlong(const LegDescription& leg, const Segment& segment) {
  const BodyDescription& body = BodyOfLink(leg, segment.link);
  const Vec u = Unit(segment.vector_mm);
  EXPECT_LT(Distance(Mm(body.com_m), Scaled(40.0, u)), 1e-3) << segment.link;  // 6 decimals in m
  const double m = 0.073, r = 0.012;
  const double length_m =
      std::hypot(segment.vector_mm[0], segment.vector_mm[1], segment.vector_mm[2]) / 1000.0;
  const double along = m * r * r / 2.0;
  const double across = m * (3.0 * r * r + length_m * length_m) / 12.0;
  EXPECT_LT(Distance(Times(body.inertia_kg_m2, u), Scaled(along, u)), 1e-11) << segment.link;
  // A direction across the segment: u x (0, 1, 0) normalised (no segment lies along y).
  const Vec w = Unit(Vec{-u[2], 0.0, u[0]});
  EXPECT_LT(Distance(Times(body.inertia_kg_m2, w), Scaled(across, w)), 1e-10) << segment.link;
}

TEST(LegDescriptionTest, FrontSegmentsAreRodsAlongTheSegments) {
  const LegDescription leg = LoadLegDescription(kFrontUrdf);
  ExpectRodAlong(leg, {"upper_leg", {12.8, 0.5, -64.0}});
  ExpectRodAlong(leg, {"lower_leg", {-18.88, 0.0, -66.0}});
}

// Checks the hind URDF's worked inertial origins and rpy (see its header comment).
TEST(LegDescriptionTest, HindSegmentsAreRodsAlongTheSegments) {
  const LegDescription leg = LoadLegDescription(kHindUrdf);
  ExpectRodAlong(leg, {"upper_leg", {-12.8, 0.5, -64.0}});
  ExpectRodAlong(leg, {"lower_leg", {29.36, 0.0, -70.88}});
}

// ---- Errors name the item ---------------------------------------------------------------

TEST(LegDescriptionTest, MissingFileNamesTheFile) {
  const std::string message = ErrorOf<std::runtime_error>("/nonexistent/leg.urdf");
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
  EXPECT_NE(message.find("/nonexistent/leg.urdf"), std::string::npos) << message;
}

TEST(LegDescriptionTest, MalformedXmlNamesTheFileAndTheReason) {
  const TempUrdf urdf(kFrontUrdf, "</robot>", "");
  const std::string message = ErrorOf<std::runtime_error>(urdf.path());
  EXPECT_NE(message.find("failed to parse URDF file '" + urdf.path() + "'"), std::string::npos)
      << message;
}

TEST(LegDescriptionTest, MissingJointNamesTheJoint) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(joint name="knee")", R"(joint name="knie")"));
  EXPECT_NE(message.find("joint 'knee' not found"), std::string::npos) << message;
}

TEST(LegDescriptionTest, FixedJointWhereAHingeBelongsNamesTheJoint) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(<joint name="abductor" type="revolute">)",
               R"(<joint name="abductor" type="fixed">)"));
  EXPECT_NE(message.find("joint 'abductor' must be revolute"), std::string::npos) << message;
}

TEST(LegDescriptionTest, AnotherMovableJointNamesIt) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(<joint name="foot_joint" type="fixed">)",
               R"(<joint name="foot_joint" type="continuous">)"));
  EXPECT_NE(message.find("joint 'foot_joint'"), std::string::npos) << message;
  EXPECT_NE(message.find("is movable"), std::string::npos) << message;
}

TEST(LegDescriptionTest, LimitsLeavingNoRoomForTheStopsNameTheJoint) {
  // Rotator to +-179 deg: its stops 3 deg beyond would pass +-180.
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(lower="-2.0420352248" upper="2.0420352248")",
               R"(lower="-3.1241393610" upper="3.1241393610")"));
  EXPECT_NE(message.find("joint 'rotator' limit lower and upper"), std::string::npos) << message;
}

TEST(LegDescriptionTest, MissingFootLinkNamesTheLink) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, Edits{{R"(<link name="foot"/>)", R"(<link name="paw"/>)"},
                                 {R"(<child link="foot"/>)", R"(<child link="paw"/>)"}}));
  EXPECT_NE(message.find("link 'foot' not found"), std::string::npos) << message;
}

// The rotator hung from the foot: the leg's links form a cycle beside the root, which urdfdom
// accepts and no walk from the root reaches (found by the URDF fuzz harness under ASan).
TEST(LegDescriptionTest, AJointCycleBesideTheRootIsBadInput) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(<parent link="body"/>)", R"(<parent link="foot"/>)"));
  EXPECT_NE(message.find("link 'foot'"), std::string::npos) << message;
  EXPECT_NE(message.find("does not hang from its root link 'body'"), std::string::npos) << message;
}

TEST(LegDescriptionTest, MovingLinkWithoutInertialNamesTheLinkAndJoint) {
  const std::string message =
      ErrorOf<std::invalid_argument>(TempUrdf(kFrontUrdf, R"(<link name="rotator_housing">
    <inertial>
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <mass value="0.05"/>
      <inertia ixx="7.5e-06" ixy="0" ixz="0" iyy="7.5e-06" iyz="0" izz="7.5e-06"/>
    </inertial>
  </link>)",
                                              R"(<link name="rotator_housing"/>)"));
  EXPECT_NE(message.find("link 'rotator_housing' (moved by joint 'rotator') has no <inertial>"),
            std::string::npos)
      << message;
}

TEST(LegDescriptionTest, BadInertiaNamesTheLink) {
  const std::string message = ErrorOf<std::invalid_argument>(
      TempUrdf(kFrontUrdf, R"(ixx="3.12954e-05")", R"(ixx="-3.12954e-05")"));
  EXPECT_NE(message.find("link 'lower_leg'"), std::string::npos) << message;
  EXPECT_NE(message.find("positive definite"), std::string::npos) << message;
}

TEST(LegDescriptionTest, InertiaBreakingTheTriangleInequalityNamesTheLink) {
  const std::string message = ErrorOf<std::invalid_argument>(TempUrdf(kFrontUrdf,
                                                                      R"(izz="5.256e-06"/>
    </inertial>
  </link>

  <link name="lower_leg">)",
                                                                      R"(izz="1e-03"/>
    </inertial>
  </link>

  <link name="lower_leg">)"));
  EXPECT_NE(message.find("link 'upper_leg'"), std::string::npos) << message;
  EXPECT_NE(message.find("triangle inequality"), std::string::npos) << message;
}

TEST(LegDescriptionTest, UnsupportedDampingNamesTheJoint) {
  const std::string message = ErrorOf<std::invalid_argument>(TempUrdf(
      kFrontUrdf, R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 1 0"/><dynamics damping="0.01"/>)"));
  EXPECT_NE(message.find("joint 'knee'"), std::string::npos) << message;
  EXPECT_NE(message.find("damping"), std::string::npos) << message;
}

// ---- Physical ranges: each bad field of a copy of the front leg is refused in one line ----

struct BadField {
  std::string name;      // the test's name
  Edits edits;           // of robots/ers210a/leg.urdf
  std::string expected;  // the message after "urdf '<path>': "
};

void PrintTo(const BadField& field, std::ostream* out) { *out << field.name; }

class BadFieldTest : public ::testing::TestWithParam<BadField> {};

// The upper leg's inertial block, whose inertia the inertia cases replace.
const std::string kUpperInertia =
    R"(<inertia ixx="2.85435e-05" ixy="0" ixz="0" iyy="2.85435e-05" iyz="0" izz="5.256e-06"/>)";
const std::string kUpperMass = R"(<mass value="0.073"/>)";  // the first one is upper_leg's

TEST_P(BadFieldTest, IsRefusedInOneLineNamingTheFileTheItemAndTheField) {
  const TempUrdf urdf(kFrontUrdf, GetParam().edits);
  const std::string message = ErrorOf<std::invalid_argument>(urdf);
  EXPECT_EQ(message, "urdf '" + urdf.path() + "': " + GetParam().expected);
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

INSTANTIATE_TEST_SUITE_P(
    LegDescriptionTest, BadFieldTest,
    ::testing::Values(
        BadField{"TinyMass",
                 {{kUpperMass, R"(<mass value="1e-30"/>)"}},
                 "link 'upper_leg' mass must be in [0.0001, 100] kg, got 1e-30"},
        BadField{"HugeMass",
                 {{kUpperMass, R"(<mass value="1e30"/>)"}},
                 "link 'upper_leg' mass must be in [0.0001, 100] kg, got 1e+30"},
        // Principal moments -1e-5, 1e-5, 2e-5: not positive definite.
        BadField{"InertiaNotPositiveDefinite",
                 {{kUpperInertia,
                   R"(<inertia ixx="0" ixy="1e-05" ixz="0" iyy="0" iyz="0" izz="2e-05"/>)"}},
                 "link 'upper_leg' inertia must be positive definite, principal moments (-1e-05, "
                 "1e-05, 2e-05) kg m^2"},
        // 1e-5 + 1e-5 < 3e-5: no rigid body has these moments.
        BadField{"InertiaBreakingTheTriangleInequality",
                 {{kUpperInertia,
                   R"(<inertia ixx="1e-05" ixy="0" ixz="0" iyy="1e-05" iyz="0" izz="3e-05"/>)"}},
                 "link 'upper_leg' inertia breaks the triangle inequality, principal moments "
                 "(1e-05, 1e-05, 3e-05) kg m^2"},
        BadField{"TinyInertia",
                 {{kUpperInertia,
                   R"(<inertia ixx="1e-12" ixy="0" ixz="0" iyy="1e-12" iyz="0" izz="1e-12"/>)"}},
                 "link 'upper_leg' inertia's least principal moment must be in [1e-09, 10] kg "
                 "m^2, got 1e-12"},
        BadField{
            "HugeInertia",
            {{kUpperInertia, R"(<inertia ixx="50" ixy="0" ixz="0" iyy="50" iyz="0" izz="50"/>)"}},
            "link 'upper_leg' inertia's least principal moment must be in [1e-09, 10] kg "
            "m^2, got 50"},
        BadField{"FarInertialOrigin",
                 {{R"(<origin xyz="0.007844 0.000306 -0.039222")", R"(<origin xyz="0 0 -2")"}},
                 "link 'upper_leg' inertial origin offset must be in [0, 1] m, got 2"},
        BadField{"FarJointOrigin",
                 {{R"(<origin xyz="0.0128 0.0005 -0.064" rpy="0 0 0"/>)",
                   R"(<origin xyz="0 0 -1.5" rpy="0 0 0"/>)"}},
                 "joint 'knee' origin offset must be in [0, 1] m, got 1.5"},
        BadField{"ZeroAxis",
                 {{R"(<axis xyz="0 1 0"/>)", R"(<axis xyz="0 0 0"/>)"}},
                 "joint 'knee' axis must be finite and non-zero, got (0, 0, 0)"},
        BadField{"LowerLimitNotBelowUpper",
                 {{R"(lower="-0.4712388980" upper="2.5656340004")", R"(lower="1" upper="1")"}},
                 "joint 'knee' limit lower and upper [57.295780, 57.295780] deg must be "
                 "increasing and leave room for the mechanical stops 3 deg beyond them inside "
                 "(-180, 180) deg"}),
    [](const ::testing::TestParamInfo<BadField>& param) { return param.param.name; });

// urdfdom itself refuses a NaN in an origin, naming the joint and the origin (in one line).
TEST(LegDescriptionTest, NanInAJointOriginIsRefusedInOneLine) {
  const std::string message = ErrorOf<std::runtime_error>(
      TempUrdf(kFrontUrdf, R"(<origin xyz="0.0128 0.0005 -0.064" rpy="0 0 0"/>)",
               R"(<origin xyz="nan 0.0005 -0.064" rpy="0 0 0"/>)"));
  EXPECT_NE(message.find("Unable to parse component [nan]"), std::string::npos) << message;
  EXPECT_NE(message.find("origin element for joint [knee]"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// The shipped robots are inside every range.
TEST(LegDescriptionTest, ShippedRobotsLoad) {
  for (const std::string robot : {"ers210a", "ers210a_hind"}) {
    EXPECT_NO_THROW(
        LoadLegDescription(std::string(LEGLAB_SOURCE_DIR) + "/robots/" + robot + "/leg.urdf"))
        << robot;
  }
}

}  // namespace
}  // namespace leglab::sim
