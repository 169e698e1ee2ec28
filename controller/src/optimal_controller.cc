#include "leglab/controller/optimal_controller.h"

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "leglab/controller/foot_objective.h"
#include "leglab/controller/model_based_controller.h"
#include "leglab/core/units.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/optimal_requests.h"

namespace leglab {

namespace {

DesiredCycle ComputeOptimalRequestCycle(const ControllerContext& context, double tolerance_deg) {
  const auto period = static_cast<int>(context.desired.size());
  const DesiredCycle start = ModelBasedRequestCycle(context, CmMethod::kExact);
  DesiredCycle requests(period);
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> desired(period), initial(period);
    for (int t = 0; t < period; ++t) {
      desired[t] = context.desired[t][j];
      initial[t] = start[t][j];
    }
    OptimalRequestsOptions options;
    options.lower_deg = RadToDeg(context.limits[j].lower_rad);
    options.upper_deg = RadToDeg(context.limits[j].upper_rad);
    options.structured_solve = true;  // the same steps up to rounding, no T x T factorisations
    options.tolerance_deg = tolerance_deg;
    const OptimalRequests best = OptimizeRequests(desired, context.models[j], initial, options);
    for (int t = 0; t < period; ++t) requests[t][j] = best.requests_deg[t];
  }
  return requests;
}

// Joint j's column of a cycle.
std::vector<double> Column(const DesiredCycle& cycle, int j) {
  std::vector<double> column(cycle.size());
  for (size_t t = 0; t < cycle.size(); ++t) column[t] = cycle[t][j];
  return column;
}

// The foot objective the sweeps lower, as a root mean square, mm: sqrt(mean_t |FK(M(t)) -
// p(t)|^2 + sum_j suppression_j mean_t (L R_j)(t)^2), M the predicted steady state, p the
// desired foot path, L the cyclic second difference; suppression_j in mm^2/deg^2.
double FootObjectiveMm(const LegGeometry& geometry, const DesiredCycle& predicted,
                       std::span<const Eigen::Vector3d> desired_foot, const DesiredCycle& requests,
                       const std::array<double, kLegJoints>& suppression) {
  const double foot_mm = FootRmsErrorMm(geometry, predicted, desired_foot);
  double sum = foot_mm * foot_mm;
  for (int j = 0; j < kLegJoints; ++j) {
    if (suppression[j] > 0.0) {
      sum += suppression[j] * SumOfSquaredSecondDifferences(Column(requests, j)) /
             static_cast<double>(requests.size());
    }
  }
  return std::sqrt(sum);
}

DesiredCycle ComputeFootOptimalRequestCycle(const ControllerContext& context,
                                            const DesiredCycle& joint_optimal, double joint_weight,
                                            double request_smoothing) {
  const auto period = static_cast<int>(context.desired.size());
  const LegGeometry& geometry = *context.geometry;
  const std::vector<Eigen::Vector3d> desired_foot = FootPathMm(geometry, context.desired);
  DesiredCycle requests = joint_optimal;
  DesiredCycle predicted(period);
  for (int j = 0; j < kLegJoints; ++j) {
    const std::vector<double> steady = CyclicSteadyState(context.models[j], Column(requests, j));
    for (int t = 0; t < period; ++t) predicted[t][j] = steady[t];
  }
  // The move suppression in the objective's units: request_smoothing times joint j's mean
  // weight on the desired cycle (FootJointProblem::weight_scale there), fixed for the whole
  // descent so that every acceptance below compares one function.
  std::array<double, kLegJoints> suppression{};
  for (int j = 0; j < kLegJoints; ++j) {
    const std::optional<FootJointProblem> at_desired = FootObjectiveJointProblem(
        geometry, desired_foot, context.desired, context.desired, j, joint_weight);
    if (at_desired) suppression[j] = request_smoothing * at_desired->weight_scale;
  }
  double error_mm = FootObjectiveMm(geometry, predicted, desired_foot, requests, suppression);
  for (int sweep = 0; sweep < OptimalController::kMaxFootSweeps; ++sweep) {
    const double before_mm = error_mm;
    for (int j = 0; j < kLegJoints; ++j) {
      std::optional<FootJointProblem> problem = FootObjectiveJointProblem(
          geometry, desired_foot, context.desired, predicted, j, joint_weight);
      if (!problem) continue;
      OptimalRequestsOptions options;
      options.lower_deg = RadToDeg(context.limits[j].lower_rad);
      options.upper_deg = RadToDeg(context.limits[j].upper_rad);
      options.weights = std::move(problem->weights);
      options.structured_solve = true;
      // The problem's weights are scaled to mean 1: the same suppression in its units.
      options.request_smoothing = suppression[j] / problem->weight_scale;
      // Re-linearised at the next sweep: solved as far as a start (kStartToleranceDeg).
      options.tolerance_deg = OptimalController::kStartToleranceDeg;
      const OptimalRequests next =
          OptimizeRequests(problem->target_deg, context.models[j], Column(requests, j), options);
      DesiredCycle candidate = predicted;
      DesiredCycle candidate_requests = requests;
      for (int t = 0; t < period; ++t) {
        candidate[t][j] = next.steady_state_deg[t];
        candidate_requests[t][j] = next.requests_deg[t];
      }
      const double candidate_mm =
          FootObjectiveMm(geometry, candidate, desired_foot, candidate_requests, suppression);
      if (!(candidate_mm < error_mm)) continue;  // the linearisation misled: keep the cycle
      error_mm = candidate_mm;
      predicted = std::move(candidate);
      requests = std::move(candidate_requests);
    }
    if (before_mm - error_mm < OptimalController::kFootToleranceMm) break;
  }
  return requests;
}

}  // namespace

DesiredCycle OptimalRequestCycle(const ControllerContext& context, double tolerance_deg) {
  if (const std::string problem = KeyValueProblem(tolerance_deg, kOptimalToleranceDoc);
      !problem.empty()) {
    throw std::invalid_argument("optimal: the joint optimum's tolerance must be " + problem +
                                ", got " + FormatNumber(tolerance_deg, NumberStyle::kReadable));
  }
  auto compute = [&context, tolerance_deg] {
    return ComputeOptimalRequestCycle(context, tolerance_deg);
  };
  if (context.offline_cycles == nullptr) return compute();
  // One entry per tolerance, never another's (a run's bits must not depend on which modes ran
  // before); the tolerance's exact value in the name.
  char name[64];
  std::snprintf(name, sizeof name, "optimal tolerance %.17g", tolerance_deg);
  return context.offline_cycles->GetOrCompute(name, context, compute);
}

DesiredCycle FootOptimalRequestCycle(const ControllerContext& context, double joint_weight,
                                     double request_smoothing) {
  if (!context.geometry) {
    throw std::invalid_argument("optimal: the foot objective needs the leg's geometry");
  }
  // The joint optimum first (the memo's lock is not re-entrant), as a start: the sweeps move
  // on from it at once.
  const DesiredCycle joint_optimal =
      OptimalRequestCycle(context, OptimalController::kStartToleranceDeg);
  auto compute = [&] {
    return ComputeFootOptimalRequestCycle(context, joint_optimal, joint_weight, request_smoothing);
  };
  if (context.offline_cycles == nullptr) return compute();
  // The weight's exact value (to_string's six decimals would give 1e-7 and 0 one entry).
  char name[96];
  if (request_smoothing > 0.0) {
    std::snprintf(name, sizeof name, "optimal-foot %.17g smoothing %.17g", joint_weight,
                  request_smoothing);
  } else {
    std::snprintf(name, sizeof name, "optimal-foot %.17g", joint_weight);
  }
  return context.offline_cycles->GetOrCompute(name, context, compute);
}

void OptimalController::VisitKeys(KeyVisitor& v, Spec& spec) {
  VisitObjectiveKeys(v, spec.objective, spec.joint_weight, spec.request_smoothing);
  VisitModelSourceKey(v, spec.model);
}

OptimalController::OptimalController(const Spec& spec, const ControllerContext& context) {
  if (context.desired.empty()) {
    throw std::invalid_argument("controller: the desired cycle is empty");
  }
  CheckKeys(std::string(kTraits.config_section) + ".", spec, &VisitKeys);
  RequireSettlingModels(context, kName);
  requests_ = spec.objective == Objective::kFoot
                  ? FootOptimalRequestCycle(context, spec.joint_weight, spec.request_smoothing)
                  : OptimalRequestCycle(context);
}

LegAngles OptimalController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(requests_, tick);
}

}  // namespace leglab
