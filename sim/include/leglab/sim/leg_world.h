#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>

#include "leglab/core/leg.h"
#include "leglab/core/plant.h"
#include "leglab/core/units.h"
#include "leglab/sim/leg_description.h"
#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// One simulated joint as described by the URDF (the older name of JointDescription).
using JointInfo = JointDescription;

/// The rigid-body physics of the leg: a LegDescription (the URDF, checked) turned into a world of
/// one physics engine (PhysicsEngine), nothing else (no servo firmware, no sensor; LegSim adds
/// those). The root link is fixed to the world at the world origin, so world coordinates are
/// body-frame coordinates. Each link moved by a revolute joint becomes a rigid body with its
/// frame's mass; links hung on fixed joints are lumped into their parent (a link without
/// <inertial>, such as `foot`, is just a frame). Each revolute joint has a velocity motor with a
/// torque limit and mechanical stops kStopMarginRad beyond its URDF limits. Gravity is
/// -kGravityMPerS2 along z.
///
/// ODE (the default) moves each body in maximal coordinates and holds it to its parent by a
/// hinge constraint, which fast motion can open (kMaxTurnPerPhysicsStepDeg); DART moves one
/// skeleton in joint coordinates, where a joint cannot open, and has no stand
/// (docs/design/dart.md). The engine is initialised once per process on first use. Separate
/// LegWorlds may be stepped on parallel threads; one LegWorld must be used by one thread at a
/// time.
class LegWorld {
 public:
  /// Gravitational acceleration, m/s^2, acting along -z.
  static constexpr double kGravityMPerS2 = 9.81;
  /// How far beyond the URDF (software) limits the mechanical stops are, rad (3 deg, as on
  /// the ERS-210A).
  static constexpr double kStopMarginRad = kMechanicalStopMarginRad;
  /// A hinge turning faster than this, rad/s, means the integration has blown up.
  static constexpr double kExplodedRateRadPerS = 1000.0;

  /// A contact carrying more than this normal force, N, counts as loaded (PlantTelemetry::slip_mm).
  static constexpr double kLoadedContactN = 0.1;

  /// Builds `engine`'s world of `leg` (bodies placed at q = 0, at rest; hinges with their motors
  /// off). With `stand.enabled` (ODE only) the root link rides on a carriage of mass stand.load_kg
  /// on a vertical ODE slider (lower stop at -stand.stop_below_shoulder_mm) instead of being fixed
  /// to the world, and a floor plane and a sphere at the foot (stand.foot_radius_mm) collide
  /// through an ODE space; with stand.sled_stiffness_n_per_m > 0 the rail rides on a sled: the
  /// carriage also moves along x and y (never turning), held at 0 by the sled's spring-damper
  /// (the slides' own mass neglected: the body's horizontal mass is the load and the leg);
  /// `stand` is expected valid (ValidateSimConfig). `leg` is normally
  /// LoadLegDescription's result; throws std::invalid_argument when its indices do not form a tree
  /// with each LegJoint moving one link and each body carried by its link, naming the link when
  /// ODE rejects a body's mass, or when `stand.enabled` with PhysicsEngine::kDart.
  explicit LegWorld(const LegDescription& leg, const StandConfig& stand = {},
                    PhysicsEngine engine = PhysicsEngine::kOde);

  /// LegWorld(LoadLegDescription(urdf_path)): parses the URDF at `urdf_path` (absolute or
  /// relative to the working directory) and builds its world. Throws what LoadLegDescription
  /// throws (std::runtime_error naming a missing or malformed file, std::invalid_argument
  /// naming an invalid joint or link).
  explicit LegWorld(const std::string& urdf_path, const StandConfig& stand = {},
                    PhysicsEngine engine = PhysicsEngine::kOde);
  ~LegWorld();
  LegWorld(LegWorld&&) noexcept;             ///< A moved-from LegWorld may only be destroyed.
  LegWorld& operator=(LegWorld&&) noexcept;  ///< A moved-from LegWorld may only be destroyed.
  LegWorld(const LegWorld&) = delete;
  LegWorld& operator=(const LegWorld&) = delete;

  /// The URDF description of joint `joint` (0 <= joint < kLegJoints, LegAngles order).
  const JointDescription& joint(int joint) const;

  /// The leg this world was built from.
  const LegDescription& description() const;

  /// Hinge angles as the engine reports them, rad (zero at the URDF's q = 0, sign of the URDF
  /// axis).
  LegAngles AnglesRad() const;

  /// Hinge angular rates, rad/s.
  LegAngles RatesRadPerS() const;

  /// Sets joint `joint`'s velocity motor: it holds `speed_rad_per_s` using at most
  /// `max_torque_nm` (>= 0; 0 switches the motor off).
  void SetMotor(int joint, double speed_rad_per_s, double max_torque_nm);

  /// One physics step of `dt_s` seconds (ODE's dWorldStep, DART's World::step). On the stand,
  /// the foot's contacts with the floor are found first (dSpaceCollide, dCollide) and joined
  /// for this step only (a contact joint group, emptied after it), with the stand's stiffness
  /// and damping as ERP and CFM for `dt_s` (StandConfig). Throws std::runtime_error with ODE's
  /// message ("ODE internal error 1: assertion ...") when ODE reports an error instead of
  /// letting it abort the process; the world must then be destroyed, not stepped again.
  void Step(double dt_s);

  /// Teleports the leg to the joint angles `q_rad` (rad), every body at rest. Does not check
  /// limits. On the stand the carriage is put at rest on its stop, or, when the foot would
  /// then be in the floor, as high as makes the foot just touch it.
  void SetConfigurationRad(const LegAngles& q_rad);

  /// The stand's measurements after the latest Step (zeros without a stand).
  const PlantTelemetry& stand_state() const;

  /// Whether the world has a stand.
  bool has_stand() const;

  /// Origin of link `link`'s frame in the body frame (= the world frame in the air, the
  /// world frame lowered by the carriage height on the stand), mm, from the engine's body poses.
  /// Throws std::invalid_argument when the URDF has no such link.
  std::array<double, 3> LinkOriginMm(std::string_view link) const;

  /// Kinetic plus gravitational potential energy of the moving bodies (and the carriage on the
  /// stand, and the sled with its spring's energy when there is one), J (zero potential at
  /// world z = 0).
  double MechanicalEnergyJ() const;

  /// Kinetic energy (translation and rotation) of the moving bodies, J.
  double KineticEnergyJ() const;

  /// Empty when the state is sound; otherwise what is wrong with it (a non-finite value, a
  /// hinge faster than kExplodedRateRadPerS, or, on ODE, a hinge whose two anchors drifted
  /// apart).
  std::string StateProblem() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace leglab::sim
