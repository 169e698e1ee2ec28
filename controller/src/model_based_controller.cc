#include "leglab/controller/model_based_controller.h"

#include <stdexcept>

#include "leglab/model/request_synthesis.h"

namespace leglab {

ModelBasedController::ModelBasedController(const DesiredCycle& desired,
                                           const std::array<JointModelParams, kLegJoints>& models,
                                           CmMethod cm, int pwl_segments) {
  if (desired.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
  const auto period = static_cast<int>(desired.size());
  requests_.resize(period);
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> joint_desired(period);
    for (int t = 0; t < period; ++t) joint_desired[t] = desired[t][j];
    approximations_[j] =
        FitPiecewiseLinear(joint_desired, models[j].v_max_deg_per_tick, {.segments = pwl_segments});
    const std::vector<double> joint_requests =
        SynthesizeRequests(models[j], approximations_[j], cm);
    for (int t = 0; t < period; ++t) requests_[t][j] = joint_requests[t];
  }
}

LegAngles ModelBasedController::Update(long tick, const LegAngles& /*measured_deg*/) {
  const auto period = static_cast<long>(requests_.size());
  return requests_[(tick % period + period) % period];
}

}  // namespace leglab
