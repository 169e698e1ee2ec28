#include "leglab/controller/direct_controller.h"

#include <stdexcept>

namespace leglab {

TimeShiftController::TimeShiftController(DesiredCycle desired, int shift_ticks,
                                         std::string_view name)
    : desired_(std::move(desired)), shift_ticks_(shift_ticks), name_(name) {
  if (desired_.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
}

LegAngles TimeShiftController::Update(long tick, const LegAngles& /*measured_deg*/) {
  const auto period = static_cast<long>(desired_.size());
  return desired_[((tick + shift_ticks_) % period + period) % period];
}

}  // namespace leglab
