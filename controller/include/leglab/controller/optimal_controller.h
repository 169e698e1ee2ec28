#pragma once

#include "leglab/controller/controller.h"

namespace leglab {

/// Optimal requests: per joint, the request cycle whose cyclic steady state under the
/// identified model (eqs. 2-3 exactly, no piecewise-linear approximation) is nearest the
/// desired cycle in RMS (OptimizeRequests, started from the paper's model-based requests and
/// never worse than them), within the joint limits. Computed once, at construction; Update()
/// is a table look-up. What remains of its error on a plant is the floor (what no trajectory
/// within the model's speed and acceleration limits can avoid) plus the model's mismatch with
/// the plant, which no offline inversion can remove.
class OptimalController final : public JointController {
 public:
  /// No options.
  struct Spec {
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "optimal";
  static constexpr std::string_view kLabel = "Opt";
  static constexpr bool kFeedForward = true;
  static Spec ReadSpec(OptionReader& /*reader*/) { return {}; }

  /// Throws std::invalid_argument on an empty cycle.
  OptimalController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

  /// One cycle of the requests, requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }

 private:
  DesiredCycle requests_;
};

/// The optimal request cycle of every joint for `context` (what OptimalController requests),
/// requests[t][j]. Shared with the learning modes that start from it: computed once per
/// context (its offline_cycles memo) for the same desired cycle, models and limits.
DesiredCycle OptimalRequestCycle(const ControllerContext& context);

}  // namespace leglab
