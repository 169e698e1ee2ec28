#include "leglab/controller/direct_controller.h"

#include <stdexcept>

namespace leglab {

DirectController::DirectController(const Spec& /*spec*/, const ControllerContext& context)
    : desired_(context.desired) {
  if (desired_.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
}

LegAngles DirectController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(desired_, tick);
}

}  // namespace leglab
