#pragma once

#include <memory>
#include <span>

#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"
#include "leglab/servo/servo_plan.h"

namespace leglab {

/// The most desired angles ahead a planner is given, and the longest lag (ticks) of a model it
/// plans for: a joint model's own bound (a model's memory is this long).
inline constexpr int kMaxServoPreviewTicks = 100000;
inline constexpr int kMaxServoLagTicks = kMaxModelTicks;

/// How an online planner chooses its requests and uses what is measured.
struct ServoPlannerOptions {
  PlanMethod method = PlanMethod::kModelBased;  ///< as PlanServoRequests's (below)
  /// Desired angles after this tick's that Request is given (and uses) each tick. -1: the
  /// method's own, HorizonTicks() for kModelBased (all it needs: more is ignored) and
  /// l + handover + kOptimalWindowTicks for kOptimal (so that that many requests descend).
  /// kOptimal needs more than the model's lag l (at least HorizonTicks()); at most
  /// kMaxServoPreviewTicks.
  int preview_ticks = -1;
  /// A measured angle further than this (deg) from the model's prediction of it re-anchors the
  /// planner's copy of the model there (angle and, for the extended model, the velocity from
  /// the last two measurements). Closer ones are taken as the model's own error and ignored,
  /// so that the requests do not chase noise. > 0; infinity: never.
  double reanchor_deg = 2.0;
  /// kOptimal: the most projected L-BFGS iterations a tick, both descents together
  /// (HorizonDescent: each one gradient by the adjoint, O(preview + hold_ticks), and a
  /// backtracking line search). 1 to 1000.
  int optimal_iterations_per_tick = kOptimalMaxIterations;
  /// kOptimal: the wall-clock time (s) a Request may spend iterating, from its start: it stops
  /// at the first iteration that would start later, or at the iteration cap, whichever comes
  /// first. Negative (-1): half the model's tick; 0: no time budget, the cap alone (the same
  /// requests on every machine, for tests and tables). -1 to 10. The budget is spent on most
  /// ticks (a tick ends early only once its descents have stalled): several planners sharing
  /// a tick need a share of it each.
  double budget_s = -1.0;
  /// kOptimal: ticks after the preview over which the last desired angle given is taken as
  /// held and the requests are model_based's for it, so that the plan pays for a state it
  /// leaves behind that the servo cannot leave (a load held by friction or a saturated duty).
  /// 0 to kMaxServoPreviewTicks.
  int hold_ticks = 0;
  /// kOptimal: the requests acting on the preview's last handover_ticks ticks are model_based's
  /// and do not descend, so that the preview shows the plan handing the motion back to
  /// model_based and the joint settling after it: a receding horizon that cannot see the
  /// consequences of its last requests spends them greedily, and can do worse than
  /// model_based. A preview of at most l + handover_ticks is model_based, bit for bit. -1:
  /// 2 (l + 1) plus the model's settling (three velocity time constants, ceil(3
  /// velocity_lag_s / tick_s) ticks, for the extended model; its averaging window a for the
  /// paper's). 0 to kMaxServoPreviewTicks.
  int handover_ticks = -1;
};

/// The declared range of ServoPlannerOptions::preview_ticks (-1: the method's own), which
/// plan's --preview-ticks takes from 0.
inline constexpr KeyDoc kServoPreviewDoc{
    .min = -1,
    .max = kMaxServoPreviewTicks,
    .unit = "ticks",
    .description = "desired angles after this tick's given to Request (-1: the method's own)"};

/// The declared range of ServoPlannerOptions::optimal_iterations_per_tick.
inline constexpr KeyDoc kServoIterationsDoc{
    .min = 1, .max = 1000, .description = "optimal: the most L-BFGS iterations a tick"};

/// The declared range of ServoPlannerOptions::budget_s.
inline constexpr KeyDoc kServoBudgetDoc{
    .min = -1,
    .max = 10,
    .unit = "s",
    .description =
        "optimal: wall-clock time a tick may iterate (-1: half the tick; 0: the "
        "iteration cap alone)"};

/// The declared range of ServoPlannerOptions::handover_ticks.
inline constexpr KeyDoc kServoHandoverDoc{
    .min = -1,
    .max = kMaxServoPreviewTicks,
    .unit = "ticks",
    .description =
        "optimal: the preview's last ticks whose requests stay model_based's (-1: two "
        "horizons and the model's settling)"};

/// The declared range of ServoPlannerOptions::hold_ticks.
inline constexpr KeyDoc kServoHoldDoc{
    .min = 0,
    .max = kMaxServoPreviewTicks,
    .unit = "ticks",
    .description = "optimal: ticks after the preview the last desired angle is taken as held"};

/// ServoPlannerOptions' numbers, declared once (see KeyVisitor) with the ranges their comments
/// give: what the planner checks when it is built (its method is checked by its type).
void VisitKeys(KeyVisitor& visitor, ServoPlannerOptions& options);

/// Requests for a servo one tick at a time, from a fitted model: PlanServoRequests online, for
/// a loop that sends each request as it is computed and reads the servo back.
///
/// Tick t: Request(window, measured) is given the desired angles D(t), D(t+1), ... (as many as
/// are known, up to the preview; the last one is held beyond the window, as the batch plan
/// holds D(N-1)) and M(t), the angle just measured, and returns R(t), to send now. R(t) first
/// acts at t + l + 1, so R(t) depends on the desired angles up to D(t + l + 1): HorizonTicks()
/// is l + 1.
///
/// kModelBased is the batch plan, tick by tick: given HorizonTicks() + 1 desired angles and,
/// as measured, what the batch plan predicts, its requests are the batch plan's, bit for bit.
/// The planner keeps a copy of the model driven by its own requests; a measurement more than
/// reanchor_deg off that copy's prediction (the servo held or pushed) moves the copy to it.
/// For the paper's model, whose model-based request is the model inverted from its state
/// each tick, the inversion then starts from the measured angle. The extended model's
/// model-based request follows the desired path open loop, as the batch plan does, whatever
/// is measured: the servo's own P-law brings a held or pushed joint back
/// (docs/design/servo-planner.md says why it is not steered back through the model).
/// PredictedDeg() against the measured angle shows a disturbance either way.
///
/// kOptimal is a receding horizon: each tick it lowers the squared error over the preview (and
/// hold_ticks after it) from the (re-anchored) model state by projected L-BFGS, starting from
/// the better of model_based's plan for the horizon and the last tick's shifted by one, and
/// sends the first request. Once that descent stalls, what is left of the tick goes to a
/// second one from model_based's plan afresh, carried across ticks, which replaces the first
/// when it is lower: a warm start can settle where a fresh one would not. The requests acting on
/// the preview's last handover_ticks ticks and on the held ones stay model_based's, so that the
/// plan hands the motion back to model_based within what it can see rather than spending its end
/// greedily. It starts from model_based and only descends: its plan's error over the horizon is
/// never above model_based's.
///
/// No heap allocation after construction (Reset, Request and Hold). Not thread-safe.
class ServoPlanner {
 public:
  /// For the extended model with `drive` on ticks of `tick_s` (s), requests within `limits`.
  /// Throws std::invalid_argument on a model, drive or tick ServoPlanProblem refuses, a lag
  /// over kMaxServoLagTicks, limits as PlanServoRequests refuses them, or options out of range.
  ServoPlanner(const ServoModelParams& params, const ServoDrive& drive, double tick_s,
               const ServoLimits& limits, const ServoPlannerOptions& options = {});
  /// For the paper's model, whose ticks are `tick_s` seconds (to convert the speed limit).
  ServoPlanner(const JointModelParams& params, double tick_s, const ServoLimits& limits,
               const ServoPlannerOptions& options = {});
  ServoPlanner(ServoPlanner&&) noexcept;
  ServoPlanner& operator=(ServoPlanner&&) noexcept;
  ~ServoPlanner();

  /// l + 1: the desired angles after this tick's that a request depends on.
  int HorizonTicks() const;
  /// The desired angles after this tick's that Request uses (ServoPlannerOptions).
  int PreviewTicks() const;
  /// The servo at rest at `angle_deg`, within the limits (else std::invalid_argument): the
  /// model's state, R(-1) = `angle_deg`, and the next Request is tick 0. A Request before any
  /// Reset resets at its window's first angle.
  void Reset(double angle_deg);
  /// R(t) (deg), within the limits. `window_deg`: D(t), D(t+1), ..., at least one angle, all
  /// finite (those beyond PreviewTicks() + 1 are ignored); `measured_deg`: M(t), finite.
  /// Throws std::invalid_argument otherwise, the planner unchanged.
  double Request(std::span<const double> window_deg, double measured_deg);
  /// A tick that passed with no request sent (a loop that woke too late): the servo held
  /// R(t-1). Advances the model copy by that tick as the servo did, so that the next Request is
  /// tick t + 1 and is never planned as if the loop had been on time. `window_deg` as
  /// Request's; there is no measurement. Throws std::invalid_argument as Request does.
  void Hold(std::span<const double> window_deg);
  /// The model's prediction of the last Request's measured angle, before any re-anchoring.
  double PredictedDeg() const;
  /// The model's prediction of the next Request's measured angle M(t) (after Reset, M(0)):
  /// what a servo that is the model would measure.
  double ExpectedDeg() const;
  /// Whether the last Request's measurement re-anchored the model.
  bool Reanchored() const;
  /// Ticks since the last Reset: Requests and Holds.
  long Ticks() const;

  /// The implementation (servo_planner.cc), not part of the API: public so that the source
  /// file's planners can derive from it.
  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace leglab
