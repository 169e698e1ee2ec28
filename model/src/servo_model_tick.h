#pragma once

// The extended model's tick (ServoModelParams), inline for the loops that run it many times
// (the fit's rollouts) and for the model's own functions: one definition of the arithmetic, so
// that the fit scores exactly what the model predicts, bit for bit. Internal to leglab_model.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "leglab/model/servo_model.h"

namespace leglab::servo_tick {

/// Throws std::invalid_argument on a recording whose sizes differ, whose drive is out of range
/// or which holds a sample that is not finite.
void CheckRecording(const ServoRecording& recording);

/// The load's duty g at `angle_deg` (ServoLoadDuty).
inline double LoadDuty(const ServoModelParams& p, const ServoDrive& drive, double angle_deg) {
  return drive.mass_kg * kGravityMS2 * drive.length_m *
         std::sin(angle_deg * std::numbers::pi / 180.0) / p.stall_torque_nm;
}

/// The speed w* the net duty settles to (ServoTargetSpeed).
inline double TargetSpeed(const ServoModelParams& p, const ServoDrive& drive, double angle_deg,
                          double error_deg) {
  const double duty = std::clamp(p.gain_per_deg_kp * drive.kp * error_deg, -1.0, 1.0);
  const double load_duty = LoadDuty(p, drive, angle_deg);
  const double net = duty - load_duty;
  const double band = p.friction_duty + p.friction_load_ratio * std::abs(load_duty);
  if (std::abs(net) <= band) return 0.0;
  return p.v_max_deg_s * (net - std::copysign(band, net));
}

/// The share of the way to w* the velocity goes in one tick: 1 - exp(-tick_s / velocity_lag_s).
inline double VelocityBlend(const ServoModelParams& p, double tick_s) {
  return -std::expm1(-tick_s / p.velocity_lag_s);
}

/// One tick's angle and velocity (AdvanceServoModel), `blend` = VelocityBlend(p, tick_s): from
/// M(t-1), w(t-1) under the request R(t-1-l) = `acting_request_deg` to M(t), w(t).
inline void Advance(const ServoModelParams& p, const ServoDrive& drive, double tick_s, double blend,
                    double acting_request_deg, double& angle_deg, double& velocity_deg_s) {
  const double target = TargetSpeed(p, drive, angle_deg, acting_request_deg - angle_deg);
  velocity_deg_s += blend * (target - velocity_deg_s);
  angle_deg += velocity_deg_s * tick_s;
}

}  // namespace leglab::servo_tick
