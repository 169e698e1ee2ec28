#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <string_view>

#include "leglab/core/plant.h"
#include "leglab/sim/angle_sensor.h"
#include "leglab/sim/joint_servo.h"
#include "leglab/sim/leg_world.h"
#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// The simulation broke down (a non-finite or exploding state). The message names the tick.
class SimError : public std::runtime_error {
 public:
  /// The breakdown found by the state check after control tick `tick` (counted from 0):
  /// `problem` says what broke (e.g. "joint 'knee' came apart: ..."). what() is
  /// "leglab::sim: the simulation broke down during control tick <tick> (t = <ms> ms): <problem>".
  SimError(long tick, std::string problem);

  /// The control tick during which the state check found the breakdown.
  long tick() const { return tick_; }
  /// What broke, without the tick.
  const std::string& problem() const { return problem_; }

 private:
  long tick_;
  std::string problem_;
};

/// The simulated plant: one ERS-210A leg held in the air (LegWorld physics), driven by servo
/// firmware (JointServo, one per joint) and read by noisy angle sensors (AngleSensor). It is
/// hardware to the controller: write requests, tick, read measured angles. As a leglab::Plant,
/// Reset() is SetJointAnglesDeg(), Tick(request) is SetRequestsDeg(request) then Tick(), and
/// the reading is {MeasuredDeg(), TrueDeg(), CommandedDeg(), Telemetry()}.
///
/// With config.stand.enabled the leg is on the single-leg test stand (StandConfig: a carriage
/// on a vertical rail carrying a load, a floor under the foot); the stand's instruments are
/// the reading's telemetry, which the controller never sees.
///
/// Timing: at control tick t the caller calls SetRequestsDeg(R(t)) and then Tick(); after
/// Tick() returns, MeasuredDeg() is the angle recorded immediately after request t, sampled at
/// the end of that tick. A request is acted on servo.delay_ms later: with 32 ms a step
/// requested at tick t first moves the joint during tick t + 4 and first shows in the
/// measurement returned after tick t + 4.
///
/// Deterministic: the same config (including seed) and calls give bit-identical results, also
/// when separate LegSims run on parallel threads (one LegSim per thread at a time).
class LegSim final : public leglab::Plant {
 public:
  /// Validates `config` (std::invalid_argument naming the key), then builds the leg from
  /// config.urdf_path (std::runtime_error naming the file if it is missing or malformed,
  /// std::invalid_argument naming the joint or link if one is missing or invalid; see
  /// LegWorld). The leg starts at rest at q = 0 with every request 0, tick() == 0, and
  /// MeasuredDeg() and Read() hold one reading of that pose.
  explicit LegSim(const SimConfig& config);
  ~LegSim() override;
  LegSim(LegSim&&) noexcept;             ///< A moved-from LegSim may only be destroyed.
  LegSim& operator=(LegSim&&) noexcept;  ///< A moved-from LegSim may only be destroyed.
  LegSim(const LegSim&) = delete;
  LegSim& operator=(const LegSim&) = delete;

  /// Sets the request for the coming tick, deg (LegAngles order). Each value is clamped to
  /// its joint's URDF limits, as the real servo does. Until the next call, later ticks repeat
  /// it. Throws std::invalid_argument naming the joint for a non-finite value.
  void SetRequestsDeg(const LegAngles& request_deg);

  /// Advances one 8 ms control tick: kTickMs / physics_dt_ms physics steps, each running the
  /// servo firmware and one dWorldStep, then samples the sensors. Throws SimError naming the
  /// tick when the state turns non-finite or explodes (the sim is then unusable).
  void Tick();

  /// Plant: SetRequestsDeg(request_deg), then Tick(); returns the reading at the end of the
  /// tick ({MeasuredDeg(), TrueDeg(), CommandedDeg()}), valid until the next Tick or Reset.
  /// Throws std::invalid_argument naming the joint for a non-finite request, SimError when
  /// the simulation breaks down.
  const PlantReading& Tick(const LegAngles& request_deg) override;

  /// Plant: SetJointAnglesDeg(pose_deg) (throws as it does).
  void Reset(const LegAngles& pose_deg) override { SetJointAnglesDeg(pose_deg); }

  /// Plant: the reading at the end of the latest Tick(), or of the pose after construction or
  /// the latest SetJointAnglesDeg()/Reset(); deg.
  const PlantReading& Read() const override { return reading_; }

  /// Plant: "sim".
  std::string_view name() const override { return "sim"; }

  /// Plant: changes any of ChangeableSimSettings() (robot.yaml's servo.* and sensor.* values)
  /// from the next tick on, without restarting the physics: the links keep moving, the
  /// servos keep their queued requests (JointServo::Reconfigure) and the sensor its stream of
  /// draws. Throws std::invalid_argument naming the key for another key or a value
  /// ValidateSimConfig rejects; nothing changes then.
  void ChangeSettings(std::span<const PlantSetting> settings) override;

  /// The latest sensor reading, deg: true angle + Gaussian noise (sensor.noise_deg, seeded),
  /// quantised to 1 microradian; sampled once at the end of each Tick().
  LegAngles MeasuredDeg() const { return reading_.measured_deg; }

  /// The stand's instruments at the end of the latest tick (zeros without a stand): the
  /// floor's mean force on the foot over the tick, the carriage height, the slip since reset.
  const PlantTelemetry& Telemetry() const { return reading_.telemetry; }

  /// The exact hinge angles now, deg.
  LegAngles TrueDeg() const { return reading_.true_deg; }

  /// The latest request as the servo took it (clamped to the joint limits), deg.
  LegAngles CommandedDeg() const { return reading_.applied_deg; }

  /// Centre of the ball of the foot (the `foot` link origin) in the body frame (on the stand
  /// the carriage's), mm, from the ODE body poses.
  std::array<double, 3> FootPositionMm() const { return world_.LinkOriginMm(kFootLinkName); }

  /// Teleports the leg to `q_deg` at rest, and resets the servos (requests, delay line,
  /// smoothing) to hold there. Draws a fresh sensor reading. Does not advance tick().
  /// Throws std::invalid_argument naming the joint when an angle is non-finite or outside its
  /// URDF limits.
  void SetJointAnglesDeg(const LegAngles& q_deg);

  /// Powers the motors (default on). Off sets their maximum torque to 0, leaving a passive
  /// pendulum under gravity; the firmware keeps running and takes over when powered again.
  void SetMotorsEnabled(bool on) { motors_enabled_ = on; }

  /// Kinetic plus gravitational potential energy of the moving links, J.
  double MechanicalEnergyJ() const { return world_.MechanicalEnergyJ(); }

  /// Number of completed control ticks.
  long tick() const { return tick_; }

  /// The configuration this plant was built from.
  const SimConfig& config() const { return config_; }

  /// The physics underneath (URDF joint data, link poses); read-only.
  const LegWorld& world() const { return world_; }

 private:
  static LegAngles ToDeg(const LegAngles& rad);
  // Takes the reading, in degrees: one sensor sample of the hinge angles, the hinge angles
  // themselves and the servos' latest requests. The state changes only in Tick() and
  // SetJointAnglesDeg(), which call it last; the getters return parts of it.
  void SampleReading();

  SimConfig config_;
  LegWorld world_;
  std::array<JointServo, kLegJoints> servos_;
  std::array<double, kLegJoints> max_torque_nm_{};
  AngleSensor sensor_;
  int steps_per_tick_;
  double physics_dt_s_;
  LegAngles request_rad_{};
  PlantReading reading_{};
  std::array<double, 3> tick_force_n_{};  // on the stand: the floor's mean force this tick
  double slip_at_reset_mm_ = 0.0;         // the world's slip count at the latest reset
  bool motors_enabled_ = true;
  long tick_ = 0;
};

}  // namespace leglab::sim
