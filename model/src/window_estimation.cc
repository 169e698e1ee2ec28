#include "leglab/model/window_estimation.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace leglab {

WindowEstimate EstimateJointModelInWindow(const JointRecording& window,
                                          const JointModelParams& current,
                                          const WindowEstimationOptions& options) {
  ValidateJointModelParams(current);
  const IdentificationOptions& b = options.bounds;
  IdentificationOptions search;
  search.lag_min_ticks =
      std::clamp(current.lag_ticks - options.lag_radius_ticks, b.lag_min_ticks, b.lag_max_ticks);
  search.lag_max_ticks =
      std::clamp(current.lag_ticks + options.lag_radius_ticks, b.lag_min_ticks, b.lag_max_ticks);
  search.accel_min_ticks = std::clamp(current.accel_ticks - options.accel_radius_ticks,
                                      b.accel_min_ticks, b.accel_max_ticks);
  search.accel_max_ticks = std::clamp(current.accel_ticks + options.accel_radius_ticks,
                                      b.accel_min_ticks, b.accel_max_ticks);
  WindowEstimate estimate;
  estimate.fit = IdentifyJointModel(std::span(&window, 1), search);
  const JointModelParams& best = estimate.fit.params;
  if (best.lag_ticks != current.lag_ticks || best.accel_ticks != current.accel_ticks) {
    IdentificationOptions stay = search;
    stay.lag_min_ticks = stay.lag_max_ticks = current.lag_ticks;
    stay.accel_min_ticks = stay.accel_max_ticks = current.accel_ticks;
    IdentificationResult kept = IdentifyJointModel(std::span(&window, 1), stay);
    if (!(estimate.fit.rms_residual_deg < (1.0 - options.switch_margin) * kept.rms_residual_deg)) {
      estimate.fit = kept;
    }
  }

  // Saturation of the fitted model along the measured path: a request acting at t that is at
  // least theta_0 away from the angle at t - 1.
  const JointModelParams& p = estimate.fit.params;
  const auto n = static_cast<long>(window.request_deg.size());
  for (long t = p.lag_ticks + p.accel_ticks + 1; t < n; ++t) {
    for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
      if (std::abs(window.request_deg[t - i] - window.measured_deg[t - 1]) >= p.theta0_deg) {
        ++estimate.saturated_ticks;
        break;
      }
    }
  }
  estimate.v_max_identified = estimate.saturated_ticks >= options.min_saturated_ticks;
  if (!estimate.v_max_identified) {
    const double slope = p.v_max_deg_per_tick / p.theta0_deg;
    estimate.fit.params.v_max_deg_per_tick = current.v_max_deg_per_tick;
    estimate.fit.params.theta0_deg = current.v_max_deg_per_tick / slope;
  }
  return estimate;
}

}  // namespace leglab
