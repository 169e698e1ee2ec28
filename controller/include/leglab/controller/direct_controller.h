#pragma once

#include "leglab/controller/controller.h"

namespace leglab {

/// Requests the desired angles `shift_ticks` ahead: R(t) = D(t + k). With k = 0 this is the
/// paper's direct method (requests = desired angles); k > 0 is its time-shift baseline.
class TimeShiftController final : public JointController {
 public:
  /// Throws std::invalid_argument on an empty cycle.
  TimeShiftController(DesiredCycle desired, int shift_ticks, std::string_view name);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return name_; }

 private:
  DesiredCycle desired_;
  int shift_ticks_;
  std::string name_;
};

}  // namespace leglab
