#include "blend_controller.h"

#include <stdexcept>
#include <string>

namespace leglab {

void BlendController::VisitKeys(KeyVisitor& v, Spec& spec) {
  v.Key("gain", spec.gain,
        {.min = 0,
         .max = 1,
         .description = "how far towards the desired angle lead_ticks ahead it requests"});
  v.Key("lead_ticks", spec.lead_ticks,
        {.min = 0, .max = 999, .unit = "ticks", .description = "how far ahead it looks"});
}

BlendController::BlendController(const Spec& spec, const ControllerContext& context)
    : spec_(spec), desired_(context.desired) {
  if (desired_.empty()) throw std::invalid_argument("controller: the desired cycle is empty");
  CheckKeys(std::string(kTraits.config_section) + ".", spec_, &VisitKeys);
}

LegAngles BlendController::Update(long tick, const LegAngles& /*measured_deg*/) {
  const LegAngles& now = CycleAt(desired_, tick);
  const LegAngles& ahead = CycleAt(desired_, tick + spec_.lead_ticks);
  LegAngles request{};
  for (int j = 0; j < kLegJoints; ++j) request[j] = now[j] + spec_.gain * (ahead[j] - now[j]);
  return request;
}

}  // namespace leglab
