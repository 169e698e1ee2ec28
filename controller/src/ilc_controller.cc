#include "leglab/controller/ilc_controller.h"

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <optional>
#include <stdexcept>
#include <vector>

#include "leglab/controller/foot_objective.h"
#include "leglab/controller/model_based_controller.h"
#include "leglab/controller/optimal_controller.h"
#include "leglab/core/units.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/optimal_requests.h"

namespace leglab {
namespace {

// Zero-phase cyclic moving average over `window` (odd) ticks.
Eigen::VectorXd CyclicMovingAverage(const Eigen::VectorXd& x, int window) {
  if (window <= 1) return x;
  const auto n = static_cast<int>(x.size());
  const int half = window / 2;
  Eigen::VectorXd out(n);
  for (int t = 0; t < n; ++t) {
    double sum = 0.0;
    for (int k = -half; k <= half; ++k) sum += x[((t + k) % n + n) % n];
    out[t] = sum / window;
  }
  return out;
}

}  // namespace

void IlcController::VisitKeys(KeyVisitor& v, Spec& spec) {
  v.Key("gain", spec.gain,
        {.min = 0,
         .max = 1,
         .min_open = true,
         .description = "share of each step's newly seen model-plant mismatch learned"});
  v.Key("start", spec.start, kStartNames, {.description = "the offline requests it learns from"});
  v.Key("freeze_after_warmup", spec.freeze_after_warmup,
        {.description = "true: learn during the warm-up steps only"});
  v.Key("filter_ticks", spec.filter_ticks,
        {.min = 1,
         .max = 999,
         .unit = "ticks",
         .description = "width of the zero-phase moving average (Q-filter) of the mismatch "
                        "learned; odd, 1: off"});
  if (spec.filter_ticks % 2 == 0) v.Fail("filter_ticks", "an odd number >= 1");
  v.Key("solver_iterations", spec.solver_iterations,
        {.min = 1,
         .max = 1000,
         .description = "effort of each update: the solver's linearisations at most"});
  v.Key("solver_tolerance_deg", spec.solver_tolerance_deg,
        {.min = 0,
         .max = 1,
         .unit = "deg",
         .description = "each update's solve stops once a step gains less than this (RMS)"});
  VisitObjectiveKeys(v, spec.objective, spec.joint_weight, spec.request_smoothing);
}

IlcController::IlcController(const Spec& spec, const ControllerContext& context)
    : spec_(spec), context_(context) {
  if (context_.desired.empty()) {
    throw std::invalid_argument("controller: the desired cycle is empty");
  }
  CheckKeys(std::string(kTraits.config_section) + ".", spec_, &VisitKeys);
  RequireSettlingModels(context_, kName);
  if (spec_.objective == Objective::kFoot) {
    if (!context_.geometry) {
      throw std::invalid_argument("ilc: the foot objective needs the leg's geometry");
    }
    desired_foot_mm_ = FootPathMm(*context_.geometry, context_.desired);
  }
  // The joint optimum as a start: learning moves on from it at its first update.
  start_ = spec_.start == Start::kModelBased
               ? ModelBasedRequestCycle(context_, CmMethod::kExact)
               : OptimalRequestCycle(context_, OptimalController::kStartToleranceDeg);
  Reset();
}

void IlcController::Reset() {
  const size_t period = start_.size();
  requests_ = start_;
  measured_.assign(period, LegAngles{});
  seen_.assign(period, false);
  disturbance_.assign(period, LegAngles{});
  predicted_.assign(period, LegAngles{});
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> cycle(period);
    for (size_t t = 0; t < period; ++t) cycle[t] = requests_[t][j];
    const std::vector<double> steady = CyclicSteadyState(context_.models[j], cycle);
    for (size_t t = 0; t < period; ++t) predicted_[t][j] = steady[t];
  }
}

LegAngles IlcController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(requests_, tick);
}

void IlcController::Observe(long tick, const LegAngles& /*applied_deg*/,
                            const LegAngles& measured_deg) {
  const auto period = static_cast<long>(measured_.size());
  const auto t = static_cast<size_t>((tick % period + period) % period);
  measured_[t] = measured_deg;
  seen_[t] = true;
}

bool IlcController::Solve(int joint, const std::vector<double>& target, std::vector<double> weights,
                          std::vector<double>& requests, std::vector<double>& steady_state) const {
  OptimalRequestsOptions options;
  options.lower_deg = RadToDeg(context_.limits[joint].lower_rad);
  options.upper_deg = RadToDeg(context_.limits[joint].upper_rad);
  options.max_iterations = spec_.solver_iterations;
  options.tolerance_deg = spec_.solver_tolerance_deg;
  options.smoothing_theta0 = 0.0;  // warm-started next to the optimum: exact f at once
  options.weights = std::move(weights);
  options.structured_solve = true;  // no T x T factorisation per step (the same step)
  options.request_smoothing = spec_.request_smoothing;  // banded too (BandedStepSolver)
  try {
    OptimalRequests next = OptimizeRequests(target, context_.models[joint], requests, options);
    requests = std::move(next.requests_deg);
    steady_state = std::move(next.steady_state_deg);
  } catch (const std::exception&) {
    return false;  // the 8 ms loop does not throw: keep the cycle it had
  }
  return true;
}

void IlcController::EndOfStep(long step) {
  const bool complete = std::all_of(seen_.begin(), seen_.end(), [](bool s) { return s; });
  std::fill(seen_.begin(), seen_.end(), false);
  if (!complete) return;  // a step it did not watch whole teaches nothing
  if (spec_.freeze_after_warmup && step >= context_.warmup_steps) return;
  const auto period = static_cast<int>(requests_.size());
  // The learned mismatch, per joint; a joint whose measurement was not finite keeps its own.
  DesiredCycle disturbance = disturbance_;
  std::array<bool, kLegJoints> measured_finite{};
  for (int j = 0; j < kLegJoints; ++j) {
    Eigen::VectorXd mismatch(period);
    for (int t = 0; t < period; ++t) mismatch[t] = measured_[t][j] - predicted_[t][j];
    measured_finite[j] = mismatch.allFinite();
    if (!measured_finite[j]) continue;
    mismatch = CyclicMovingAverage(mismatch, spec_.filter_ticks);
    for (int t = 0; t < period; ++t) {
      disturbance[t][j] = disturbance_[t][j] + spec_.gain * (mismatch[t] - disturbance_[t][j]);
    }
  }
  const bool foot = spec_.objective == Objective::kFoot;
  for (int j = 0; j < kLegJoints; ++j) {
    // The joint objective has nothing new to solve for a joint it learned nothing about; the
    // foot objective does when the other joints moved.
    if (!foot && !measured_finite[j]) continue;
    std::vector<double> target(period), requests(period), steady_state(period), weights;
    for (int t = 0; t < period; ++t) {
      target[t] = context_.desired[t][j] - disturbance[t][j];
      requests[t] = requests_[t][j];
    }
    if (foot) {
      // Joint j's share of the foot's error, linearised at the angles the model and the
      // learned mismatch predict (the other joints' as updated so far this sweep).
      DesiredCycle angles(period);
      for (int t = 0; t < period; ++t) {
        for (int k = 0; k < kLegJoints; ++k) angles[t][k] = predicted_[t][k] + disturbance[t][k];
      }
      std::optional<FootJointProblem> problem = FootObjectiveJointProblem(
          *context_.geometry, desired_foot_mm_, context_.desired, angles, j, spec_.joint_weight);
      if (!problem) continue;
      for (int t = 0; t < period; ++t) target[t] = problem->target_deg[t] - disturbance[t][j];
      weights = std::move(problem->weights);
    }
    if (!Solve(j, target, std::move(weights), requests, steady_state)) continue;
    for (int t = 0; t < period; ++t) {
      disturbance_[t][j] = disturbance[t][j];
      requests_[t][j] = requests[t];
      predicted_[t][j] = steady_state[t];
    }
  }
}

}  // namespace leglab
