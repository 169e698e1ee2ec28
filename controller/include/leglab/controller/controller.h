#pragma once

#include <array>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/core/leg.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/kinematics.h"
#include "leglab/model/piecewise_linear.h"

namespace leglab {

/// One cycle of desired joint angles: desired[t][j] for tick t = 0..T-1, degrees. The
/// trajectory repeats with period T (one walking step).
using DesiredCycle = std::vector<LegAngles>;

/// What every controller is built from besides its own options: what to follow, each joint's
/// model and limits, and each joint's slope-limited piecewise-linear approximation of the
/// desired cycle (set up by MakeControllerContext, fitted on first use).
struct ControllerContext;

/// Each joint's piecewise-linear approximation P of a desired cycle (section 4.1, with
/// FitPiecewiseLinear), fitted on first use: only the modes that follow P (model_based, and
/// optimal and ilc through their model-based start) and the outputs that show it need it (a
/// run whose modes do not and which writes no trace, e.g. direct and time_shift alone, never
/// fits it). The inputs
/// are fixed at construction, so the result is the same bits whenever and by whichever thread
/// it is first asked for. Thread-safe; shared by the copies of a context.
class ApproximationMemo {
 public:
  ApproximationMemo(DesiredCycle desired, const std::array<double, kLegJoints>& v_max_deg_per_tick,
                    int segments);
  /// The fits (once; later calls return the same).
  const std::array<PiecewiseLinear, kLegJoints>& Get();
  /// Segments of every fit (what num_segments() of each gives), without fitting.
  int segments() const { return segments_; }
  /// The approximations of the same desired cycle and segments under other v_max (another
  /// model's context), sharing this one's PwlFitCache: the fits of both form each breakpoint
  /// set's normal equations once. The same bits as a memo of its own.
  std::shared_ptr<ApproximationMemo> ForOtherModels(
      const std::array<double, kLegJoints>& v_max_deg_per_tick) const;

 private:
  std::shared_ptr<std::array<PwlFitCache, kLegJoints>> caches_ =
      std::make_shared<std::array<PwlFitCache, kLegJoints>>();
  DesiredCycle desired_;
  std::array<double, kLegJoints> v_max_deg_per_tick_;
  int segments_;
  std::once_flag once_;
  std::array<PiecewiseLinear, kLegJoints> fits_;
};

/// Request cycles computed offline from a context, kept so that the modes that start from the
/// same one (optimal, and ilc started from it) compute it once a run. Shared by the copies of
/// a context and thread-safe (modes run in parallel); an entry is reused only for the very
/// inputs it was computed from (desired cycle, models and limits, compared exactly), so a copy
/// of the context with another model computes its own.
class OfflineCycleMemo {
 public:
  /// The cycle named `name` for `context`: the one computed earlier for the same inputs, else
  /// `compute()` (run once, under the memo's lock).
  DesiredCycle GetOrCompute(const char* name, const ControllerContext& context,
                            const std::function<DesiredCycle()>& compute);

 private:
  struct Entry {
    std::string name;
    DesiredCycle desired;
    std::array<JointModelParams, kLegJoints> models;
    std::array<JointLimits, kLegJoints> limits;
    DesiredCycle cycle;
  };
  std::mutex mutex_;
  std::vector<Entry> entries_;
};

struct ControllerContext {
  DesiredCycle desired;                             ///< deg, one step
  std::array<JointModelParams, kLegJoints> models;  ///< identified or given
  std::array<JointLimits, kLegJoints> limits;       ///< rad, the plant's software limits
  /// P of each joint (section 4.1), fitted on first use: read it with Approximation.
  std::shared_ptr<ApproximationMemo> approximations;
  /// Steps the experiment runs before it measures (learning modes may treat them apart).
  int warmup_steps = 0;
  /// The leg's geometry, for modes that weigh their errors at the foot (ILC's foot objective);
  /// the experiments set it from the robot. Absent, such a mode cannot be made.
  std::optional<LegGeometry> geometry;
  /// Offline request cycles already computed for this run (see OfflineCycleMemo).
  std::shared_ptr<OfflineCycleMemo> offline_cycles = std::make_shared<OfflineCycleMemo>();

  /// Joint `joint`'s approximation P (fitted now if no one has asked for it before); an empty
  /// one (no segments) for a context not made by MakeControllerContext.
  const PiecewiseLinear& Approximation(int joint) const;
  /// The segments of every joint's P (Approximation(j).num_segments()) without fitting it.
  int ApproximationSegments() const { return approximations ? approximations->segments() : 0; }
};

/// Builds the context: each joint's approximation with `pwl_segments` segments and its model's
/// v_max, fitted on first use (ApproximationMemo). Throws std::invalid_argument on an empty cycle,
/// an invalid model or limits, or pwl_segments outside [1, T] (the message names
/// `controller.pwl_segments`).
ControllerContext MakeControllerContext(DesiredCycle desired,
                                        const std::array<JointModelParams, kLegJoints>& models,
                                        const std::array<JointLimits, kLegJoints>& limits,
                                        int pwl_segments);

/// The same for a robot's leg: its geometry's limits, and the geometry itself for the modes
/// that work at the foot. Throws as above, and as ValidateLegGeometry.
ControllerContext MakeControllerContext(DesiredCycle desired,
                                        const std::array<JointModelParams, kLegJoints>& models,
                                        const LegGeometry& geometry, int pwl_segments);

/// A controller mode's optional traits, declared in one block of its class:
///   static constexpr ControllerModeTraits kTraits{.feed_forward = true, .config_section = "x"};
/// A misspelt field does not compile. Each `has_` flag declares a static function of the mode,
/// and the registry checks at compile time that the function exists exactly when its flag is
/// set (registry.h), so a misspelt function is an error too, not a silently missing trait.
struct ControllerModeTraits {
  bool feed_forward = false;           ///< requests periodic, independent of measurements
  bool follows_approximation = false;  ///< Table 2 also compares it with the approximation P
  bool estimates_model = false;        ///< ModelEstimates() reports its joint models every step
  std::string_view config_section = "controller";  ///< the config map of its keys
  /// Where a search's scores go (no .csv); set exactly when has_search_candidates.
  std::string_view search_file{};
  /// static std::vector<Spec> SearchCandidates(const Spec&, const ControllerContext&)
  bool has_search_candidates = false;
  /// static int RequestLeadTicks(const Spec&): a search candidate requests what the candidate
  /// with lead 0 requests, this many ticks earlier (R(t) = R_0(t + lead))
  bool has_request_lead = false;
  /// static bool ModelFittedToWalk(const Spec&): the experiments build it with models fitted to
  /// the walk, not the step tests'
  bool has_walk_models = false;
  /// static std::vector<std::pair<std::string_view, long>> Parameters(const Spec&): its
  /// integer parameters, for the outputs
  bool has_parameters = false;
};

/// Each joint's model as a controller currently estimates it, with the RMS residual of its fit
/// to the data it was estimated from (deg).
using JointModelEstimates = std::array<IdentificationResult, kLegJoints>;

/// A request policy for one leg (ros2_control's update(time, period) in miniature). Per
/// 8 ms control tick the experiment calls, in order:
///   r = Update(tick, measured)    the requests for this tick, from the last reading;
///   Observe(tick, applied, measured)  what the plant did with them (applied = clamped r);
/// and after the last tick of every step (of T ticks, warm-up steps included) EndOfStep().
/// Learning controllers adapt in Observe/EndOfStep; feed-forward ones ignore both.
/// Controllers see no simulator type.
class JointController {
 public:
  virtual ~JointController() = default;

  /// Back to the state right after construction: a new run starts at tick 0.
  virtual void Reset() {}

  /// Requested angles (deg) for tick `tick` (0, 1, 2, ... from the start of the run), given
  /// the angles measured right after the previous request. Finite and within the limits.
  virtual LegAngles Update(long tick, const LegAngles& measured_deg) = 0;

  /// After tick `tick`: the requests as the plant applied them (clamped), and the angles
  /// measured right after.
  virtual void Observe(long /*tick*/, const LegAngles& /*applied_deg*/,
                       const LegAngles& /*measured_deg*/) {}

  /// Step `step` (0, 1, ... from the start of the run) has ended.
  virtual void EndOfStep(long /*step*/) {}

  /// The joint models a controller that estimates them holds now (after the latest
  /// EndOfStep); empty (this default) for a controller that does not.
  virtual std::optional<JointModelEstimates> ModelEstimates() const { return std::nullopt; }

  /// The mode's name, as chosen in the config.
  virtual std::string_view name() const = 0;
};

/// Which models a mode computes its requests from.
enum class ModelSource {
  kStepTests,  ///< `step_tests`: the models identified from the step tests (or given)
  kWalk,       ///< `walk`: fitted to the plant's walk (see ModelFittedToWalk in registry.h)
};
inline constexpr std::array<std::string_view, 2> kModelSourceNames = {"step_tests", "walk"};

/// Declares a mode's key `model` (a ModelSource), shared by the modes that invert a model.
void VisitModelSourceKey(KeyVisitor& visitor, ModelSource& source);

/// What an optimising mode (optimal, ilc) minimises under the model.
enum class Objective {
  kJoint,  ///< `joint`: each joint's RMS error on its own
  kFoot,   ///< `foot`: the foot's distance from its path plus joint_weight times the joints'
};
inline constexpr std::array<std::string_view, 2> kObjectiveNames = {"joint", "foot"};

/// Declares the keys `objective`, `joint_weight` and `request_smoothing` that optimal and ilc
/// share.
void VisitObjectiveKeys(KeyVisitor& visitor, Objective& objective, double& joint_weight,
                        double& request_smoothing);

/// Throws std::invalid_argument "<mode>: the <joint>'s model has no cyclic steady state ..."
/// naming the first joint whose model does not settle under every request cycle
/// (SettlesOnEveryCycle: v_max >= 2 theta_0), for the modes that optimise the model's steady
/// state (optimal, ilc). Identified models always settle (kMaxFittedSpeedRatio); a given one
/// may not.
void RequireSettlingModels(const ControllerContext& context, std::string_view mode);

/// desired[tick mod T] (any integer tick).
inline const LegAngles& CycleAt(const DesiredCycle& cycle, long tick) {
  const auto period = static_cast<long>(cycle.size());
  return cycle[static_cast<size_t>((tick % period + period) % period)];
}

/// `request_deg` clamped into `limits` (rad), as the servos would.
LegAngles ClampToLimits(const LegAngles& request_deg,
                        const std::array<JointLimits, kLegJoints>& limits);

}  // namespace leglab
