#include "leglab/model/line_inverse.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

enum class SlopeKind { kBelowTopSpeed, kTopSpeed };

// Classifies |m| against v_max; throws when it exceeds v_max.
SlopeKind ClassifySlope(const JointModelParams& p, double m) {
  ValidateJointModelParams(p);
  const double excess = std::abs(m) - p.v_max_deg_per_tick;
  if (!std::isfinite(m) || excess > kSlopeTolerance) {
    std::ostringstream msg;
    msg << "line inverse: slope " << m << " deg/tick exceeds v_max " << p.v_max_deg_per_tick
        << " deg/tick";
    throw std::invalid_argument(msg.str());
  }
  return excess >= -kSlopeTolerance ? SlopeKind::kTopSpeed : SlopeKind::kBelowTopSpeed;
}

}  // namespace

double LineResponse(const JointModelParams& p, double m, double x_deg) {
  double sum = 0.0;
  for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    sum += SpeedResponse(p, x_deg - m * (i - 1));
  }
  return sum / p.accel_ticks;
}

double TopSpeedLineOffset(const JointModelParams& p) {
  return p.theta0_deg + (p.lag_ticks + p.accel_ticks) * p.v_max_deg_per_tick;
}

double LineInverseOffsetClosed(const JointModelParams& p, double slope) {
  const SlopeKind kind = ClassifySlope(p, slope);
  const double v = p.v_max_deg_per_tick, theta0 = p.theta0_deg;
  const double l = p.lag_ticks, a = p.accel_ticks;
  if (!(theta0 > v && 4.0 * theta0 > v * a)) {
    std::ostringstream msg;
    msg << "closed-form C_m needs theta_0 > v_max and 4 theta_0 > v_max a (eq. 13); got "
           "theta_0 = "
        << theta0 << ", v_max = " << v << ", a = " << p.accel_ticks << ": use the exact C_m";
    throw std::domain_error(msg.str());
  }
  const double sign = slope < 0.0 ? -1.0 : 1.0;
  if (kind == SlopeKind::kTopSpeed) return sign * TopSpeedLineOffset(p);
  const double m = std::abs(slope);
  if (m * (theta0 / v + a / 2.0) < theta0) {       // eq. 10
    return sign * m * (theta0 / v + l + a / 2.0);  // eq. 11
  }
  return sign * (theta0 + m * (l + a - std::sqrt(2.0 * theta0 / m * a * (v - m) / v)));  // eq. 12
}

double LineInverseOffsetExact(const JointModelParams& p, double slope) {
  const SlopeKind kind = ClassifySlope(p, slope);
  const double sign = slope < 0.0 ? -1.0 : 1.0;
  if (kind == SlopeKind::kTopSpeed) return sign * TopSpeedLineOffset(p);
  // f is odd, so S_{-m}(x) = -S_m(-x) and C_{-m} = -C_m: solve for |m|.
  const double m = std::abs(slope);
  std::vector<double> breakpoints;
  breakpoints.reserve(2 * static_cast<size_t>(p.accel_ticks));
  for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    breakpoints.push_back(m * (i - 1) - p.theta0_deg);
    breakpoints.push_back(m * (i - 1) + p.theta0_deg);
  }
  std::sort(breakpoints.begin(), breakpoints.end());
  // At the smallest breakpoint every term is at -v_max < m; at the largest every term is at
  // v_max > m. Walk to the first breakpoint where S reaches m and interpolate back.
  double left_x = breakpoints.front();
  double left_s = LineResponse(p, m, left_x);
  for (size_t k = 1; k < breakpoints.size(); ++k) {
    const double right_x = breakpoints[k];
    const double right_s = LineResponse(p, m, right_x);
    if (right_s >= m) {
      return sign * (left_x + (m - left_s) * (right_x - left_x) / (right_s - left_s));
    }
    left_x = right_x;
    left_s = right_s;
  }
  // Unreachable: S(largest breakpoint) = v_max > m.
  throw std::logic_error("line inverse: S never reached m");
}

double LineInverseOffset(const JointModelParams& p, double slope, CmMethod method) {
  return method == CmMethod::kClosed ? LineInverseOffsetClosed(p, slope)
                                     : LineInverseOffsetExact(p, slope);
}

}  // namespace leglab
