#include "leglab/model/servo_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "leglab/core/format.h"
#include "leglab/model/nelder_mead.h"

namespace leglab {
namespace {

std::string Positive(const char* field, double value) {
  if (std::isfinite(value) && value > 0.0) return {};
  return std::string(field) + " must be positive, got " + FormatNumber(value);
}

std::string NonNegative(const char* field, double value) {
  if (std::isfinite(value) && value >= 0.0) return {};
  return std::string(field) + " must be zero or positive, got " + FormatNumber(value);
}

void CheckRecording(const ServoRecording& recording) {
  const size_t n = recording.request_deg.size();
  if (recording.measured_deg.size() != n || recording.scored.size() != n) {
    throw std::invalid_argument("servo recording: request, measured and scored sizes differ");
  }
  const ServoDrive& drive = recording.drive;
  if (!(std::isfinite(drive.kp) && drive.kp > 0.0) ||
      !(std::isfinite(drive.mass_kg) && drive.mass_kg >= 0.0) ||
      !(std::isfinite(drive.length_m) && drive.length_m >= 0.0)) {
    throw std::invalid_argument("servo recording: kp must be positive, mass and length >= 0");
  }
  for (size_t t = 0; t < n; ++t) {
    if (!std::isfinite(recording.request_deg[t]) || !std::isfinite(recording.measured_deg[t])) {
      throw std::invalid_argument("servo recording: sample " + std::to_string(t) +
                                  " is not finite");
    }
  }
}

// The fit's variables: logarithms of the positive fields, the frictions as they are.
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

double MeanSquaredError(const std::vector<double>& predicted, const ServoRecording& recording) {
  double sum = 0.0;
  size_t count = 0;
  for (size_t t = 0; t < predicted.size(); ++t) {
    if (recording.scored[t] == 0) continue;
    const double e = predicted[t] - recording.measured_deg[t];
    sum += e * e;
    ++count;
  }
  return sum / static_cast<double>(count);
}

}  // namespace

std::string ServoModelParamsProblem(const ServoModelParams& params) {
  for (const std::string& problem : {Positive("gain_per_deg_kp", params.gain_per_deg_kp),
                                     Positive("v_max_deg_s", params.v_max_deg_s),
                                     Positive("stall_torque_nm", params.stall_torque_nm),
                                     NonNegative("friction_duty", params.friction_duty),
                                     NonNegative("friction_load_ratio", params.friction_load_ratio),
                                     Positive("velocity_lag_s", params.velocity_lag_s)}) {
    if (!problem.empty()) return problem;
  }
  if (params.lag_ticks < 0) {
    return "lag_ticks must be zero or positive, got " + std::to_string(params.lag_ticks);
  }
  return {};
}

std::vector<double> RecordedRequestsUpTo(const ServoRecording& recording, size_t t, size_t count) {
  std::vector<double> requests(count);
  for (size_t i = 0; i < count; ++i) requests[i] = recording.request_deg[t >= i ? t - i : 0];
  return requests;
}

ServoModelState ServoRestState(const ServoModelParams& params, double angle_deg) {
  ServoModelState state;
  state.angle_deg = angle_deg;
  state.past_requests_deg.assign(static_cast<size_t>(params.lag_ticks) + 1, angle_deg);
  return state;
}

double ServoLoadDuty(const ServoModelParams& params, const ServoDrive& drive, double angle_deg) {
  return drive.mass_kg * kGravityMS2 * drive.length_m *
         std::sin(angle_deg * std::numbers::pi / 180.0) / params.stall_torque_nm;
}

double ServoTargetSpeed(const ServoModelParams& params, const ServoDrive& drive, double angle_deg,
                        double error_deg) {
  const double duty = std::clamp(params.gain_per_deg_kp * drive.kp * error_deg, -1.0, 1.0);
  const double load_duty = ServoLoadDuty(params, drive, angle_deg);
  const double net = duty - load_duty;
  const double band = params.friction_duty + params.friction_load_ratio * std::abs(load_duty);
  if (std::abs(net) <= band) return 0.0;
  return params.v_max_deg_s * (net - std::copysign(band, net));
}

double AdvanceServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                         ServoModelState& state) {
  const std::vector<double>& past = state.past_requests_deg;
  const double target =
      ServoTargetSpeed(params, drive, state.angle_deg, past.back() - state.angle_deg);
  const double blend = -std::expm1(-tick_s / params.velocity_lag_s);
  state.velocity_deg_s += blend * (target - state.velocity_deg_s);
  state.angle_deg += state.velocity_deg_s * tick_s;
  return state.angle_deg;
}

void PushServoModelRequest(ServoModelState& state, double request_deg) {
  std::vector<double>& past = state.past_requests_deg;
  // R(t) joins the front; R(t-1-l), now used, leaves the back.
  std::rotate(past.rbegin(), past.rbegin() + 1, past.rend());
  past.front() = request_deg;
}

double StepServoModel(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                      ServoModelState& state, double request_deg) {
  const double angle = AdvanceServoModel(params, drive, tick_s, state);
  PushServoModelRequest(state, request_deg);
  return angle;
}

std::vector<double> PredictServoRecording(const ServoModelParams& params,
                                          const ServoRecording& recording, double tick_s) {
  CheckRecording(recording);
  if (!(std::isfinite(tick_s) && tick_s > 0.0)) {
    throw std::invalid_argument("servo recording: tick_s must be positive");
  }
  ServoModelState state;
  return PredictDrivenRuns(
      recording,
      [&](size_t t) {
        state.angle_deg = recording.measured_deg[t];
        state.velocity_deg_s = 0.0;
        state.past_requests_deg =
            RecordedRequestsUpTo(recording, t, static_cast<size_t>(params.lag_ticks) + 1);
      },
      [&](size_t t) {
        return StepServoModel(params, recording.drive, tick_s, state, recording.request_deg[t]);
      });
}

ServoModelParams FitServoModel(std::span<const ServoRecording> recordings, double tick_s,
                               const ServoFitOptions& options) {
  if (recordings.empty()) throw std::invalid_argument("servo fit: no recordings");
  if (!(std::isfinite(tick_s) && tick_s > 0.0)) {
    throw std::invalid_argument("servo fit: tick_s must be positive");
  }
  if (options.lag_max_ticks < 0 || options.restarts < 1 || options.iterations < 1) {
    throw std::invalid_argument(
        "servo fit: lag_max_ticks must be >= 0, restarts and iterations >= 1");
  }
  for (const ServoRecording& r : recordings) {
    CheckRecording(r);
    if (std::find(r.scored.begin(), r.scored.end(), 1) == r.scored.end()) {
      throw std::invalid_argument("servo fit: a recording has no driven tick");
    }
  }
  const FitVariables variables{options.v_max_deg_s.has_value(), options.v_max_deg_s.value_or(0.0)};
  ServoModelParams best;
  double best_error = std::numeric_limits<double>::infinity();
  for (int lag = 0; lag <= options.lag_max_ticks; ++lag) {
    const SimplexObjective objective = [&](const std::vector<double>& x) {
      const ServoModelParams p = variables.ToParams(x, lag);
      if (p.friction_duty < 0.0 || p.friction_load_ratio < 0.0 || p.friction_load_ratio > 2.0) {
        return std::numeric_limits<double>::infinity();
      }
      double sum = 0.0;
      for (const ServoRecording& r : recordings) {
        sum += MeanSquaredError(PredictServoRecording(p, r, tick_s), r);
      }
      return std::isfinite(sum) ? sum : std::numeric_limits<double>::infinity();
    };
    std::vector<double> x = StartPoint(recordings, variables.fixed_v_max);
    std::vector<double> step(x.size(), 0.5);
    double error = objective(x);
    for (int run = 0; run < options.restarts; ++run) {
      error = NelderMead(objective, x, step, options.iterations, 1e-7);
    }
    if (error < best_error) {
      best_error = error;
      best = variables.ToParams(x, lag);
    }
  }
  return best;
}

}  // namespace leglab
