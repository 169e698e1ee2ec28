#include "leglab/servo/servo_plan.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "horizon_descent.h"
#include "leglab/core/format.h"
#include "servo_plan_steps.h"

namespace leglab {
namespace {

using servo_plan::Choice;
using servo_plan::DesiredPathTick;
using servo_plan::ExtendedStepper;
using servo_plan::InvertAtPending;
using servo_plan::PaperStepper;
using servo_plan::PathStep;

// What every plan is asked: follow `desired` with requests in [min_deg, max_deg] that change
// by at most `max_step_deg` a tick, from R(-1) = desired[0].
struct Problem {
  std::span<const double> desired;
  double min_deg;
  double max_deg;
  double max_step_deg;
};

std::string TickProblem(double tick_s) {
  const std::string problem = KeyValueProblem(tick_s, kServoTickDoc);
  if (problem.empty()) return {};
  return "tick_s must be " + problem + ", got " + FormatNumber(tick_s);
}

// An angle is within kServoAngleDoc.
bool InRange(double angle_deg) { return KeyValueProblem(angle_deg, kServoAngleDoc).empty(); }

Problem CheckProblem(std::span<const double> desired, const ServoLimits& limits, double tick_s) {
  if (std::string problem = ServoLimitsProblem(limits); !problem.empty()) {
    throw std::invalid_argument("servo plan: " + problem);
  }
  if (desired.empty()) throw std::invalid_argument("servo plan: no desired angles");
  for (size_t t = 0; t < desired.size(); ++t) {
    if (!InRange(desired[t])) {
      throw std::invalid_argument("servo plan: desired angle " + std::to_string(t) + " must be " +
                                  KeyValueProblem(desired[t], kServoAngleDoc) + ", got " +
                                  FormatNumber(desired[t]));
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

// kModelBased: R(t) by inversion, tick by tick; flags the desired angles it cannot reach.
template <class Stepper>
std::vector<double> ModelBasedRequests(const Stepper& stepper, const Problem& p,
                                       std::vector<uint8_t>& beyond_servo) {
  const size_t n = p.desired.size();
  const auto lag = static_cast<size_t>(stepper.Lag());
  typename Stepper::State pending = stepper.Rest(p.desired[0]);
  stepper.Advance(pending);
  typename Stepper::State scratch = pending;
  std::vector<double> requests(n);
  double previous = p.desired[0];
  for (size_t t = 0; t < n; ++t) {
    const double lo = std::max(p.min_deg, previous - p.max_step_deg);
    const double hi = std::min(p.max_deg, previous + p.max_step_deg);
    const size_t acts_at = t + lag + 1;
    const double target = p.desired[std::min(acts_at, n - 1)];
    const Choice choice = InvertAtPending(stepper, pending, scratch, previous, lo, hi, target);
    if (acts_at < n && std::abs(choice.reached_deg - target) > kBeyondServoToleranceDeg) {
      beyond_servo[acts_at] = 1;
    }
    requests[t] = previous = choice.request_deg;
    Stepper::Push(pending, previous);
    stepper.Advance(pending);
  }
  return requests;
}

// kModelBased for the extended model, the paper's method carried over: the model inverted
// along the desired path (DesiredPathTick), R(t) = D(k-1) + u / (gain * kp) for k = t + l + 1.
// A duty beyond +-1 is saturated (the least request that saturates) and flagged. Open loop
// like the paper's: the servo's own P-law pulls the joint back to the path, where a
// tick-by-tick inversion of the predicted state would have to make the velocity jump.
std::vector<double> DesiredPathRequests(const ExtendedStepper& stepper, const Problem& p,
                                        std::vector<uint8_t>& beyond_servo) {
  const size_t n = p.desired.size();
  const auto desired = [&](long k) {
    return p.desired[std::clamp<long>(k, 0, static_cast<long>(n) - 1)];
  };
  std::vector<double> requests(n);
  double previous = p.desired[0];
  for (size_t t = 0; t < n; ++t) {
    const long k = static_cast<long>(t) + stepper.params.lag_ticks + 1;
    const PathStep step = DesiredPathTick(stepper, desired(k - 2), desired(k - 1), desired(k));
    double request =
        std::clamp(step.request_deg, previous - p.max_step_deg, previous + p.max_step_deg);
    request = std::clamp(request, p.min_deg, p.max_deg);
    const bool beyond = std::abs(step.duty) > 1.0 ||
                        std::abs(request - step.request_deg) > kBeyondServoToleranceDeg;
    if (beyond && static_cast<size_t>(k) < n) beyond_servo[static_cast<size_t>(k)] = 1;
    requests[t] = previous = request;
  }
  return requests;
}

// kOptimal from the kModelBased requests, by HorizonDescent from rest at D(0) (its error is
// SquaredError less the first term, M(0) - D(0), which no request changes). A motion of at
// most kOptimalBlockTicks + kOptimalOverlapTicks ticks is one problem, solved in at most
// kOptimalMaxIterations. A longer one is planned block by block, so that its cost per tick does
// not grow with its length: each block's requests are optimised together with the next
// kOptimalOverlapTicks ticks' (the start of the next block's, and its model-based requests
// beyond), in at most kOptimalBlockIterations, from the state the committed requests leave,
// and only the block's are kept. Never worse than the kModelBased requests over the whole
// motion: where the blocks' plan would be, those are returned.
template <class Stepper>
std::vector<double> OptimalRequests(const Stepper& stepper, const Problem& p,
                                    std::vector<double> requests) {
  const size_t n = requests.size();
  typename Stepper::State pending = stepper.Rest(p.desired[0]);
  stepper.Advance(pending);
  const size_t window = std::min(n, kOptimalBlockTicks + kOptimalOverlapTicks);
  // One problem, solved as far as the cap; blocks, each to its share of the effort.
  const int iterations = n > window ? kOptimalBlockIterations : kOptimalMaxIterations;
  servo_plan::HorizonDescent<Stepper> descent;
  descent.Reserve(window, window - 1, pending);
  std::vector<double> model_based = requests;
  double previous = p.desired[0];
  for (size_t start = 0; start < n; start += kOptimalBlockTicks) {
    const size_t size = std::min(window, n - start);
    const std::span<double> block = std::span<double>(requests).subspan(start, size);
    descent.ForgetMemory();
    descent.Descend(stepper, pending, p.desired.subspan(start, size),
                    {p.min_deg, p.max_deg, p.max_step_deg, previous}, block, size,
                    {.max_iterations = iterations});
    if (start + size == n) break;
    for (size_t t = start; t < start + kOptimalBlockTicks; ++t) {
      Stepper::Push(pending, requests[t]);
      stepper.Advance(pending);
    }
    previous = requests[start + kOptimalBlockTicks - 1];
  }
  if (n > window && SquaredError(stepper, p, requests) > SquaredError(stepper, p, model_based)) {
    return model_based;
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

// Never a NaN or an infinity in a plan: the bounds above keep them out; this says so if not.
void CheckFinite(const ServoPlan& plan) {
  for (size_t t = 0; t < plan.request_deg.size(); ++t) {
    if (!std::isfinite(plan.request_deg[t]) || !std::isfinite(plan.predicted_deg[t])) {
      throw std::invalid_argument(
          "servo plan: the plan is not finite at tick " + std::to_string(t) + " (request " +
          FormatNumber(plan.request_deg[t]) + ", predicted " + FormatNumber(plan.predicted_deg[t]) +
          "): the model's numbers are out of its range");
    }
  }
}

}  // namespace

std::string ServoLimitsProblem(const ServoLimits& limits) {
  if (!InRange(limits.min_deg) || !InRange(limits.max_deg) || limits.min_deg >= limits.max_deg) {
    return "the limits need min_deg < max_deg, each " + RangeText(kServoAngleDoc) + ", got " +
           FormatNumber(limits.min_deg) + " and " + FormatNumber(limits.max_deg);
  }
  if (const std::string problem = KeyValueProblem(limits.max_speed_deg_s, kServoVMaxDoc);
      !problem.empty()) {
    return "max_speed_deg_s must be " + problem + ", got " + FormatNumber(limits.max_speed_deg_s);
  }
  return {};
}

std::string ServoPlanProblem(const ServoModelParams& params, const ServoDrive& drive,
                             double tick_s) {
  if (std::string problem = ServoModelParamsProblem(params); !problem.empty()) {
    return "servo model: " + problem;
  }
  if (std::string problem = TickProblem(tick_s); !problem.empty()) return problem;
  if (std::string problem = ServoDriveProblem(drive); !problem.empty()) return problem;
  const double duty_per_deg = params.gain_per_deg_kp * drive.kp;
  if (!std::isfinite(duty_per_deg) || !std::isfinite(1.0 / duty_per_deg)) {
    return "gain_per_deg_kp x kp = " + FormatNumber(duty_per_deg) + " (duty per deg) and its " +
           "inverse must be finite";
  }
  const double load = drive.mass_kg * kGravityMS2 * drive.length_m / params.stall_torque_nm;
  if (!(load <= kMaxLoadToStall)) {
    return "mass_kg x 9.81 x length_m / stall_torque_nm = " + FormatNumber(load) +
           ": the load is over " + FormatNumber(kMaxLoadToStall, NumberStyle::kReadable) +
           " times the stall torque";
  }
  // At most kMaxLagOverTick ticks: the velocity moves at least that fraction of its way a tick.
  const KeyDoc lag_doc{.min = 0, .max = kMaxLagOverTick * tick_s, .min_open = true, .unit = "s"};
  if (const std::string problem = KeyValueProblem(params.velocity_lag_s, lag_doc);
      !problem.empty()) {
    return "velocity_lag_s must be " + problem + " (" +
           FormatNumber(kMaxLagOverTick, NumberStyle::kReadable) + " ticks), got " +
           FormatNumber(params.velocity_lag_s);
  }
  return {};
}

std::string JointModelPlanProblem(const JointModelParams& params, double tick_s) {
  if (std::string problem = JointModelParamsProblem(params); !problem.empty()) {
    return "joint model: " + problem;
  }
  if (std::string problem = TickProblem(tick_s); !problem.empty()) return problem;
  const double slope = params.v_max_deg_per_tick / params.theta0_deg;
  if (const std::string problem = KeyValueProblem(slope, kSpeedSlopeDoc); !problem.empty()) {
    return "v_max_deg_per_tick / theta0_deg must be " + problem + ", got " + FormatNumber(slope) +
           " (theta0_deg " + FormatNumber(params.theta0_deg) + " is too small)";
  }
  const double speed = params.v_max_deg_per_tick / tick_s;
  if (const std::string problem = KeyValueProblem(speed, kServoVMaxDoc); !problem.empty()) {
    return "v_max_deg_per_tick / tick_s must be " + problem + ", got " + FormatNumber(speed);
  }
  return {};
}

ServoPlan PlanServoRequests(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
                            std::span<const double> desired_deg, const ServoLimits& limits,
                            PlanMethod method) {
  const std::string problem = ServoPlanProblem(params, drive, tick_s);
  if (!problem.empty()) throw std::invalid_argument("servo plan: " + problem);
  const Problem p = CheckProblem(desired_deg, limits, tick_s);
  ServoPlan plan = Plan(ExtendedStepper{params, drive, tick_s}, p, method);
  CheckFinite(plan);
  return plan;
}

ServoPlan PlanJointModelRequests(const JointModelParams& params, double tick_s,
                                 std::span<const double> desired_deg, const ServoLimits& limits,
                                 PlanMethod method) {
  const std::string problem = JointModelPlanProblem(params, tick_s);
  if (!problem.empty()) throw std::invalid_argument("servo plan: " + problem);
  const Problem p = CheckProblem(desired_deg, limits, tick_s);
  ServoPlan plan = Plan(PaperStepper{params}, p, method);
  CheckFinite(plan);
  return plan;
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
