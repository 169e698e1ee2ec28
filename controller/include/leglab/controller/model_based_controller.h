#pragma once

#include "leglab/controller/controller.h"
#include "leglab/model/piecewise_linear.h"

namespace leglab {

/// The paper's method (section 4): each joint's desired cycle is approximated by a
/// slope-limited piecewise-linear P (automatic breakpoints), every segment is inverted with
/// C_m and the requests switch l + a/2 ticks early. All of it is computed once, at
/// construction; Update() is a table look-up.
class ModelBasedController final : public JointController {
 public:
  /// Throws std::invalid_argument on an empty cycle or bad segments, std::domain_error from
  /// the closed-form C_m outside eq. 13.
  ModelBasedController(const DesiredCycle& desired,
                       const std::array<JointModelParams, kLegJoints>& models, CmMethod cm,
                       int pwl_segments);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return "model_based"; }

  /// Joint j's piecewise-linear approximation P.
  const PiecewiseLinear& approximation(int joint) const { return approximations_[joint]; }
  /// One cycle of the requests, requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }

 private:
  std::array<PiecewiseLinear, kLegJoints> approximations_;
  DesiredCycle requests_;
};

}  // namespace leglab
