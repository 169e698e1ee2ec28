#pragma once

// A controller mode that leglab does not ship, added exactly as docs/extending.md says: this
// file pair, one registry line (extra_modes.h stands in for registry.h's list) and its CMake
// line. The extending test builds the libraries with it and runs it through the loader and
// track's pipeline.
#include <array>
#include <string_view>

#include "leglab/controller/controller.h"

namespace leglab {

/// Requests part of the way towards the desired angle `lead_ticks` ahead:
/// R(t) = D(t) + gain (D(t + lead) - D(t)). gain 0 is the direct method, gain 1 the time shift
/// by `lead_ticks`.
class BlendController final : public JointController {
 public:
  /// The `blend.*` keys.
  struct Spec {
    double gain = 0.5;   ///< blend.gain
    int lead_ticks = 4;  ///< blend.lead_ticks
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "blend";
  static constexpr std::string_view kLabel = "Bl";
  static constexpr ControllerModeTraits kTraits{.feed_forward = true, .config_section = "blend"};
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);

  /// Throws std::invalid_argument on an empty cycle or a spec out of its ranges.
  BlendController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

 private:
  Spec spec_;
  DesiredCycle desired_;
};

}  // namespace leglab
