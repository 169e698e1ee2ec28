#include "leglab/sim/sim_config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

namespace leglab::sim {
namespace {

// Shortest text that reads back as `value` ("30", "2.5", "-1e-07").
std::string Format(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

[[noreturn]] void Reject(std::string_view key, std::string_view expectation, double got) {
  throw std::invalid_argument(std::string(key) + " must be " + std::string(expectation) + ", got " +
                              Format(got));
}

// True when value / unit is a whole number, up to rounding of decimal inputs such as 0.1.
bool IsWholeMultiple(double value, double unit) {
  const double ratio = value / unit;
  return std::abs(ratio - std::round(ratio)) <= 1e-9 * std::max(1.0, std::abs(ratio));
}

void RequirePositive(std::string_view key, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    Reject(key, "a finite number > 0", value);
  }
}

}  // namespace

void ValidateSimConfig(const SimConfig& config) {
  if (config.urdf_path.empty()) {
    throw std::invalid_argument("urdf must name a URDF file, got an empty path");
  }
  const double dt = config.physics_dt_ms;
  if (!std::isfinite(dt) || dt <= 0.0 || dt > kTickMs || !IsWholeMultiple(kTickMs, dt)) {
    Reject("sim.physics_dt_ms", "> 0 and divide the 8 ms tick into a whole number of steps", dt);
  }
  const ServoConfig& servo = config.servo;
  if (!std::isfinite(servo.delay_ms) || servo.delay_ms < 0.0 ||
      !IsWholeMultiple(servo.delay_ms, kTickMs)) {
    Reject("servo.delay_ms", "a non-negative multiple of 8 ms", servo.delay_ms);
  }
  RequirePositive("servo.max_speed_deg_s", servo.max_speed_deg_s);
  RequirePositive("servo.gain_per_s", servo.gain_per_s);
  if (!std::isfinite(servo.damping) || servo.damping < 0.0) {
    Reject("servo.damping", "a finite number >= 0", servo.damping);
  }
  if (!std::isfinite(servo.smoothing_ms) || servo.smoothing_ms < 0.0 ||
      !IsWholeMultiple(servo.smoothing_ms, kTickMs)) {
    Reject("servo.smoothing_ms", "a non-negative multiple of 8 ms (the firmware's frame)",
           servo.smoothing_ms);
  }
  RequirePositive("servo.max_torque_nm", servo.max_torque_nm);
  if (!std::isfinite(config.sensor.noise_deg) || config.sensor.noise_deg < 0.0) {
    Reject("sensor.noise_deg", "a finite number >= 0", config.sensor.noise_deg);
  }
  const StandConfig& stand = config.stand;
  if (!stand.enabled) return;
  RequirePositive("stand.load_kg", stand.load_kg);
  if (!std::isfinite(stand.stop_below_shoulder_mm) || stand.stop_below_shoulder_mm < 0.0) {
    Reject("stand.stop_below_shoulder_mm",
           "a finite number >= 0 (a stop at or below the shoulder's walking height)",
           stand.stop_below_shoulder_mm);
  }
  if (!std::isfinite(stand.friction) || stand.friction < 0.0) {
    Reject("stand.friction", "a finite number >= 0", stand.friction);
  }
  RequirePositive("stand.contact_stiffness_n_per_m", stand.contact_stiffness_n_per_m);
  if (!std::isfinite(stand.contact_damping_n_s_per_m) || stand.contact_damping_n_s_per_m < 0.0) {
    Reject("stand.contact_damping_n_s_per_m", "a finite number >= 0",
           stand.contact_damping_n_s_per_m);
  }
  RequirePositive("stand.foot_radius_mm", stand.foot_radius_mm);
  if (!std::isfinite(stand.sled_stiffness_n_per_m) || stand.sled_stiffness_n_per_m < 0.0) {
    Reject("stand.sled_stiffness_n_per_m", "a finite number >= 0 (0: no sled, a rigid rail)",
           stand.sled_stiffness_n_per_m);
  }
  if (!std::isfinite(stand.sled_damping_n_s_per_m) || stand.sled_damping_n_s_per_m < 0.0) {
    Reject("stand.sled_damping_n_s_per_m", "a finite number >= 0", stand.sled_damping_n_s_per_m);
  }
  if (!std::isfinite(stand.belt_speed_mm_per_s)) {
    Reject("stand.belt_speed_mm_per_s", "finite", stand.belt_speed_mm_per_s);
  }
  if (!std::isfinite(stand.ground_below_shoulder_mm) ||
      stand.ground_below_shoulder_mm <= stand.foot_radius_mm) {
    Reject("stand ground (desired.locus.ground_below_shoulder_mm)",
           "finite and more than the foot radius below the shoulder",
           stand.ground_below_shoulder_mm);
  }
}

void SetSimSetting(SimConfig& config, std::string_view key, double value) {
  double* const fields[] = {&config.servo.delay_ms,     &config.servo.max_speed_deg_s,
                            &config.servo.gain_per_s,   &config.servo.damping,
                            &config.servo.smoothing_ms, &config.servo.max_torque_nm,
                            &config.sensor.noise_deg};
  static_assert(std::size(fields) == kChangeableSimSettings.size());
  for (size_t i = 0; i < kChangeableSimSettings.size(); ++i) {
    if (kChangeableSimSettings[i] == key) {
      *fields[i] = value;
      return;
    }
  }
  std::string valid;
  for (std::string_view name : kChangeableSimSettings) {
    valid += (valid.empty() ? "" : ", ") + std::string(name);
  }
  throw std::invalid_argument(std::string(key) + " cannot change during a run (can: " + valid +
                              ")");
}

int PhysicsStepsPerTick(double physics_dt_ms) {
  return static_cast<int>(std::lround(kTickMs / physics_dt_ms));
}

}  // namespace leglab::sim
