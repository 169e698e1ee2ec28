#include "leglab/controller/controller.h"

#include <stdexcept>

#include "leglab/controller/direct_controller.h"
#include "leglab/controller/model_based_controller.h"

namespace leglab {

const std::vector<std::string>& ControllerModes() {
  static const std::vector<std::string> modes = {"direct", "time_shift", "model_based"};
  return modes;
}

std::unique_ptr<JointController> MakeController(
    const ControllerSpec& spec, const DesiredCycle& desired,
    const std::array<JointModelParams, kLegJoints>& models) {
  if (spec.mode == "direct") return std::make_unique<TimeShiftController>(desired, 0, "direct");
  if (spec.mode == "time_shift") {
    return std::make_unique<TimeShiftController>(desired, spec.shift_ticks, "time_shift");
  }
  if (spec.mode == "model_based") {
    return std::make_unique<ModelBasedController>(desired, models, spec.cm, spec.pwl_segments);
  }
  std::string valid;
  for (const std::string& m : ControllerModes()) valid += (valid.empty() ? "" : ", ") + m;
  throw std::invalid_argument("unknown controller mode '" + spec.mode + "' (valid: " + valid + ")");
}

}  // namespace leglab
