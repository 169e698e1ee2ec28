#pragma once

#include "leglab/controller/controller.h"

namespace leglab {

/// The paper's direct method: requests the desired angles, R(t) = D(t).
class DirectController final : public JointController {
 public:
  /// No options.
  struct Spec {
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "direct";
  static constexpr std::string_view kLabel = "Dir";  ///< in Table 2's keys, e.g. L2(Des,Dir)
  static constexpr ControllerModeTraits kTraits{.feed_forward = true};
  static void VisitKeys(KeyVisitor& /*visitor*/, Spec& /*spec*/) {}

  DirectController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

 private:
  DesiredCycle desired_;
};

}  // namespace leglab
