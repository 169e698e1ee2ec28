#include "leglab/controller/model_based_controller.h"

#include <stdexcept>

#include "leglab/model/request_synthesis.h"

namespace leglab {

void ModelBasedController::VisitKeys(KeyVisitor& v, Spec& spec) {
  v.Key("cm", spec.cm, kCmNames,
        {.description = "model_based's C_m: exact (the discrete root of eq. 6) or closed (the "
                        "paper's eqs. 10-12)"});
  VisitModelSourceKey(v, spec.model);
}

DesiredCycle ModelBasedRequestCycle(const ControllerContext& context, CmMethod cm) {
  if (context.desired.empty()) {
    throw std::invalid_argument("controller: the desired cycle is empty");
  }
  const auto period = static_cast<int>(context.desired.size());
  DesiredCycle requests(period);
  for (int j = 0; j < kLegJoints; ++j) {
    const std::vector<double> joint_requests =
        SynthesizeRequests(context.models[j], context.Approximation(j), cm);
    for (int t = 0; t < period; ++t) requests[t][j] = joint_requests[t];
  }
  // R = P + C_m may ask beyond a limit near the ends of the range: ask for what the servo
  // would take anyway.
  for (LegAngles& r : requests) r = ClampToLimits(r, context.limits);
  return requests;
}

ModelBasedController::ModelBasedController(const Spec& spec, const ControllerContext& context)
    : requests_(ModelBasedRequestCycle(context, spec.cm)) {}

LegAngles ModelBasedController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(requests_, tick);
}

}  // namespace leglab
