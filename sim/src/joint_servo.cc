#include "leglab/sim/joint_servo.h"
#include "leglab/core/units.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <numeric>
#include <utility>

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

void JointServo::Reconfigure(const ServoConfig& config) {
  gain_per_s_ = config.gain_per_s;
  damping_ = config.damping;
  max_speed_rad_per_s_ = DegToRad(config.max_speed_deg_s);

  // The queue oldest first, re-sized at its old end.
  const size_t delay_size = static_cast<size_t>(std::lround(config.delay_ms / kTickMs)) + 1;
  std::vector<double> queue(delay_line_.size());
  for (size_t i = 0; i < queue.size(); ++i) {
    queue[i] = delay_line_[(oldest_ + i) % delay_line_.size()];
  }
  std::vector<double> delay_line(delay_size, queue.front());
  for (size_t i = 0; i < std::min(delay_size, queue.size()); ++i) {
    delay_line[delay_size - 1 - i] = queue[queue.size() - 1 - i];
  }
  delay_line_ = std::move(delay_line);
  oldest_ = 0;

  // The window newest last, re-sized at its old end.
  const size_t window_size =
      std::max<size_t>(1, static_cast<size_t>(std::lround(config.smoothing_ms / kTickMs)));
  std::vector<double> history(window_.size());
  for (size_t i = 0; i < history.size(); ++i) history[i] = window_[(next_ + i) % window_.size()];
  const double mean =
      std::accumulate(window_.begin(), window_.end(), 0.0) / static_cast<double>(window_.size());
  std::vector<double> window(window_size, mean);
  for (size_t i = 0; i < std::min(window_size, history.size()); ++i) {
    window[window_size - 1 - i] = history[history.size() - 1 - i];
  }
  window_ = std::move(window);
  next_ = 0;
}

void JointServo::Hold(double angle_rad) {
  std::fill(delay_line_.begin(), delay_line_.end(), Clamp(angle_rad));
  oldest_ = 0;
  std::fill(window_.begin(), window_.end(), 0.0);
  next_ = 0;
}

}  // namespace leglab::sim
