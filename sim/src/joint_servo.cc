#include "leglab/sim/joint_servo.h"
#include "leglab/core/units.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <numeric>

namespace leglab::sim {

JointServo::JointServo(const ServoConfig& config, double lower_rad, double upper_rad)
    : gain_per_s_(config.gain_per_s),
      damping_(config.damping),
      max_speed_rad_per_s_(DegToRad(config.max_speed_deg_s)),
      lower_rad_(lower_rad),
      upper_rad_(upper_rad),
      delay_line_(static_cast<std::size_t>(std::lround(config.delay_ms / kTickMs)) + 1),
      window_(std::max<std::size_t>(
          1, static_cast<std::size_t>(std::lround(config.smoothing_ms / kTickMs)))) {
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

double JointServo::FrameSpeedRadPerS(double angle_rad, double rate_rad_per_s) {
  const double error_rad = target_rad() - angle_rad;
  window_[next_] = std::clamp(gain_per_s_ * error_rad - damping_ * rate_rad_per_s,
                              -max_speed_rad_per_s_, max_speed_rad_per_s_);
  next_ = (next_ + 1) % window_.size();
  // A handful of frames: summing them afresh keeps the result exact and order-independent.
  return std::accumulate(window_.begin(), window_.end(), 0.0) / static_cast<double>(window_.size());
}

void JointServo::Hold(double angle_rad) {
  std::fill(delay_line_.begin(), delay_line_.end(), Clamp(angle_rad));
  oldest_ = 0;
  std::fill(window_.begin(), window_.end(), 0.0);
  next_ = 0;
}

}  // namespace leglab::sim
