#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/core/leg.h"

namespace leglab::sim {

/// The servo firmware of every joint (robot.yaml `servo.*`). Defaults emulate the paper's Aibo
/// (Stronger & Stone, Table 1); see robots/ers210a/robot.yaml for the reasoning.
struct ServoConfig {
  /// How long a request is held back before the firmware acts on it, ms; a non-negative
  /// multiple of kTickMs. A request set before tick t first moves the joint during tick
  /// t + delay_ms / 8.
  double delay_ms = 40.0;
  /// Top joint speed, deg/s (> 0): the commanded speed is capped at it.
  double max_speed_deg_s = 312.5;
  /// Proportional speed law, 1/s (> 0): commanded speed = gain_per_s * (target - angle)
  /// - damping * rate.
  double gain_per_s = 72.0;
  /// Velocity feedback of the speed law, dimensionless (>= 0): the commanded speed is reduced
  /// by damping times the joint's angular rate (the D of the servo's PD loop), so the joint
  /// starts braking before it reaches the target instead of overshooting it.
  double damping = 1.3;
  /// Window of the moving average that smooths the commanded speed, ms; a non-negative
  /// multiple of the 8 ms frame (0 or 8: no smoothing).
  double smoothing_ms = 48.0;
  /// Most torque the motor may use, N m (> 0); capped per joint by the URDF effort limit.
  double max_torque_nm = 5.45;
};

/// The joint angle sensor (robot.yaml `sensor.*`).
struct SensorConfig {
  /// Standard deviation of the Gaussian noise added to each measured angle, deg (>= 0).
  double noise_deg = 0.1;
};

/// The lightest carriage load a stand accepts, kg: a lighter one is refused as bad input.
inline constexpr double kMinStandLoadKg = 0.01;

/// The single-leg test stand (robot.yaml `stand.*`): the leg's root link mounted on
/// a carriage that slides on a vertical rail (an ODE slider joint), carrying its share of the
/// body, with a lower stop on the rail and a floor under the foot. Off (`enabled` false, no
/// `stand:` section) the leg hangs in the air, fixed to the world, exactly as without it.
///
/// Heights: the carriage height is the shoulder's height above its *walking height*, the
/// height at which the centre of the ball of the foot, `ground_below_shoulder_mm` below the
/// shoulder, has the foot sphere just touching the floor. So the floor plane lies
/// ground_below_shoulder_mm + foot_radius_mm below the shoulder at carriage height 0, and the
/// stop holds the carriage at -stop_below_shoulder_mm.
///
/// Contact softness is given in physical units and turned into ODE's ERP and CFM for the
/// physics step h (ODE manual, "How to use ERP and CFM"): ERP = h k / (h k + c),
/// CFM = 1 / (h k + c), with k the stiffness (N/m) and c the damping (N s/m): the contact then
/// acts as a spring-damper k, c integrated implicitly.
struct StandConfig {
  /// The stand is built (a `stand:` section was given).
  bool enabled = false;
  /// Mass the carriage carries besides the leg, kg (>= kMinStandLoadKg): default a quarter of an
  /// ERS-210A, which weighs about 1.5 kg with battery and memory stick (Sony's ERS-210A
  /// specifications).
  double load_kg = 0.375;
  /// How far below its walking height the rail's lower stop holds the shoulder, mm (>= 0; a
  /// negative value would put the stop above the shoulder's walking height, so that the foot
  /// could never carry the load on the walk's ground).
  double stop_below_shoulder_mm = 5.0;
  /// Coulomb friction coefficient of foot on floor (>= 0; ODE's friction pyramid).
  double friction = 1.0;
  /// Contact stiffness of foot on floor, N/m (> 0).
  double contact_stiffness_n_per_m = 20000.0;
  /// Contact damping of foot on floor, N s/m (>= 0).
  double contact_damping_n_s_per_m = 100.0;
  /// Speed of the floor's surface backward (along -x), mm/s: the floor is a treadmill belt, as
  /// on the single-leg rigs of legged-robot labs, since the rail lets the body move only
  /// vertically; a walk's stance sweeps the foot backward, and a still floor would make it
  /// slide its whole stroke. 0 is a still floor. The experiments default it to the walk's
  /// stance speed (desired.locus: length / (ground_fraction x t_step)).
  double belt_speed_mm_per_s = 0.0;
  /// Radius of the contact sphere at the foot (the ball of the foot), mm (> 0).
  double foot_radius_mm = 13.96;
  /// The horizontal sled under the rail, N/m (>= 0): with a stiffness k > 0 the vertical rail
  /// rides on a sled, a cross slide that moves along x and y (as the sleds and booms of
  /// legged-robot labs' single-leg rigs; the slides' own mass neglected), tied to the frame's
  /// origin by a spring k and a damper sled_damping_n_s_per_m along each axis, integrated
  /// implicitly (LegWorld): the horizontal compliance of the rest of the body and its other
  /// legs, so that the stance's speed errors can move the body instead of sliding the foot.
  /// 0 (the default): no sled, the rail is fixed to the frame (bit for bit as without it).
  double sled_stiffness_n_per_m = 0.0;
  /// The sled's damper, N s/m (>= 0); used only with a sled (sled_stiffness_n_per_m > 0).
  double sled_damping_n_s_per_m = 0.0;
  /// Where the walk's ground is: the foot centre's depth below the shoulder on the ground, mm
  /// (the experiments set it from the walk's locus).
  double ground_below_shoulder_mm = 100.0;
  /// The config gives no belt speed: the experiments set belt_speed_mm_per_s to the walk's
  /// stance speed.
  bool belt_follows_walk = true;
};

/// The coarsest physics step, ms: beyond it the leg on the stand breaks down even at the
/// default servo speed (docs/design/sim-breakdown.md).
inline constexpr double kMaxPhysicsDtMs = 2.0;

/// The most a joint may turn in one physics step at the servo's top speed, deg:
/// servo.max_speed_deg_s x sim.physics_dt_ms / 1000 must not exceed it. ODE's step moves a link
/// along the tangent of the circle its hinge holds it on, which opens the hinge by about
/// r theta^2 / 2 for a turn theta at reach r, and its error correction closes only a fraction
/// of that each step: a joint comes apart once the turn per step is too large for the leg's
/// reach. Set for the ERS-210A's leg; the derivation and the grid: docs/design/sim-breakdown.md.
inline constexpr double kMaxTurnPerPhysicsStepDeg = 2.0;

/// The rigid-body engine a LegWorld runs on (`sim.engine`).
enum class PhysicsEngine {
  kOde,   ///< ODE: maximal coordinates, hinge constraints; the stand; the default
  kDart,  ///< DART: reduced coordinates (joints cannot open); the leg in the air only
};
inline constexpr std::array<std::string_view, 2> kPhysicsEngineNames{"ode", "dart"};

/// Whether this build has DART (the CMake option LEGLAB_WITH_DART, on when DART is found):
/// without it PhysicsEngine::kDart is refused (ValidateSimConfig, LegWorld) as bad input.
bool BuiltWithDart();

/// Everything the simulated plant needs (robot.yaml, with `urdf` resolved to a path).
struct SimConfig {
  /// URDF of the leg, absolute or relative to the working directory.
  std::string urdf_path;
  /// The physics engine.
  PhysicsEngine engine = PhysicsEngine::kOde;
  /// Physics step, ms (> 0); must divide kTickMs into a whole number of steps. The config's
  /// range: at most kMaxPhysicsDtMs, with CheckTurnPerPhysicsStep.
  double physics_dt_ms = 1.0;
  /// Servo firmware parameters, shared by the three joints.
  ServoConfig servo{};
  /// Angle sensor parameters.
  SensorConfig sensor{};
  /// Seed of the sensor noise generator; the same seed gives bit-identical runs.
  std::uint64_t seed = 1;
  /// The test stand; off by default (the leg in the air).
  StandConfig stand{};
};

/// The robot.yaml keys of the plant, declared once (see KeyVisitor): `urdf` (as written, not
/// yet resolved to a path), `sim.*`, `servo.*`, `sensor.*`, `stand.*` (a `stand` section given
/// builds the stand) and `seed`.
void VisitKeys(KeyVisitor& visitor, SimConfig& config);

/// Checks every value of `config` against its documented range, and that this build has its
/// engine (BuiltWithDart). Throws std::invalid_argument naming the offending key as in
/// robot.yaml (e.g. "servo.delay_ms must be a non-negative multiple of 8 ms, got 30").
void ValidateSimConfig(const SimConfig& config);

/// Checks the servo's top speed against the physics step on ODE: throws std::invalid_argument
/// naming both keys ("servo.max_speed_deg_s 3600 with sim.physics_dt_ms 1 turns a joint 3.6 deg
/// in one physics step; ... sim.engine: dart takes it") when servo.max_speed_deg_s x
/// physics_dt_ms / 1000 exceeds kMaxTurnPerPhysicsStepDeg and the engine is ODE (DART's joints
/// cannot open). The config loader applies it, as it applies the keys' ranges;
/// ValidateSimConfig does not, so that a LegSim built directly may still be driven apart.
void CheckTurnPerPhysicsStep(const SimConfig& config);

/// The settings a running LegSim can change (LegSim::ChangeSettings): the `servo.*` and
/// `sensor.*` keys, named as in robot.yaml, in their declaration's order.
std::vector<std::string> ChangeableSimSettings();

/// Sets the value of `key` (one of ChangeableSimSettings()) in `config`, unvalidated.
/// Throws std::invalid_argument "<key> cannot change during a run (can: ...)" for any other
/// key.
void SetSimSetting(SimConfig& config, std::string_view key, double value);

/// Number of physics steps in one control tick for a validated `physics_dt_ms`.
int PhysicsStepsPerTick(double physics_dt_ms);

}  // namespace leglab::sim
