#include "leglab/model/identification.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace leglab {
namespace {

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("identification: " + what);
}

// Sum of squared prediction errors over ticks >= warmup, and how many ticks were scored.
double SquaredError(const JointModelParams& p, const JointRecording& r, int warmup, long* count) {
  const long n = static_cast<long>(r.request_deg.size());
  const int memory = p.lag_ticks + p.accel_ticks;
  double angle = r.measured_deg[warmup - 1];
  double sum = 0.0;
  for (long t = warmup; t < n; ++t) {
    double velocity = 0.0;
    for (int i = p.lag_ticks + 1; i <= memory; ++i) {
      velocity += SpeedResponse(p, r.request_deg[t - i] - angle);
    }
    angle += velocity / p.accel_ticks;
    const double e = r.measured_deg[t] - angle;
    sum += e * e;
  }
  *count += n - warmup;
  return sum;
}

double TotalSquaredError(const JointModelParams& p, std::span<const JointRecording> recordings,
                         int warmup) {
  long count = 0;
  double sum = 0.0;
  for (const JointRecording& r : recordings) sum += SquaredError(p, r, warmup, &count);
  return sum;
}

// Nelder-Mead on (log v_max, log theta_0) with l and a fixed. Returns the best objective and
// writes the best parameters into `p`.
double FitContinuous(JointModelParams& p, std::span<const JointRecording> recordings, int warmup,
                     double v_start, double theta_start) {
  using Point = std::array<double, 2>;
  auto objective = [&](const Point& x) {
    JointModelParams q = p;
    q.v_max_deg_per_tick = std::exp(x[0]);
    q.theta0_deg = std::exp(x[1]);
    return TotalSquaredError(q, recordings, warmup);
  };
  std::array<Point, 3> simplex = {Point{std::log(v_start), std::log(theta_start)},
                                  Point{std::log(v_start * 1.2), std::log(theta_start)},
                                  Point{std::log(v_start), std::log(theta_start * 1.3)}};
  std::array<double, 3> value;
  for (int i = 0; i < 3; ++i) value[i] = objective(simplex[i]);

  for (int iteration = 0; iteration < 400; ++iteration) {
    std::array<int, 3> order = {0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return value[a] < value[b]; });
    const int best = order[0], middle = order[1], worst = order[2];
    const double size = std::max(std::abs(simplex[worst][0] - simplex[best][0]),
                                 std::abs(simplex[worst][1] - simplex[best][1]));
    if (size < 1e-9) break;
    const Point centroid = {0.5 * (simplex[best][0] + simplex[middle][0]),
                            0.5 * (simplex[best][1] + simplex[middle][1])};
    auto along = [&](double t) {
      return Point{centroid[0] + t * (simplex[worst][0] - centroid[0]),
                   centroid[1] + t * (simplex[worst][1] - centroid[1])};
    };
    const Point reflected = along(-1.0);
    const double reflected_value = objective(reflected);
    if (reflected_value < value[best]) {
      const Point expanded = along(-2.0);
      const double expanded_value = objective(expanded);
      if (expanded_value < reflected_value) {
        simplex[worst] = expanded, value[worst] = expanded_value;
      } else {
        simplex[worst] = reflected, value[worst] = reflected_value;
      }
    } else if (reflected_value < value[middle]) {
      simplex[worst] = reflected, value[worst] = reflected_value;
    } else {
      const bool outside = reflected_value < value[worst];
      const Point contracted = along(outside ? -0.5 : 0.5);
      const double contracted_value = objective(contracted);
      if (contracted_value < (outside ? reflected_value : value[worst])) {
        simplex[worst] = contracted, value[worst] = contracted_value;
      } else {
        // Shrink towards the best point.
        for (int i : {middle, worst}) {
          simplex[i] = {0.5 * (simplex[i][0] + simplex[best][0]),
                        0.5 * (simplex[i][1] + simplex[best][1])};
          value[i] = objective(simplex[i]);
        }
      }
    }
  }
  const int best = static_cast<int>(std::min_element(value.begin(), value.end()) - value.begin());
  p.v_max_deg_per_tick = std::exp(simplex[best][0]);
  p.theta0_deg = std::exp(simplex[best][1]);
  return value[best];
}

}  // namespace

std::vector<double> PredictRecording(const JointModelParams& p, const JointRecording& r,
                                     int warmup) {
  ValidateJointModelParams(p);
  const long n = static_cast<long>(r.request_deg.size());
  if (r.measured_deg.size() != r.request_deg.size()) Fail("request and measured lengths differ");
  if (warmup < p.lag_ticks + p.accel_ticks || warmup < 1 || warmup > n) {
    Fail("the warm-up must cover l + a ticks and fit in the recording");
  }
  std::vector<double> predicted(r.measured_deg.begin(), r.measured_deg.begin() + warmup);
  predicted.reserve(n);
  double angle = r.measured_deg[warmup - 1];
  for (long t = warmup; t < n; ++t) {
    double velocity = 0.0;
    for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
      velocity += SpeedResponse(p, r.request_deg[t - i] - angle);
    }
    angle += velocity / p.accel_ticks;
    predicted.push_back(angle);
  }
  return predicted;
}

IdentificationResult IdentifyJointModel(std::span<const JointRecording> recordings,
                                        const IdentificationOptions& o) {
  if (recordings.empty()) Fail("no recordings");
  if (o.lag_min_ticks < 0 || o.lag_max_ticks < o.lag_min_ticks) Fail("bad lag range");
  if (o.accel_min_ticks < 1 || o.accel_max_ticks < o.accel_min_ticks) Fail("bad accel range");
  const int warmup = o.lag_max_ticks + o.accel_max_ticks;

  // A starting top speed from the data: the fastest measured change, and theta_0 from it.
  double fastest = 0.0;
  for (size_t k = 0; k < recordings.size(); ++k) {
    const JointRecording& r = recordings[k];
    if (r.request_deg.size() != r.measured_deg.size()) {
      Fail("recording " + std::to_string(k) + ": request and measured lengths differ");
    }
    if (static_cast<long>(r.request_deg.size()) <= warmup) {
      Fail("recording " + std::to_string(k) + " is shorter than the warm-up of " +
           std::to_string(warmup + 1) + " ticks");
    }
    for (size_t t = 0; t < r.request_deg.size(); ++t) {
      if (!std::isfinite(r.request_deg[t]) || !std::isfinite(r.measured_deg[t])) {
        Fail("recording " + std::to_string(k) + " has a non-finite sample at tick " +
             std::to_string(t));
      }
      if (t > 0) fastest = std::max(fastest, std::abs(r.measured_deg[t] - r.measured_deg[t - 1]));
    }
  }
  if (!(fastest > 0.0)) Fail("the joint never moved: nothing to identify");

  IdentificationResult best;
  double best_error = std::numeric_limits<double>::infinity();
  for (int lag = o.lag_min_ticks; lag <= o.lag_max_ticks; ++lag) {
    for (int accel = o.accel_min_ticks; accel <= o.accel_max_ticks; ++accel) {
      for (double theta_factor : {1.5, 4.0}) {
        JointModelParams p{fastest, fastest * theta_factor, lag, accel};
        const double error = FitContinuous(p, recordings, warmup, fastest, fastest * theta_factor);
        if (error < best_error) {
          best_error = error;
          best.params = p;
        }
      }
    }
  }
  long count = 0;
  for (const JointRecording& r : recordings)
    count += static_cast<long>(r.request_deg.size()) - warmup;
  best.rms_residual_deg = std::sqrt(best_error / static_cast<double>(count));
  return best;
}

}  // namespace leglab
