#pragma once

#include <optional>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/model/window_estimation.h"

namespace leglab {

/// The paper's model-based requests from a model learned while walking (its future work: "learn
/// the model of its joints automatically from experience based on its knowledge of the joint
/// requests and actual angles over time"). Per joint it keeps the applied requests and
/// measured angles of the latest `adaptive.window_steps` steps and, after every step,
/// re-estimates {v_max, theta_0, l, a} from them (EstimateJointModelInWindow: the
/// identification's open-loop fit, l and a searched within +-2 of the current estimate). It
/// sees nothing else of the plant: not the step tests, not the identified model of the
/// context, not the plant's settings; it starts from `adaptive.initial_model`.
///
/// Re-planning: when an estimate moves by more than the estimator resolves on a steady plant
/// (l or a changes, v_max by more than kVmaxResolution or theta_0 by more than
/// kTheta0Resolution from the model the requests were planned with), that joint's
/// approximation P is refitted under the new v_max and its request cycle re-synthesised (R =
/// P + C_m, exact C_m) for the next step.
///
/// Identifiability: v_max shows only where the joint saturates. A joint whose window never
/// saturates keeps its v_max and learns the slope v_max / theta_0 (all the data determine).
/// With `adaptive.probe_deg` > 0 such a joint is probed in the next step, until a window has
/// saturated it since its l or a last changed: a pulse of probe_deg, l + a ticks long, is
/// added to its requests from the step's first tick, away from its nearer limit, which
/// saturates it when probe_deg exceeds theta_0 (a cost in tracking error for that step). 0
/// (default) never probes.
///
/// Excursion probing (`adaptive.probe_ticks` > 0, with probe_deg > 0): on a walk, a window's
/// fit pins l + a/2 and not l and a apart (the walk's requests change smoothly), and a joint
/// that never saturates shows no v_max. A step test separates them: the velocity ramps up over
/// a ticks, starting l + 1 ticks after the step, and a step larger than theta_0 reaches top
/// speed. So while a joint's model is uncertain (from the start, and again after a change is
/// detected) each step adds a step-test-like excursion to its requests: probe_deg, away from
/// the joint's nearer limit, held probe_ticks ticks from the step's tick kProbeLeadTicks on.
/// The model is then the identification's own fit (IdentifyJointModel, the whole grid of l
/// and a) to the probed steps since the change (the latest kPooledProbeSteps of them), as
/// `identify` fits its step tests, rather than to the walk. Probing stops when two
/// consecutive fits agree on l and a (kStableFits); from then on the model is kept and the
/// walk only monitors it: after each step the model's open-loop prediction residual on that
/// step is compared with the one of the first step after it was learned, and a residual over
/// kChangeRatio times that (or kResidualFloorDeg) marks a change (the joint is probed again, from
/// no probed steps). Persistence of excitation scheduled by uncertainty: probing costs tracking
/// error in the probed steps (and the first ticks after one, when the excursion is held to the
/// step's end), the steps before the model is known. Costs: while a joint probes, every
/// EndOfStep runs the whole identification on up to kPooledProbeSteps steps of it, far more
/// than one 8 ms tick (fine in simulation; on a robot it belongs in a background thread). A
/// step of at most kProbeLeadTicks ticks has no room for an excursion: it never probes, and
/// the model is learned from the walk alone. Once learned, the residual reported for a joint
/// (ModelEstimates, `model_estimates.csv`'s fit_rms_deg) is the monitor's: the kept model's
/// prediction residual on the latest step, no longer the fit's.
///
/// Requests are always finite and within the limits: a failed estimate or re-plan keeps the
/// previous model and cycle, and a non-finite request (which a valid model never gives)
/// falls back to the desired angle.
class AdaptiveController final : public JointController {
 public:
  /// The `adaptive.*` keys.
  struct Spec {
    JointModelParams initial_model = {2.5, 7.0, 4, 6};  ///< adaptive.initial_model (Table 1)
    int window_steps = 2;                               ///< adaptive.window_steps
    double probe_deg = 0.0;                             ///< adaptive.probe_deg
    int probe_ticks = 0;  ///< adaptive.probe_ticks; 0: pulses, > 0: excursions
    friend bool operator==(const Spec&, const Spec&) = default;
  };
  static constexpr std::string_view kName = "adaptive";
  static constexpr std::string_view kLabel = "Ad";
  static constexpr ControllerModeTraits kTraits{.estimates_model = true,
                                                .config_section = "adaptive"};
  /// A v_max change smaller than this is not re-planned for, deg/tick.
  static constexpr double kVmaxResolution = 0.03;
  /// A theta_0 change smaller than this is not re-planned for, deg.
  static constexpr double kTheta0Resolution = 0.3;
  /// Excursion probing: the excursion starts at this tick of a step (the identification's
  /// largest l + a, so the fit has the requests that act on the first scored tick).
  static constexpr int kProbeLeadTicks = 24;
  /// Excursion probing: the model is fitted to at most this many latest probed steps.
  static constexpr int kPooledProbeSteps = 4;
  /// Excursion probing: probing stops after this many fits in a row with the l and a of the fit
  /// before.
  static constexpr int kStableFits = 1;
  /// Excursion probing: a step whose residual exceeds this many times the first one after the
  /// model was learned marks a change of the joint.
  static constexpr double kChangeRatio = 1.5;
  /// Excursion probing: the residual the change test compares against is at least this, deg,
  /// so that an exact model (residual 0 up to rounding) is not taken for a changed one.
  static constexpr double kResidualFloorDeg = 0.1;
  /// Its keys, declared once (see KeyVisitor).
  static void VisitKeys(KeyVisitor& visitor, Spec& spec);

  /// Throws std::invalid_argument on an empty cycle or a bad spec.
  AdaptiveController(const Spec& spec, const ControllerContext& context);

  void Reset() override;
  LegAngles Update(long tick, const LegAngles& measured_deg) override;
  void Observe(long tick, const LegAngles& applied_deg, const LegAngles& measured_deg) override;
  void EndOfStep(long step) override;
  std::optional<JointModelEstimates> ModelEstimates() const override { return estimates_; }
  std::string_view name() const override { return kName; }

  /// The request cycle the next step will use (without a probe), requests()[t][j].
  const DesiredCycle& requests() const { return requests_; }
  /// The model each joint's requests were planned with.
  const std::array<JointModelParams, kLegJoints>& planned_models() const { return planned_; }

 private:
  bool Excursions() const;
  // Excursion probing: +1 or -1, the side of joint j's planned requests with more room.
  double ProbeSign(int joint) const;
  // Excursion probing's EndOfStep for joint j (the latest step's recording in `step`).
  void LearnFromExcursions(int joint, JointRecording step);
  // Re-plans joint j's column of requests_ for `model`; false (nothing changed) on failure.
  bool Replan(int joint, const JointModelParams& model);

  Spec spec_;
  ControllerContext context_;
  int pwl_segments_ = 8;
  std::array<JointModelParams, kLegJoints> planned_;
  JointModelEstimates estimates_;
  DesiredCycle requests_;
  // The latest window_steps * T observed ticks, oldest first (requests as applied, measured).
  std::array<JointRecording, kLegJoints> window_;
  long last_observed_tick_ = -1;
  std::array<bool, kLegJoints> probe_next_{};  // probe this joint in the coming step
  std::array<bool, kLegJoints> probing_{};     // probing it in the current step
  // A window since the joint last changed (l or a) saturated it: its v_max is current.
  std::array<bool, kLegJoints> vmax_known_{};
  // Excursion probing: the probed steps since the joint last changed (latest last), the fits
  // in a row that kept l and a, whether the model is learned (probing stopped), the residual of
  // the first step after it was, and the excursion's sign in the coming step.
  std::array<std::vector<JointRecording>, kLegJoints> probed_steps_;
  std::array<int, kLegJoints> stable_fits_{};
  std::array<bool, kLegJoints> learned_{};
  std::array<double, kLegJoints> baseline_rms_{};
  std::array<double, kLegJoints> probe_sign_{};
};

}  // namespace leglab
