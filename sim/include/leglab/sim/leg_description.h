#pragma once

#include <array>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/core/leg.h"
#include "leglab/core/units.h"

namespace leglab::sim {

/// URDF name of the link whose origin is the centre of the ball of the foot.
inline constexpr std::string_view kFootLinkName = "foot";

/// How far beyond the URDF (software) limits the mechanical stops are, rad (3 deg, as on the
/// ERS-210A). A URDF's limits must leave room for them inside (-pi, pi).
inline constexpr double kMechanicalStopMarginRad = DegToRad(3.0);

// Physical ranges of a leg of this kind (Aibo-sized: links of tens of grams and centimetres),
// checked by LoadLegDescription before any physics engine sees the URDF: each spans orders of
// magnitude around the shipped leg, and outside it ODE's step fails (a 1e-30 kg link aborts it,
// a 1e30 kg one tears the joints apart). Listed in docs/extending.md ("A robot").

/// Least mass of a link with <inertial>, kg: 0.1 g, a screw; lighter links make ODE's mass
/// matrix singular next to the 0.073 kg segments.
inline constexpr double kMinLinkMassKg = 1e-4;
/// Greatest mass of a link, kg: a leg segment of a large quadruped; heavier ones outweigh the
/// 5 N m servos by orders of magnitude and make the joint constraints drift apart.
inline constexpr double kMaxLinkMassKg = 100.0;
/// Least principal moment of inertia about a link's centre of mass, kg m^2: a 0.1 g bead of
/// 5 mm radius (the shipped thinnest is 5e-6, a 12 mm rod).
inline constexpr double kMinPrincipalInertiaKgM2 = 1e-9;
/// Greatest principal moment of inertia, kg m^2: 100 kg spread 0.3 m from its axis.
inline constexpr double kMaxPrincipalInertiaKgM2 = 10.0;
/// Relative slack of the triangle inequality of principal moments (each at most the sum of the
/// other two): a thin rod or plate written with rounded moments sits on its edge.
inline constexpr double kInertiaTriangleTolerance = 1e-9;
/// Greatest length of a joint origin's or an inertial origin's offset from its frame, m: no
/// part of a leg is a metre from the joint it hangs on (the shipped greatest is 0.084 m).
inline constexpr double kMaxOriginOffsetM = 1.0;

/// The ranges above as declarations, which LoadLegDescription checks through.
inline constexpr KeyDoc kLinkMassDoc{.min = kMinLinkMassKg, .max = kMaxLinkMassKg, .unit = "kg"};
inline constexpr KeyDoc kPrincipalInertiaDoc{
    .min = kMinPrincipalInertiaKgM2, .max = kMaxPrincipalInertiaKgM2, .unit = "kg m^2"};
inline constexpr KeyDoc kOriginOffsetDoc{.min = 0, .max = kMaxOriginOffsetM, .unit = "m"};
/// A joint's <limit effort>, N m: positive and finite.
inline constexpr KeyDoc kLimitEffortDoc{.min = 0,
                                        .max = std::numeric_limits<double>::infinity(),
                                        .min_open = true,
                                        .max_open = true,
                                        .unit = "N m"};

/// A rigid transform: a point p given in the child frame is rotation * p + translation_m in
/// the parent frame.
struct RigidTransform {
  /// Rotation matrix, row-major (rotation[row][column]); its columns are the child's axes in
  /// the parent frame.
  std::array<std::array<double, 3>, 3> rotation{
      {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
  /// The child frame's origin in the parent frame, m.
  std::array<double, 3> translation_m{};
};

/// One revolute joint of the leg as the URDF describes it.
struct JointDescription {
  std::string name;                    ///< URDF joint name, one of kLegJointNames
  double lower_rad = 0.0;              ///< software lower limit, rad
  double upper_rad = 0.0;              ///< software upper limit, rad
  double effort_nm = 0.0;              ///< torque rating, N m (> 0)
  double velocity_rad_per_s = 0.0;     ///< speed rating, rad/s
  std::array<double, 3> position_m{};  ///< the joint's origin in the root (body) frame at q = 0, m
  std::array<double, 3> axis{};        ///< its unit axis in the root (body) frame at q = 0
};

/// One URDF link. LegDescription::links lists them depth-first from the root, so a parent
/// always precedes its children.
struct LinkDescription {
  std::string name;  ///< URDF link name
  /// Index of the parent link in LegDescription::links; -1 for the root.
  int parent = -1;
  /// LegJoint of the revolute joint that moves this link relative to its parent; -1 when it
  /// hangs on a fixed joint (or is the root).
  int joint = -1;
  /// This link's frame at q = 0 in its parent's frame (the URDF joint origin); identity for
  /// the root.
  RigidTransform origin{};
  /// Unit axis of `joint` in this link's frame (the URDF <axis>, normalised); (0, 0, 1) when
  /// `joint` is -1.
  std::array<double, 3> axis{0.0, 0.0, 1.0};
  /// Index in LegDescription::bodies of the rigid body this link rides on; -1 for the root and
  /// links fixed to it (they stay put).
  int body = -1;
  /// This link's frame in the frame of the link that carries its body (LinkDescription at
  /// bodies[body].link), or in the root frame when `body` is -1. Identity for a moving link.
  RigidTransform in_body{};
};

/// One rigid body: a link moved by a revolute joint, with the links hung on it by fixed joints
/// lumped in (their masses combined about the joint centre of mass, parallel-axis theorem).
struct BodyDescription {
  /// Index in LegDescription::links of the moving link whose frame the body carries.
  int link = -1;
  /// Total mass, kg (> 0).
  double mass_kg = 0.0;
  /// Centre of mass in the carrying link's frame, m.
  std::array<double, 3> com_m{};
  /// Inertia about the centre of mass in the carrying link's axes, kg m^2, row-major
  /// (symmetric, positive definite).
  std::array<std::array<double, 3>, 3> inertia_kg_m2{};
};

/// A leg's URDF as plain data, checked: what the simulator builds its physics from.
struct LegDescription {
  /// The URDF file it was read from, as given to LoadLegDescription.
  std::string urdf_path;
  /// The URDF's <robot name="...">.
  std::string robot_name;
  /// The three revolute joints, in LegJoint order.
  std::array<JointDescription, kLegJoints> joints;
  /// Origin of link kFootLinkName in the root frame at q = 0, m.
  std::array<double, 3> foot_position_m{};
  /// Every link, depth-first from the root (links[0]).
  std::vector<LinkDescription> links;
  /// Every moving rigid body, in the depth-first order of the links that carry them.
  std::vector<BodyDescription> bodies;

  /// Index in `links` of the link called `name`; -1 when there is none.
  int FindLink(std::string_view name) const;
};

/// Parses and checks the URDF at `urdf_path` (absolute or relative to the working directory):
/// reads its tree depth-first, its three joints and lumps fixed children into their moving
/// parent. Touches no physics engine.
/// Throws std::runtime_error naming the file when it is missing or urdfdom rejects it (with
/// urdfdom's reason), and std::invalid_argument naming the item when a joint of kLegJointNames
/// or the `foot` link is missing, a joint is not revolute or has limits the stops
/// (kMechanicalStopMarginRad beyond them) cannot wrap within (-pi, pi), damping/friction/mimic
/// is given (not modelled), another movable joint exists, a joint's axis is zero or not finite, an
/// origin is not finite or farther than kMaxOriginOffsetM, or a moving link has no or an invalid
/// mass/inertia (mass outside [kMinLinkMassKg, kMaxLinkMassKg], an inertia that is not positive
/// definite, has a principal moment outside [kMinPrincipalInertiaKgM2, kMaxPrincipalInertiaKgM2]
/// or breaks the triangle inequality). Those range messages are one line, "urdf '<path>': link
/// 'upper_leg' mass must be in [0.0001, 100] kg, got 1e-30".
LegDescription LoadLegDescription(const std::string& urdf_path);

}  // namespace leglab::sim
