#pragma once

#include <utility>
#include <vector>

#include "leglab/controller/controller.h"

namespace leglab {

/// The paper's time-shift baseline: requests the desired angles k ticks ahead,
/// R(t) = D(t + k). It compensates a lag and nothing else.
class TimeShiftController final : public JointController {
 public:
  /// `controller.shift_ticks`: k (>= 0), used when the shift is not searched.
  struct Spec {
    int shift_ticks = 0;
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "time_shift";
  static constexpr std::string_view kLabel = "TS";
  static constexpr ControllerModeTraits kTraits{.feed_forward = true,
                                                .search_file = "shift_search",
                                                .has_search_candidates = true,
                                                .has_request_lead = true,
                                                .has_parameters = true};
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);
  /// The shifts an experiment may search (`track.search_shift`): k = 0..T-1, every distinct
  /// shift of a cycle of T ticks.
  static std::vector<Spec> SearchCandidates(const Spec& spec, const ControllerContext& context);
  /// R_k(t) = D(t + k) = R_0(t + k): candidate k leads the unshifted requests by k ticks.
  static int RequestLeadTicks(const Spec& spec) { return spec.shift_ticks; }
  /// The parameters a search chose, for the tables: {"k", shift_ticks}.
  static std::vector<std::pair<std::string_view, long>> Parameters(const Spec& spec) {
    return {{"k", spec.shift_ticks}};
  }

  /// Throws std::invalid_argument on an empty cycle or a negative shift.
  TimeShiftController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

 private:
  DesiredCycle desired_;
  int shift_ticks_;
};

}  // namespace leglab
