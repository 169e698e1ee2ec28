#pragma once

#include <cstddef>
#include <vector>

#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// The firmware of one joint's servo: no physics, no ODE. It runs once per 8 ms frame, as the
/// Aibo's joint commands do: it takes the frame's request into a delay line, and turns the
/// delayed target, the joint angle and the joint's rate at the start of the frame into the
/// speed the velocity motor holds through the frame:
///   commanded = clamp(gain_per_s * (target - angle) - damping * rate, -max_speed, +max_speed)
///   speed     = mean of `commanded` over the last smoothing_ms / 8 frames.
/// The motor cannot change its speed at once: a new saturated command is reached in equal
/// steps over smoothing_ms whatever the previous speed was. The damping (the D of a PD loop)
/// makes it brake before the target instead of overshooting it.
class JointServo {
 public:
  /// `config` must have passed ValidateSimConfig. Targets are clamped into [lower_rad,
  /// upper_rad] (the joint's software limits, radians, lower <= upper). The servo starts at
  /// rest, holding 0 (clamped).
  JointServo(const ServoConfig& config, double lower_rad, double upper_rad);

  /// Takes the request for the current tick, radians; it is clamped into the joint limits and
  /// acted on delay_ms later. Call once per tick before that tick's physics steps.
  void PushRequest(double request_rad);

  /// One frame of firmware, after PushRequest: the motor speed to hold through this frame,
  /// rad/s, given the joint angle, rad, and its angular rate, rad/s, at the frame's start.
  double FrameSpeedRadPerS(double angle_rad, double rate_rad_per_s);

  /// Takes new firmware settings (`config` validated) without forgetting its state, as if the
  /// firmware were swapped between two frames: requests already queued are still acted on in
  /// order (a longer delay repeats the oldest queued request for the extra ticks, a shorter
  /// one drops the oldest), and the smoothing keeps its newest commands (a longer window is
  /// padded with the current mean, so the motor speed does not jump).
  void Reconfigure(const ServoConfig& config);

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
  double damping_;
  double max_speed_rad_per_s_;
  double lower_rad_;
  double upper_rad_;
  // Requests of the last delay_ticks + 1 ticks; oldest_ indexes the one acted on.
  std::vector<double> delay_line_;
  std::size_t oldest_ = 0;
  // Commanded speeds of the last smoothing_ms / 8 frames, rad/s; next_ is the oldest.
  std::vector<double> window_;
  std::size_t next_ = 0;
};

}  // namespace leglab::sim
