#include "leglab/controller/time_shift_controller.h"

#include <stdexcept>
#include <string>

namespace leglab {

TimeShiftController::Spec TimeShiftController::ReadSpec(OptionReader& reader) {
  Spec spec;
  reader.Read("shift_ticks", spec.shift_ticks);
  if (spec.shift_ticks < 0) reader.Fail("shift_ticks", "non-negative");
  return spec;
}

std::vector<TimeShiftController::Spec> TimeShiftController::SearchCandidates(
    const Spec& /*spec*/, const ControllerContext& context) {
  std::vector<Spec> candidates(context.desired.size());
  for (size_t k = 0; k < candidates.size(); ++k) candidates[k].shift_ticks = static_cast<int>(k);
  return candidates;
}

TimeShiftController::TimeShiftController(const Spec& spec, const ControllerContext& context)
    : desired_(context.desired), shift_ticks_(spec.shift_ticks) {
  if (desired_.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
  if (shift_ticks_ < 0) {
    throw std::invalid_argument("time_shift: shift_ticks must be non-negative, got " +
                                std::to_string(shift_ticks_));
  }
}

LegAngles TimeShiftController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(desired_, tick + shift_ticks_);
}

}  // namespace leglab
