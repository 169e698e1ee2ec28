#pragma once

#include <string>

#include "leglab/controller/controller.h"
#include "leglab/model/line_inverse.h"

namespace leglab {

/// The paper's method (section 4): each joint's desired cycle is approximated by a
/// slope-limited piecewise-linear P (the context's approximations), every segment is inverted
/// with C_m and the requests switch l + a/2 ticks early. All of it is computed once, at
/// construction; Update() is a table look-up.
class ModelBasedController final : public JointController {
 public:
  /// `controller.cm`: the paper's closed-form C_m or the exact discrete root (default).
  /// `controller.model`: `step_tests` (default), the context's models; or `walk`, models fitted
  /// to the walk, as optimal.model (OptimalController), so that the two compare on one model.
  struct Spec {
    CmMethod cm = CmMethod::kExact;
    ModelSource model = ModelSource::kStepTests;
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "model_based";
  static constexpr std::string_view kLabel = "MB";
  /// It follows the approximation P, so Table 2 also compares it with P (L2(Pwl,MB)).
  static constexpr ControllerModeTraits kTraits{
      .feed_forward = true, .follows_approximation = true, .has_walk_models = true};
  /// The names of CmMethod's values in the config.
  static constexpr std::array<std::string_view, 2> kCmNames = {"closed", "exact"};
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);
  /// Whether the experiments must give this spec a context with models fitted to the walk.
  static bool ModelFittedToWalk(const Spec& spec) { return spec.model == ModelSource::kWalk; }

  /// Throws std::invalid_argument on an empty cycle or a slope over v_max, std::domain_error
  /// from the closed-form C_m outside eq. 13.
  ModelBasedController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

  /// One cycle of the requests, requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }

 private:
  DesiredCycle requests_;
};

/// The paper's request cycle for `context` with C_m by `cm`, requests[t][j], clamped into the
/// limits (what ModelBasedController requests). Throws as ModelBasedController.
DesiredCycle ModelBasedRequestCycle(const ControllerContext& context, CmMethod cm);

}  // namespace leglab
