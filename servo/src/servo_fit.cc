#include "leglab/servo/servo_fit.h"

// FitServoModel: Nelder-Mead on the open-loop prediction error, lag by lag.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "leglab/core/format.h"
#include "leglab/model/nelder_mead.h"
#include "servo_model_tick.h"
#include "servo_rollouts.h"

namespace leglab {
namespace {

// The fit's variables: logarithms of the positive fields, the frictions as they are, in the
// order gain, v_max (unless given), stall torque, friction band, its load ratio, velocity lag.
struct FitVariables {
  bool fixed_v_max = false;
  double v_max_deg_s = 0.0;

  ServoModelParams ToParams(const std::vector<double>& x, int lag) const {
    size_t i = 0;
    ServoModelParams p;
    p.gain_per_deg_kp = std::exp(x[i++]);
    p.v_max_deg_s = fixed_v_max ? v_max_deg_s : std::exp(x[i++]);
    p.stall_torque_nm = std::exp(x[i++]);
    p.friction_duty = x[i++];
    p.friction_load_ratio = x[i++];
    p.velocity_lag_s = std::exp(x[i++]);
    p.lag_ticks = lag;
    return p;
  }
};

// A start every recording set can take: saturation at 20 deg of error at the median gain, the
// load held at half duty when level, and small friction and lag.
std::vector<double> StartPoint(std::span<const ServoRecording> recordings, bool fixed_v_max) {
  std::vector<double> kps;
  double load_nm = 0.0;
  for (const ServoRecording& r : recordings) {
    kps.push_back(r.drive.kp);
    load_nm = std::max(load_nm, r.drive.mass_kg * kGravityMS2 * r.drive.length_m);
  }
  std::nth_element(kps.begin(), kps.begin() + static_cast<long>(kps.size() / 2), kps.end());
  const double kp = kps[kps.size() / 2];
  std::vector<double> x = {std::log(1.0 / (20.0 * kp))};
  if (!fixed_v_max) x.push_back(std::log(500.0));
  x.push_back(std::log(load_nm > 0.0 ? 2.0 * load_nm : 1.0));
  x.push_back(0.02);  // friction_duty
  x.push_back(0.3);   // friction_load_ratio
  x.push_back(std::log(0.03));
  return x;
}

// The fit's objective at one lag: the sum over recordings of each one's mean squared open-loop
// prediction error over its driven ticks, the errors of PredictServoRecording bit for bit,
// without its allocations and checks (done once, in FitServoModel).
class PredictionError {
 public:
  PredictionError(std::span<const ServoRecording> recordings, double tick_s, int lag)
      : rollouts_(recordings, tick_s, lag), instructions_(BestLaneInstructions()) {
    for (const ServoRecording& r : recordings) {
      driven_ticks_.push_back(
          static_cast<double>(std::count(r.scored.begin(), r.scored.end(), uint8_t{1})));
    }
  }

  double operator()(const ServoModelParams& p) const {
    rollouts_.SquaredErrors(p, sums_, instructions_);
    double sum = 0.0;
    for (size_t k = 0; k < sums_.size(); ++k) sum += sums_[k] / driven_ticks_[k];
    return sum;
  }

 private:
  ServoRollouts rollouts_;
  LaneInstructions instructions_;
  std::vector<double> driven_ticks_;  // per recording
  mutable std::vector<double> sums_;  // work space
};

}  // namespace

void VisitKeys(KeyVisitor& v, ServoFitOptions& options) {
  v.Key("lag_max_ticks", options.lag_max_ticks,
        WithDescription(kAnyJointModel.lag_ticks, "l is searched over [0, lag_max_ticks]"));
  if (options.v_max_deg_s) v.Key("v_max_deg_s", *options.v_max_deg_s, kServoVMaxDoc);
  v.Key("restarts", options.restarts,
        {.min = 1, .max = 1000, .description = "Nelder-Mead runs per lag"});
  v.Key("iterations", options.iterations, kServoFitIterationsDoc);
}

ServoLagFit FitServoModelAtLag(std::span<const ServoRecording> recordings, double tick_s,
                               const ServoFitOptions& options, int lag) {
  if (recordings.empty()) throw std::invalid_argument("servo fit: no recordings");
  if (const std::string problem = KeyValueProblem(tick_s, kServoTickDoc); !problem.empty()) {
    throw std::invalid_argument("servo fit: tick_s must be " + problem + ", got " +
                                FormatNumber(tick_s));
  }
  if (std::string problem = KeysProblem(
          options, [](KeyVisitor& v, ServoFitOptions& o) { VisitKeys(v, o); }, "servo fit: ");
      !problem.empty()) {
    throw std::invalid_argument(problem);
  }
  const KeyDoc searched = WithRange(kAnyJointModel.lag_ticks, 0, options.lag_max_ticks);
  if (const std::string problem = KeyValueProblem(lag, searched); !problem.empty()) {
    throw std::invalid_argument("servo fit: lag must be " + problem + " (lag_max_ticks), got " +
                                std::to_string(lag));
  }
  for (const ServoRecording& r : recordings) {
    servo_tick::CheckRecording(r);
    if (std::find(r.scored.begin(), r.scored.end(), 1) == r.scored.end()) {
      throw std::invalid_argument("servo fit: a recording has no driven tick");
    }
  }
  const FitVariables variables{options.v_max_deg_s.has_value(), options.v_max_deg_s.value_or(0.0)};
  const PredictionError error(recordings, tick_s, lag);
  const SimplexObjective objective = [&](const std::vector<double>& x) {
    const ServoModelParams p = variables.ToParams(x, lag);
    if (p.friction_duty < 0.0 || p.friction_load_ratio < 0.0 || p.friction_load_ratio > 2.0) {
      return std::numeric_limits<double>::infinity();
    }
    const double sum = error(p);
    return std::isfinite(sum) ? sum : std::numeric_limits<double>::infinity();
  };
  std::vector<double> x = StartPoint(recordings, variables.fixed_v_max);
  const std::vector<double> step(x.size(), 0.5);
  ServoLagFit fit;
  fit.squared_error = objective(x);
  for (int run = 0; run < options.restarts; ++run) {
    fit.squared_error = NelderMead(objective, x, step, options.iterations, 1e-7);
  }
  fit.params = variables.ToParams(x, lag);
  return fit;
}

ServoModelParams FitServoModel(std::span<const ServoRecording> recordings, double tick_s,
                               const ServoFitOptions& options) {
  ServoLagFit best = FitServoModelAtLag(recordings, tick_s, options, 0);
  for (int lag = 1; lag <= options.lag_max_ticks; ++lag) {
    const ServoLagFit fit = FitServoModelAtLag(recordings, tick_s, options, lag);
    if (fit.squared_error < best.squared_error) best = fit;
  }
  return best.params;
}

}  // namespace leglab
