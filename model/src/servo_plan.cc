#include "leglab/model/servo_plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "leglab/core/format.h"

namespace leglab {
namespace {

// The extended model as the planner steps it.
struct ExtendedStepper {
  using State = ServoModelState;
  const ServoModelParams& params;
  const ServoDrive& drive;
  double tick_s;

  int Lag() const { return params.lag_ticks; }
  State Rest(double angle_deg) const { return ServoRestState(params, angle_deg); }
  double Step(State& state, double request_deg) const {
    return StepServoModel(params, drive, tick_s, state, request_deg);
  }
};

// The paper's model (eq. 3) as the planner steps it.
struct PaperStepper {
  using State = JointModelState;
  const JointModelParams& params;

  int Lag() const { return params.lag_ticks; }
  State Rest(double angle_deg) const { return RestState(params, angle_deg); }
  double Step(State& state, double request_deg) const {
    return StepJointModel(params, state, request_deg);
  }
};

// What every plan is asked: follow `desired` with requests in [min_deg, max_deg] that change
// by at most `max_step_deg` a tick, from R(-1) = desired[0].
struct Problem {
  std::span<const double> desired;
  double min_deg;
  double max_deg;
  double max_step_deg;
};

Problem CheckProblem(std::span<const double> desired, const ServoLimits& limits, double tick_s) {
  if (!(std::isfinite(tick_s) && tick_s > 0.0)) {
    throw std::invalid_argument("servo plan: tick_s must be positive, got " + FormatNumber(tick_s));
  }
  if (!std::isfinite(limits.min_deg) || !std::isfinite(limits.max_deg) ||
      limits.min_deg >= limits.max_deg) {
    throw std::invalid_argument("servo plan: the limits need finite min_deg < max_deg, got " +
                                FormatNumber(limits.min_deg) + " and " +
                                FormatNumber(limits.max_deg));
  }
  if (!(std::isfinite(limits.max_speed_deg_s) && limits.max_speed_deg_s > 0.0)) {
    throw std::invalid_argument("servo plan: max_speed_deg_s must be positive, got " +
                                FormatNumber(limits.max_speed_deg_s));
  }
  if (desired.empty()) throw std::invalid_argument("servo plan: no desired angles");
  for (size_t t = 0; t < desired.size(); ++t) {
    if (!std::isfinite(desired[t])) {
      throw std::invalid_argument("servo plan: desired angle " + std::to_string(t) +
                                  " is not finite");
    }
  }
  if (desired[0] < limits.min_deg || desired[0] > limits.max_deg) {
    throw std::invalid_argument("servo plan: the first desired angle " + FormatNumber(desired[0]) +
                                " is outside the limits");
  }
  return {desired, limits.min_deg, limits.max_deg, limits.max_speed_deg_s * tick_s};
}

// Runs `stepper` over `requests` from rest at `start_deg`: M(0..N-1).
template <class Stepper>
std::vector<double> Simulate(const Stepper& stepper, double start_deg,
                             std::span<const double> requests) {
  typename Stepper::State state = stepper.Rest(start_deg);
  std::vector<double> angles(requests.size());
  for (size_t t = 0; t < requests.size(); ++t) angles[t] = stepper.Step(state, requests[t]);
  return angles;
}

template <class Stepper>
double SquaredError(const Stepper& stepper, const Problem& p, std::span<const double> requests) {
  const std::vector<double> angles = Simulate(stepper, p.desired[0], requests);
  double sum = 0.0;
  for (size_t t = 0; t < angles.size(); ++t) sum += std::pow(angles[t] - p.desired[t], 2);
  return sum;
}

// M(t+l+1) when R(t) = `request` is stepped from `from` (which holds M(t-1)); the l + 1 steps
// after it use the same request, which cannot reach M(t+l+1). `scratch` avoids allocations.
template <class Stepper>
double ReachedAngle(const Stepper& stepper, const typename Stepper::State& from,
                    typename Stepper::State& scratch, double request) {
  scratch = from;
  double angle = 0.0;
  for (int i = 0; i < stepper.Lag() + 2; ++i) angle = stepper.Step(scratch, request);
  return angle;
}

// The least r in [lo, hi] with reach(r) >= value, to the resolution of a double (hi if none):
// reach is non-decreasing.
template <class Reach>
double FirstAtLeast(const Reach& reach, double lo, double hi, double value) {
  if (reach(lo) >= value) return lo;
  for (double mid = lo + (hi - lo) / 2; mid > lo && mid < hi; mid = lo + (hi - lo) / 2) {
    (reach(mid) >= value ? hi : lo) = mid;
  }
  return hi;
}

// The greatest r in [lo, hi] with reach(r) <= value (lo if none).
template <class Reach>
double LastAtMost(const Reach& reach, double lo, double hi, double value) {
  if (reach(hi) <= value) return hi;
  for (double mid = lo + (hi - lo) / 2; mid > lo && mid < hi; mid = lo + (hi - lo) / 2) {
    (reach(mid) <= value ? lo : hi) = mid;
  }
  return lo;
}

struct Choice {
  double request_deg;
  double reached_deg;
};

// The least-effort request in [lo, hi] whose reached angle is nearest `target`: of the
// interval of requests that reach the best angle, the one nearest `acting_deg`.
template <class Reach>
Choice ChooseRequest(const Reach& reach, double lo, double hi, double target, double acting_deg) {
  const double at_lo = reach(lo);
  const double at_hi = reach(hi);
  double first = lo;
  double last = hi;
  if (target <= at_lo) {
    last = LastAtMost(reach, lo, hi, at_lo);
  } else if (target >= at_hi) {
    first = FirstAtLeast(reach, lo, hi, at_hi);
  } else {
    first = FirstAtLeast(reach, lo, hi, target);
    last = LastAtMost(reach, first, hi, target);
  }
  const double request = std::clamp(acting_deg, first, last);
  return {request, reach(request)};
}

// kModelBased: R(t) by inversion, tick by tick; flags the desired angles it cannot reach.
template <class Stepper>
std::vector<double> ModelBasedRequests(const Stepper& stepper, const Problem& p,
                                       std::vector<uint8_t>& beyond_servo) {
  const size_t n = p.desired.size();
  const auto lag = static_cast<size_t>(stepper.Lag());
  typename Stepper::State state = stepper.Rest(p.desired[0]);
  typename Stepper::State scratch = state;
  const auto reach = [&](double r) { return ReachedAngle(stepper, state, scratch, r); };
  std::vector<double> requests(n);
  double previous = p.desired[0];
  for (size_t t = 0; t < n; ++t) {
    const double lo = std::max(p.min_deg, previous - p.max_step_deg);
    const double hi = std::min(p.max_deg, previous + p.max_step_deg);
    const size_t acts_at = t + lag + 1;
    const double target = p.desired[std::min(acts_at, n - 1)];
    // M(t+l): one step fewer than ReachedAngle, so R(t) has not acted yet.
    scratch = state;
    double acting = state.angle_deg;
    for (size_t i = 0; i < lag + 1; ++i) acting = stepper.Step(scratch, previous);
    const Choice choice = ChooseRequest(reach, lo, hi, target, acting);
    if (acts_at < n && std::abs(choice.reached_deg - target) > kBeyondServoToleranceDeg) {
      beyond_servo[acts_at] = 1;
    }
    requests[t] = previous = choice.request_deg;
    stepper.Step(state, previous);
  }
  return requests;
}

// The requests clamped in time order to the limits and the speed limit from R(-1) = `start`.
void Project(const Problem& p, std::vector<double>& requests) {
  double previous = p.desired[0];
  for (double& r : requests) {
    r = std::clamp(r, previous - p.max_step_deg, previous + p.max_step_deg);
    r = std::clamp(r, p.min_deg, p.max_deg);
    previous = r;
  }
}

// d/dR(t) of the squared error over the ticks t+l+1 .. t+l+1+kOptimalWindowTicks, by central
// differences from the states the requests pass through.
template <class Stepper>
std::vector<double> WindowGradient(const Stepper& stepper, const Problem& p,
                                   const std::vector<double>& requests) {
  constexpr double kStepDeg = 1e-4;
  const size_t n = requests.size();
  const auto lag = static_cast<size_t>(stepper.Lag());
  std::vector<typename Stepper::State> states(n, stepper.Rest(p.desired[0]));
  for (size_t t = 0; t + 1 < n; ++t) {
    states[t + 1] = states[t];
    stepper.Step(states[t + 1], requests[t]);
  }
  typename Stepper::State scratch = states[0];
  const auto window_error = [&](size_t t, double request) {
    scratch = states[t];
    const size_t end = std::min(n, t + lag + 2 + static_cast<size_t>(kOptimalWindowTicks));
    double sum = 0.0;
    for (size_t k = t; k < end; ++k) {
      const double angle = stepper.Step(scratch, k == t ? request : requests[k]);
      if (k >= t + lag + 1) sum += std::pow(angle - p.desired[k], 2);
    }
    return sum;
  };
  std::vector<double> gradient(n);
  for (size_t t = 0; t < n; ++t) {
    gradient[t] =
        (window_error(t, requests[t] + kStepDeg) - window_error(t, requests[t] - kStepDeg)) /
        (2 * kStepDeg);
  }
  return gradient;
}

// One projected gradient step that lowers `error`, halving the step length `alpha` until one
// does (at most 40 times). Returns false, leaving `requests` as they are, if none does.
template <class Stepper>
bool DescentStep(const Stepper& stepper, const Problem& p, std::vector<double>& requests,
                 double& error, double& alpha) {
  const std::vector<double> gradient = WindowGradient(stepper, p, requests);
  double largest = 0.0;
  for (const double g : gradient) largest = std::max(largest, std::abs(g));
  if (largest == 0.0) return false;
  // The first step moves the steepest request by 1 deg.
  if (alpha == 0.0) alpha = 1.0 / largest;
  for (int tries = 0; tries < 40; ++tries, alpha /= 2) {
    std::vector<double> candidate(requests);
    for (size_t t = 0; t < candidate.size(); ++t) candidate[t] -= alpha * gradient[t];
    Project(p, candidate);
    const double candidate_error = SquaredError(stepper, p, candidate);
    if (candidate_error < error) {
      requests = std::move(candidate);
      error = candidate_error;
      if (tries == 0) alpha *= 2;  // a step taken at once: try a longer one next time
      return true;
    }
  }
  return false;
}

// The duty u that gives target speed `speed` (deg/s) at load duty `load` and friction band
// `band` (the lines n..w* of ServoModelParams inverted), the least |u| where the speed is 0.
double DutyForSpeed(const ServoModelParams& params, double speed, double load, double band) {
  if (speed > 0.0) return load + speed / params.v_max_deg_s + band;
  if (speed < 0.0) return load + speed / params.v_max_deg_s - band;
  return load - std::clamp(load, -band, band);  // inside the band: as little duty as holds
}

// kModelBased for the extended model, the paper's method carried over: the model inverted
// along the desired path. R(t) acts on tick k = t + l + 1; were the joint on the path at
// k - 1 (angle D(k-1), velocity w_d(k-1)), its velocity at k is w_d(k) when the target speed is
// w* = w_d(k-1) + (w_d(k) - w_d(k-1)) / (1 - exp(-tick / velocity_lag)); the duty giving w*
// (DutyForSpeed) and the P-law give the request R(t) = D(k-1) + u / (gain * kp). A duty
// beyond +-1 is saturated (the least request that saturates) and flagged. Open loop like the
// paper's: the servo's own P-law pulls the joint back to the path, where a tick-by-tick
// inversion of the predicted state would have to make the velocity jump.
std::vector<double> DesiredPathRequests(const ExtendedStepper& stepper, const Problem& p,
                                        std::vector<uint8_t>& beyond_servo) {
  const ServoModelParams& params = stepper.params;
  const size_t n = p.desired.size();
  const double blend = -std::expm1(-stepper.tick_s / params.velocity_lag_s);
  const auto desired = [&](long k) {
    return p.desired[std::clamp<long>(k, 0, static_cast<long>(n) - 1)];
  };
  const auto speed = [&](long k) { return (desired(k) - desired(k - 1)) / stepper.tick_s; };
  std::vector<double> requests(n);
  double previous = p.desired[0];
  for (size_t t = 0; t < n; ++t) {
    const long k = static_cast<long>(t) + params.lag_ticks + 1;
    const double target = speed(k - 1) + (speed(k) - speed(k - 1)) / blend;
    const double angle = desired(k - 1);
    const double load = ServoLoadDuty(params, stepper.drive, angle);
    const double band = params.friction_duty + params.friction_load_ratio * std::abs(load);
    const double duty = DutyForSpeed(params, target, load, band);
    const double error = std::clamp(duty, -1.0, 1.0) / (params.gain_per_deg_kp * stepper.drive.kp);
    const double wanted = angle + error;
    double request = std::clamp(wanted, previous - p.max_step_deg, previous + p.max_step_deg);
    request = std::clamp(request, p.min_deg, p.max_deg);
    const bool beyond =
        std::abs(duty) > 1.0 || std::abs(request - wanted) > kBeyondServoToleranceDeg;
    if (beyond && static_cast<size_t>(k) < n) beyond_servo[static_cast<size_t>(k)] = 1;
    requests[t] = previous = request;
  }
  return requests;
}

// kOptimal from the kModelBased requests: never worse than them.
template <class Stepper>
std::vector<double> OptimalRequests(const Stepper& stepper, const Problem& p,
                                    std::vector<double> requests) {
  double error = SquaredError(stepper, p, requests);
  double alpha = 0.0;
  for (int i = 0; i < kOptimalMaxIterations; ++i) {
    const double before = error;
    if (!DescentStep(stepper, p, requests, error, alpha)) break;
    if (before - error <= 1e-12 * before) break;
  }
  return requests;
}

template <class Stepper>
ServoPlan Plan(const Stepper& stepper, const Problem& p, PlanMethod method) {
  ServoPlan plan;
  plan.beyond_servo.assign(p.desired.size(), 0);
  if constexpr (std::is_same_v<Stepper, ExtendedStepper>) {
    plan.request_deg = DesiredPathRequests(stepper, p, plan.beyond_servo);
  } else {
    plan.request_deg = ModelBasedRequests(stepper, p, plan.beyond_servo);
  }
  if (method == PlanMethod::kOptimal) {
    plan.request_deg = OptimalRequests(stepper, p, std::move(plan.request_deg));
  }
  plan.predicted_deg = Simulate(stepper, p.desired[0], plan.request_deg);
  plan.beyond_servo_ticks =
      static_cast<int>(std::count(plan.beyond_servo.begin(), plan.beyond_servo.end(), 1));
  return plan;
}

void CheckDrive(const ServoDrive& drive) {
  if (!(std::isfinite(drive.kp) && drive.kp > 0.0)) {
    throw std::invalid_argument("servo plan: kp must be positive, got " + FormatNumber(drive.kp));
  }
  if (!(std::isfinite(drive.mass_kg) && drive.mass_kg >= 0.0) ||
      !(std::isfinite(drive.length_m) && drive.length_m >= 0.0)) {
    throw std::invalid_argument("servo plan: mass_kg and length_m must be zero or positive");
  }
}

}  // namespace

ServoPlan PlanServoRequests(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                            std::span<const double> desired_deg, const ServoLimits& limits,
                            PlanMethod method) {
  const std::string problem = ServoModelParamsProblem(params);
  if (!problem.empty()) throw std::invalid_argument("servo plan: servo model: " + problem);
  CheckDrive(drive);
  const Problem p = CheckProblem(desired_deg, limits, tick_s);
  return Plan(ExtendedStepper{params, drive, tick_s}, p, method);
}

ServoPlan PlanJointModelRequests(const JointModelParams& params, double tick_s,
                                 std::span<const double> desired_deg, const ServoLimits& limits,
                                 PlanMethod method) {
  const std::string problem = JointModelParamsProblem(params);
  if (!problem.empty()) throw std::invalid_argument("servo plan: joint model: " + problem);
  const Problem p = CheckProblem(desired_deg, limits, tick_s);
  return Plan(PaperStepper{params}, p, method);
}

std::vector<double> PredictServoAngles(const ServoModelParams& params, const ServoDrive& drive,
                                       double tick_s, std::span<const double> requests_deg) {
  if (requests_deg.empty()) return {};
  return Simulate(ExtendedStepper{params, drive, tick_s}, requests_deg[0], requests_deg);
}

std::vector<double> PredictJointModelAngles(const JointModelParams& params,
                                            std::span<const double> requests_deg) {
  if (requests_deg.empty()) return {};
  return Simulate(PaperStepper{params}, requests_deg[0], requests_deg);
}

}  // namespace leglab
