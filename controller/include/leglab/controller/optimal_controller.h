#pragma once

#include <string>

#include "leglab/controller/controller.h"
#include "leglab/model/optimal_requests.h"

namespace leglab {

/// Optimal requests: per joint, the request cycle whose cyclic steady state under the
/// identified model (eqs. 2-3 exactly, no piecewise-linear approximation) is nearest the
/// desired cycle in RMS (OptimizeRequests, started from the paper's model-based requests and
/// never worse than them), within the joint limits. Computed once, at construction; Update()
/// is a table look-up. What remains of its error on a plant is the floor (what no trajectory
/// within the model's speed and acceleration limits can avoid) plus the model's mismatch with
/// the plant, which no offline inversion can remove.
///
/// Objective (`optimal.objective`): `joint` (the loader's default) is the above, each joint on
/// its own. `foot` minimises what the experiment scores, the foot's distance from its path
/// under the model's predicted steady state, plus `optimal.joint_weight` times each joint's own
/// error: ILC's foot objective (FootObjectiveJointProblem, derivation in ilc_controller.h) with
/// no learned mismatch, solved offline to convergence. Starting from the joint objective's
/// optimum (solved as far as a start, kStartToleranceDeg), it sweeps Gauss-Seidel over the
/// joints, each joint's linearised problem solved by OptimizeRequests (to kStartToleranceDeg)
/// with the other joints at their predicted angles; a joint's new cycle is kept only if it
/// lowers the sweeps' acceptance objective, and they stop when one lowers it by less than
/// kFootToleranceMm or after kMaxFootSweeps. That objective is the predicted foot error's mean
/// square plus, with `optimal.request_smoothing` rho > 0, the move suppression rho sum_j m_j
/// mean_t (R_j(t+1) - 2 R_j(t) + R_j(t-1))^2, m_j = FootJointProblem::weight_scale of joint j on
/// the desired cycle (mm^2/deg^2; 0 for a joint that does not move the foot there); each
/// joint's solve carries the same suppression term, in the same units. The joint_weight term
/// only guides the solves (as ILC's does) and is not part of what is accepted. Without rho the
/// foot error never rises above the joint optimum's; with it the requests need not chatter: the
/// model follows a corner of the desired cycle exactly only with requests that swing at its
/// averaging period a ever after (eq. 3's moving average of a terms inverted), which a servo
/// unlike the model turns into error (docs/results/beyond.md, "The slow triangle").
///
/// Model (`optimal.model`): `step_tests` (the loader's default) optimises under the context's
/// models, identified from the step tests (or given); `walk` under models fitted to the walk
/// itself ("identification for control"): the experiments play the paper's model-based
/// requests on the plant and fit each joint's model to those requests and the angles measured
/// (pooled with the step tests' recordings when there are any), and hand this mode a context
/// with those models (see ModelFittedToWalk; the controller never sees the plant).
class OptimalController final : public JointController {
 public:
  /// The `optimal.*` keys.
  struct Spec {
    Objective objective = Objective::kJoint;  ///< optimal.objective
    double joint_weight = 2.0;                ///< optimal.joint_weight: foot objective
    /// optimal.request_smoothing, foot objective: the weight rho of the move suppression on
    /// the requests' second difference (see the class); 0: none.
    double request_smoothing = 0.0;
    ModelSource model = ModelSource::kStepTests;  ///< optimal.model
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "optimal";
  static constexpr std::string_view kLabel = "Opt";
  static constexpr ControllerModeTraits kTraits{
      .feed_forward = true, .config_section = "optimal", .has_walk_models = true};
  /// The foot objective's stopping rules: a sweep that lowers the objective's root (the
  /// model's predicted foot RMS error with the move suppression, mm) by less than this is the
  /// last, and there are at most kMaxFootSweeps.
  static constexpr double kFootToleranceMm = 1e-2;
  static constexpr int kMaxFootSweeps = 20;
  /// How far a solve that only starts another iteration is taken (deg of RMS error a step
  /// must still gain): the joint optimum the foot objective's sweeps start from, each sweep's
  /// per-joint solve (re-linearised at the next sweep), and ILC's start (ILC's own per-step
  /// solves stop at ilc.solver_tolerance_deg, 1e-4 by default, for the same reason). Solving
  /// these to OptimizeRequests' 1e-9 took 3-4 times the iterations and moved the shipped
  /// results by less than their spread over seeds (docs/design/optimal-requests.md).
  static constexpr double kStartToleranceDeg = 1e-4;
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);
  /// Whether the experiments must give this spec a context with models fitted to the walk.
  static bool ModelFittedToWalk(const Spec& spec) { return spec.model == ModelSource::kWalk; }

  /// Throws std::invalid_argument on an empty cycle, a bad spec, or the foot objective without
  /// the context's geometry.
  OptimalController(const Spec& spec, const ControllerContext& context);
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  std::string_view name() const override { return kName; }

  /// One cycle of the requests, requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }

 private:
  DesiredCycle requests_;
};

/// The optimal request cycle of every joint for `context` under the joint objective (what
/// OptimalController requests by default), requests[t][j], solved until a step gains less than
/// `tolerance_deg` of RMS error (OptimizeRequests' tolerance; the default is its default, what
/// the joint objective requests; a cycle that only starts another iteration takes
/// OptimalController::kStartToleranceDeg). Shared with the modes that start from it: computed
/// once per context (its offline_cycles memo) and tolerance for the same desired cycle, models
/// and limits. Throws std::invalid_argument on a negative or NaN tolerance.
DesiredCycle OptimalRequestCycle(const ControllerContext& context,
                                 double tolerance_deg = OptimalRequestsOptions{}.tolerance_deg);

/// The foot objective's request cycle (see OptimalController), from the joint objective's;
/// memoised per context like it. Throws std::invalid_argument without the context's geometry.
DesiredCycle FootOptimalRequestCycle(const ControllerContext& context, double joint_weight,
                                     double request_smoothing = 0.0);

}  // namespace leglab
