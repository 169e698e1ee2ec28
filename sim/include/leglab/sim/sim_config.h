#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

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

/// Everything the simulated plant needs (robot.yaml, with `urdf` resolved to a path).
struct SimConfig {
  /// URDF of the leg, absolute or relative to the working directory.
  std::string urdf_path;
  /// ODE physics step, ms (> 0); must divide kTickMs into a whole number of steps.
  double physics_dt_ms = 1.0;
  /// Servo firmware parameters, shared by the three joints.
  ServoConfig servo{};
  /// Angle sensor parameters.
  SensorConfig sensor{};
  /// Seed of the sensor noise generator; the same seed gives bit-identical runs.
  std::uint64_t seed = 1;
};

/// Checks every value of `config` against its documented range.
/// Throws std::invalid_argument naming the offending key as in robot.yaml (e.g.
/// "servo.delay_ms must be a non-negative multiple of 8 ms, got 30").
void ValidateSimConfig(const SimConfig& config);

/// The settings a running LegSim can change (LegSim::ChangeSettings), named as in robot.yaml.
inline constexpr std::array<std::string_view, 7> kChangeableSimSettings = {
    "servo.delay_ms",     "servo.max_speed_deg_s", "servo.gain_per_s", "servo.damping",
    "servo.smoothing_ms", "servo.max_torque_nm",   "sensor.noise_deg"};

/// Sets the value of `key` (one of kChangeableSimSettings) in `config`, unvalidated.
/// Throws std::invalid_argument "<key> cannot change during a run (can: ...)" for any other
/// key.
void SetSimSetting(SimConfig& config, std::string_view key, double value);

/// Number of physics steps in one control tick for a validated `physics_dt_ms`.
int PhysicsStepsPerTick(double physics_dt_ms);

}  // namespace leglab::sim
