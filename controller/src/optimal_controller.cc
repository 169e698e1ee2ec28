#include "leglab/controller/optimal_controller.h"

#include <stdexcept>
#include <vector>

#include "leglab/controller/model_based_controller.h"
#include "leglab/core/units.h"
#include "leglab/model/optimal_requests.h"

namespace leglab {

namespace {

DesiredCycle ComputeOptimalRequestCycle(const ControllerContext& context) {
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
    const OptimalRequests best = OptimizeRequests(desired, context.models[j], initial, options);
    for (int t = 0; t < period; ++t) requests[t][j] = best.requests_deg[t];
  }
  return requests;
}

}  // namespace

DesiredCycle OptimalRequestCycle(const ControllerContext& context) {
  if (context.offline_cycles == nullptr) return ComputeOptimalRequestCycle(context);
  return context.offline_cycles->GetOrCompute(
      "optimal", context, [&context] { return ComputeOptimalRequestCycle(context); });
}

OptimalController::OptimalController(const Spec& /*spec*/, const ControllerContext& context) {
  if (context.desired.empty()) {
    throw std::invalid_argument("controller: the desired cycle is empty");
  }
  requests_ = OptimalRequestCycle(context);
}

LegAngles OptimalController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(requests_, tick);
}

}  // namespace leglab
