#include "leglab/sim/joint_servo.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <numeric>

namespace leglab::sim {

JointServo::JointServo(const ServoConfig& config, double physics_dt_ms, double lower_rad,
                       double upper_rad)
    : gain_per_s_(config.gain_per_s),
      max_speed_rad_per_s_(config.max_speed_deg_s * std::numbers::pi / 180.0),
      lower_rad_(lower_rad),
      upper_rad_(upper_rad),
      delay_line_(static_cast<std::size_t>(std::lround(config.delay_ms / kTickMs)) + 1),
      window_(std::max<std::size_t>(
          1, static_cast<std::size_t>(std::lround(config.smoothing_ms / physics_dt_ms)))) {
  assert(lower_rad <= upper_rad);
  Hold(0.0);
}

double JointServo::Clamp(double angle_rad) const {
  return std::clamp(angle_rad, lower_rad_, upper_rad_);
}

void JointServo::PushRequest(double request_rad) {
  // The oldest slot has been acted on for its last tick: overwrite it with the newest request,
  // and the next slot becomes the oldest.
  delay_line_[oldest_] = Clamp(request_rad);
  oldest_ = (oldest_ + 1) % delay_line_.size();
}

double JointServo::latest_request_rad() const {
  return delay_line_[(oldest_ + delay_line_.size() - 1) % delay_line_.size()];
}

double JointServo::MotorSpeedRadPerS(double angle_rad) {
  const double error_rad = target_rad() - angle_rad;
  const double commanded =
      std::clamp(gain_per_s_ * error_rad, -max_speed_rad_per_s_, max_speed_rad_per_s_);
  window_sum_ += commanded - window_[next_];
  window_[next_] = commanded;
  next_ = (next_ + 1) % window_.size();
  // Re-add the window once per pass so the running sum's rounding cannot drift.
  if (next_ == 0) {
    window_sum_ = std::accumulate(window_.begin(), window_.end(), 0.0);
  }
  return window_sum_ / static_cast<double>(window_.size());
}

void JointServo::Hold(double angle_rad) {
  std::fill(delay_line_.begin(), delay_line_.end(), Clamp(angle_rad));
  oldest_ = 0;
  std::fill(window_.begin(), window_.end(), 0.0);
  next_ = 0;
  window_sum_ = 0.0;
}

}  // namespace leglab::sim
