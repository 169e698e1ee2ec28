#include "leglab/controller/time_shift_controller.h"

#include <stdexcept>
#include <string>

namespace leglab {

void TimeShiftController::VisitKeys(KeyVisitor& v, Spec& spec) {
  v.Key("shift_ticks", spec.shift_ticks,
        {.min = 0,
         .max = 999,
         .unit = "ticks",
         .description = "time_shift's k when it is not searched (track.search_shift: false), "
                        "taken modulo the step"});
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
  CheckKeys(std::string(kTraits.config_section) + ".", spec, &VisitKeys);
}

LegAngles TimeShiftController::Update(long tick, const LegAngles& /*measured_deg*/) {
  return CycleAt(desired_, tick + shift_ticks_);
}

}  // namespace leglab
