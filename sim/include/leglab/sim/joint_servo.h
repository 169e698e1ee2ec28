#pragma once

#include <cstddef>
#include <vector>

#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// The firmware of one joint's servo: no physics, no ODE. Once per control tick it takes the
/// tick's request into a delay line; once per physics step it turns the delayed target and the
/// joint angle into the speed the velocity motor should hold:
///   commanded = clamp(gain_per_s * (target - angle), -max_speed, +max_speed)
///   speed     = moving average of `commanded` over the last smoothing_ms.
/// The motor cannot change its speed at once, so a new saturated command is reached linearly
/// over smoothing_ms whatever the previous speed was.
class JointServo {
 public:
  /// `config` and `physics_dt_ms` must have passed ValidateSimConfig. Targets are clamped into
  /// [lower_rad, upper_rad] (the joint's software limits, radians, lower <= upper). The servo
  /// starts at rest, holding 0 (clamped).
  JointServo(const ServoConfig& config, double physics_dt_ms, double lower_rad, double upper_rad);

  /// Takes the request for the current tick, radians; it is clamped into the joint limits and
  /// acted on delay_ms later. Call once per tick before that tick's physics steps.
  void PushRequest(double request_rad);

  /// One physics step of firmware: the motor speed, rad/s, given the joint angle, rad.
  double MotorSpeedRadPerS(double angle_rad);

  /// Forgets every queued request and the smoothing history: holds `angle_rad` (clamped) at
  /// rest, as after a long wait.
  void Hold(double angle_rad);

  /// The target the firmware currently acts on (the request of delay_ticks() ticks ago,
  /// clamped), rad.
  double target_rad() const { return delay_line_[oldest_]; }

  /// The latest request taken by PushRequest (or Hold), clamped, rad.
  double latest_request_rad() const;

  /// Ticks between a request and the first physics step that acts on it.
  int delay_ticks() const { return static_cast<int>(delay_line_.size()) - 1; }

  /// Joint limits the targets are clamped into, rad.
  double lower_rad() const { return lower_rad_; }
  double upper_rad() const { return upper_rad_; }

 private:
  double Clamp(double angle_rad) const;

  double gain_per_s_;
  double max_speed_rad_per_s_;
  double lower_rad_;
  double upper_rad_;
  // Requests of the last delay_ticks + 1 ticks; oldest_ indexes the one acted on.
  std::vector<double> delay_line_;
  std::size_t oldest_ = 0;
  // Commanded speeds of the last smoothing window, rad/s, and their running sum.
  std::vector<double> window_;
  std::size_t next_ = 0;
  double window_sum_ = 0.0;
};

}  // namespace leglab::sim
