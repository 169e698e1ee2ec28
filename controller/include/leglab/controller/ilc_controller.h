#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "leglab/controller/controller.h"

namespace leglab {

/// Iterative learning control across steps, optimisation-based (Schoellig and D'Andrea 2009,
/// "Optimization-based iterative learning for precise quadrocopter trajectory tracking"): the
/// identified model plus a repeating disturbance d that is learned from the measurements.
/// Per joint, after every step that ran the request cycle R and measured y:
///   d <- d + gain * (Q[y - M_ss(R)] - d)       what the model got wrong about this step
///   R <- argmin_R' RMS(M_ss(R') + d - D)        OptimizeRequests, warm-started at R,
/// where M_ss is the model's cyclic steady state (eqs. 2-3) and the new R stays within the
/// limits. It starts from the best offline requests it has (`ilc.start`: optimal, the joint
/// optimum solved as far as a start, OptimalController::kStartToleranceDeg; or model_based)
/// with d = 0.
///  - Learning filter: the model's own inverse, by optimisation rather than by a linearised
///    gain. It carries the lead (a request at s first moves the joint at s + l + 1, so the
///    correction for an error at t lands l + 1 ticks earlier, the classic P-type lead of
///    Arimoto 1984) and the saturation: where the joint already runs at top speed the solver
///    does not push harder, as a linear learning law would (see docs/design/ilc.md).
///  - Gain (`ilc.gain`, in (0, 1]): how much of the newly seen mismatch enters d per step.
///    With an exact model d stays 0 and R stays optimal; below 1 it averages the 0.1 deg sensor
///    noise over about 1/gain steps and damps the learning when the model misjudges the plant.
///  - Robustness filter (`ilc.filter_ticks`, odd, 1 = off): a zero-phase cyclic moving average
///    of the mismatch before it enters d, the standard Q-filter that keeps noise and unmodelled
///    high-frequency dynamics from being learned (Bristow, Tharayil and Alleyne 2006, sec. 4).
///  - Effort (`ilc.solver_iterations`, `ilc.solver_tolerance_deg`): each update's solve stops
///    after that many sensitivity evaluations, or once a step lowers the model's RMS error by
///    less than the tolerance. Solving each step's problem to the last digit buys nothing: the
///    next step's measurement moves the target by the sensor noise anyway; the default 1e-4 deg
///    learns as well as a tight tolerance and reaches the offline optimum on an exact model
///    (see docs/design/ilc.md).
///  - Objective (`ilc.objective`): `joint` minimises each joint's RMS error on its own, as
///    above. `foot` minimises what the experiment scores, the foot's distance from its desired
///    path, sum_t |FK(M_ss(t) + d(t)) - FK(D(t))|^2, plus lambda times each joint's own squared
///    error, lambda = `ilc.joint_weight` times the joint's mean |K_j|^2 below (which keeps a joint
///    that hardly moves the foot, near a singularity, from drifting). The joints are coupled
///    through the kinematics, so each update is one Gauss-Seidel sweep over the joints of
///    Gauss-Newton on that sum: with the other joints at their predicted angles, the foot error is
///    linearised in joint j at the predicted angles, r(t) + K_j(t) (theta_j(t) - theta^_j(t)), K_j
///    = column j of FootJacobian (mm/deg), which makes joint j's problem the weighted one
///    OptimizeRequests solves: per tick the weight w_t = |K_j|^2 + lambda and the target (|K_j|^2
///    theta^_j - K_j.r + lambda D_j) / w_t (lambda = joint_weight times the mean |K_j|^2 over the
///    cycle; the weights scaled to mean 1, so the solver's tolerance stays in degrees). The steps
///    re-linearise: a step's measurement is the next sweep's starting point. Trading a joint's
///    error for the foot's is the point: at fast walks the joints cannot all reach their floors,
///    and where the foot is insensitive to a joint the error is cheaper there.
/// It learns during the warm-up steps and keeps learning while measured unless
/// `ilc.freeze_after_warmup`. Requests are always finite and within the limits; a non-finite
/// measurement of a joint keeps that joint's learned mismatch (with the joint objective, its
/// cycle too), and a failed solve leaves the joint's cycle as it was.
class IlcController final : public JointController {
 public:
  /// The offline requests learning starts from (`ilc.start`).
  enum class Start { kOptimal, kModelBased };
  static constexpr std::array<std::string_view, 2> kStartNames = {"optimal", "model_based"};
  /// The `ilc.*` keys.
  struct Spec {
    double gain = 0.5;                        ///< ilc.gain
    Start start = Start::kOptimal;            ///< ilc.start
    bool freeze_after_warmup = false;         ///< ilc.freeze_after_warmup
    int filter_ticks = 7;                     ///< ilc.filter_ticks: odd (1: no Q-filter)
    int solver_iterations = 30;               ///< ilc.solver_iterations
    double solver_tolerance_deg = 1e-4;       ///< ilc.solver_tolerance_deg
    Objective objective = Objective::kJoint;  ///< ilc.objective
    double joint_weight = 2.0;                ///< ilc.joint_weight: foot objective
    /// ilc.request_smoothing: each per-step solve's move suppression on the requests' second
    /// difference (OptimizeRequests' request_smoothing); 0: none.
    double request_smoothing = 0.0;
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "ilc";
  static constexpr std::string_view kLabel = "ILC";
  static constexpr ControllerModeTraits kTraits{.config_section = "ilc"};
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);

  /// Throws std::invalid_argument on an empty cycle, a bad spec, or the foot objective without
  /// the context's geometry.
  IlcController(const Spec& spec, const ControllerContext& context);

  void Reset() override;
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  void Observe(long tick, const LegAngles& applied_deg, const LegAngles& measured_deg) override;
  void EndOfStep(long step) override;
  std::string_view name() const override { return kName; }

  /// The request cycle the next step will use, requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }

 private:
  Spec spec_;
  ControllerContext context_;
  DesiredCycle start_;        // the offline requests learning starts from
  DesiredCycle requests_;     // the current cycle
  DesiredCycle measured_;     // this step's measured angles, by tick of the cycle
  std::vector<bool> seen_;    // which ticks of this step were observed
  DesiredCycle disturbance_;  // d: the learned model-plant mismatch, by tick
  DesiredCycle predicted_;    // M_ss(R) of the current cycle, by tick
  std::vector<Eigen::Vector3d> desired_foot_mm_;  // FK(D), by tick (foot objective)

  // One joint's new request cycle for `target` (deg, by tick) under `weights` (empty: all 1),
  // warm-started at the current one; false when the solve failed (the cycle is kept).
  bool Solve(int joint, const std::vector<double>& target, std::vector<double> weights,
             std::vector<double>& requests, std::vector<double>& steady_state) const;
};

}  // namespace leglab
