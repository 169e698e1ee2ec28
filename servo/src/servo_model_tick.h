#pragma once

// The extended model's tick (ServoModelParams), inline for the loops that run it many times
// (the fit's rollouts) and for the model's own functions: one definition of the arithmetic, so
// that the fit scores exactly what the model predicts, bit for bit. Internal to leglab::servo.

#include <algorithm>
#include <cmath>

#include "leglab/servo/servo_model.h"
#include "sine_of_degrees.h"

namespace leglab::servo_tick {

/// Throws std::invalid_argument on a recording whose sizes differ, whose drive is out of range
/// or which holds a sample that is not finite.
void CheckRecording(const ServoRecording& recording);

/// What the target speed of model `p` driving `drive` multiplies by, computed once for the many
/// ticks of a rollout.
struct Coefficients {
  double duty_per_deg = 0.0;     ///< the duty per degree of error: gain kp
  double load_duty_at_90 = 0.0;  ///< the load's duty at 90 deg: m g L / stall torque
  double friction_duty = 0.0;    ///< the friction band at no load
  double friction_load_ratio = 0.0;
  double v_max_deg_s = 0.0;
};

/// The share of the way to w* the velocity goes in one tick: 1 - exp(-tick_s / velocity_lag_s).
inline double VelocityBlend(const ServoModelParams& p, double tick_s) {
  return -std::expm1(-tick_s / p.velocity_lag_s);
}

inline Coefficients CoefficientsOf(const ServoModelParams& p, const ServoDrive& drive) {
  return {.duty_per_deg = p.gain_per_deg_kp * drive.kp,
          .load_duty_at_90 = drive.mass_kg * kGravityMS2 * drive.length_m / p.stall_torque_nm,
          .friction_duty = p.friction_duty,
          .friction_load_ratio = p.friction_load_ratio,
          .v_max_deg_s = p.v_max_deg_s};
}

/// The load's duty g at `angle_deg` (ServoLoadDuty).
inline double LoadDuty(const Coefficients& c, double angle_deg) {
  return c.load_duty_at_90 * SinDegrees(angle_deg);
}

/// The speed w* the net duty settles to (ServoTargetSpeed).
inline double TargetSpeed(const Coefficients& c, double angle_deg, double error_deg) {
  const double duty = std::clamp(c.duty_per_deg * error_deg, -1.0, 1.0);
  const double load_duty = LoadDuty(c, angle_deg);
  const double net = duty - load_duty;
  const double band = c.friction_duty + c.friction_load_ratio * std::abs(load_duty);
  if (std::abs(net) <= band) return 0.0;
  return c.v_max_deg_s * (net - std::copysign(band, net));
}

/// One tick's angle and velocity (AdvanceServoModel), `blend` = VelocityBlend(p, tick_s): from
/// M(t-1), w(t-1) under the request R(t-1-l) = `acting_request_deg` to M(t), w(t).
inline void Advance(const Coefficients& c, double tick_s, double blend, double acting_request_deg,
                    double& angle_deg, double& velocity_deg_s) {
  const double target = TargetSpeed(c, angle_deg, acting_request_deg - angle_deg);
  velocity_deg_s += blend * (target - velocity_deg_s);
  angle_deg += velocity_deg_s * tick_s;
}

}  // namespace leglab::servo_tick
