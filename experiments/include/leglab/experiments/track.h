#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "leglab/controller/registry.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/robot.h"

namespace leglab::experiments {

/// The walk the walk-fitted models (TrackResult::walk_context) are fitted to: steps run first,
/// then steps recorded, averaged into one cycle (kWalkFitPlayedCycles). 16 recorded steps: fewer
/// lose untuned walks to the time shift, more cost a walk's physics each without winning every
/// walk; see docs/design/walk-fit.md.
inline constexpr int kWalkFitWarmupSteps = 5;
inline constexpr int kWalkFitSteps = 16;
/// The walk fit averages the recorded steps into one cycle (AverageCycles: the requests repeat
/// every step and the plant is time-invariant, so the steps differ only by the sensor noise)
/// and scores the model's prediction over this many plays of it, after the fit's warm-up.
inline constexpr int kWalkFitPlayedCycles = 2;
/// The walk fit searches each joint's lag only within this many ticks of the lag of the model it
/// has (within identify.lag_range_ticks; the whole range if that leaves none): it is the same
/// servo, so the walk's lag lies near the step tests', and the narrower search finds the same fit
/// for less work; see docs/design/walk-fit.md.
inline constexpr int kWalkFitLagRadiusTicks = 3;

/// A joint whose requests over that walk span less than this (deg) keeps the model it has: the
/// walk says nothing about it (e.g. a joint held still).
inline constexpr double kWalkFitMinSwingDeg = 1.0;

/// One controller mode's run on the plant.
struct ModeRun {
  /// The options used (a searched mode's best candidate); for an external mode a default
  /// ControllerSpec that means nothing (read the run's mode with ModeInfo, not ModeOf(spec)).
  ControllerSpec spec;
  TrackingRun run;
  std::vector<double> foot_error_cm;  ///< per recorded tick
  /// An external mode's name (ExternalMode::name); empty for a registered mode (then `spec`
  /// names it).
  std::string external;
};

/// The longest name an ExternalMode may have, characters.
inline constexpr size_t kMaxExternalModeNameChars = 64;

/// A controller mode from outside the registry (a user's own, e.g. written in Python): it runs
/// after the configured modes under the same plant, seed, warm-up, steps and plant_changes, with
/// the step tests' (or given) models (TrackResult::context), and its rows appear in the tables
/// under `name`, as a registered mode's do under its name.
struct ExternalMode {
  /// [a-z0-9_]+ (a file-name part), at most kMaxExternalModeNameChars characters, not a
  /// registered mode's name nor "floor" (the foot table's row of the floor), unique among the
  /// run's external modes.
  std::string name;
  /// Builds the controller for the run's context; called once, right before its run.
  std::function<std::unique_ptr<JointController>(const ControllerContext&)> make;
};

/// What the tables and writers need to know about `run`'s mode: ModeOf(run.spec) for a
/// registered mode; for an external one, name and label are run.external (views into `run`:
/// valid while it lives and its name is unchanged), and it is neither feed-forward, nor
/// following P, nor searchable, nor estimating the model, with no search file or config section.
ControllerModeInfo ModeInfo(const ModeRun& run);

/// A searched mode's candidates (SearchCandidates, e.g. time_shift's k = 0..T-1), each with its
/// mean foot L2 over the measured steps, cm.
struct ModeSearch {
  ControllerSpec best;
  std::vector<ControllerSpec> candidates;
  std::vector<double> foot_l2_cm;
  /// The scores were taken from one run of the lead-0 candidate (track.search_shift: true),
  /// not from a run of each candidate (exhaustive).
  bool scored_from_one_run = false;
};

/// The model `identify` finds on the plant as it is from measured step `from_step` on (before
/// any change: -warmup_steps).
struct PlantIdentification {
  int from_step = 0;
  std::array<IdentificationResult, kLegJoints> joints;
};

/// Everything `track` measured.
struct TrackResult {
  Robot robot;
  DesiredMotion desired;
  ControllerContext context;  ///< desired angles, models, limits, approximations P
  /// When a mode asks for it (UsesWalkModels): the same context with each joint's model fitted
  /// to the walk instead ("identification for control"): IdentifyJointModel on the plant's
  /// response to the paper's model-based requests (exact C_m, under `context`'s models;
  /// kWalkFitWarmupSteps steps, then kWalkFitSteps recorded, whatever the run's own step
  /// counts), pooled with the step tests' recordings when the models were identified; a joint
  /// the walk hardly moves (kWalkFitMinSwingDeg) or whose fit fails keeps `context`'s model.
  /// Those modes run with it.
  std::optional<ControllerContext> walk_context;
  /// Each joint's floor (FloorTrajectory): the cyclic trajectory nearest the desired one within
  /// the model's speed and acceleration limits, deg, one step.
  std::array<std::vector<double>, kLegJoints> floor_deg;
  bool models_identified = false;    ///< identified on the plant (no model.* keys given)
  std::vector<ModeRun> runs;         ///< in the config's mode order
  std::vector<ModeSearch> searches;  ///< for the searched modes, in run order
  /// When a mode estimates the model (ControllerModeInfo::estimates_model): the plant
  /// identified before the changes and after each (plant_changes), for comparison; else empty.
  std::vector<PlantIdentification> plant_models;
  int steps = 0;
  int period = 0;
  /// On the test stand (stand.enabled): the weight the floor carries standing, (stand.load_kg +
  /// the leg's mass) x 9.81, N; 0 in the air.
  double stand_weight_n = 0.0;
  /// Plant ticks run in all (identification's step tests, searches and every mode's run): the
  /// physics the experiment cost, sim.physics_dt_ms steps each on the simulated leg.
  long plant_ticks = 0;
};

/// The context `spec` runs with: walk_context for a mode that UsesWalkModels, else context.
const ControllerContext& ContextFor(const TrackResult& r, const ControllerSpec& spec);

/// The context `run` ran with: ContextFor(r, run.spec) for a registered mode, r.context for an
/// external one.
const ControllerContext& ContextFor(const TrackResult& r, const ModeRun& run);

/// Takes each mode's run as it is done (`runs` of the TrackResult stays empty): a long run
/// writes and reduces one mode at a time instead of holding them all.
using ModeRunSink = std::function<void(const TrackResult&, ModeRun&&)>;

/// Runs Table 2's experiment: the robot, the desired cycle, the models (given or identified
/// as `identify` does), every configured mode (a searchable mode, e.g. time_shift, scores
/// every candidate as track.search_shift says and runs the best by foot L2), warmup_steps
/// then steps measured steps. Parallel on config.threads threads; the result does not depend on
/// the count. With a `sink`, each mode's run goes to it, in order, instead of into `runs`; a
/// searched mode's candidates are scored without keeping their runs either way.
///
/// Then each of `external` in order (ExternalMode): make(r.context) builds its controller, which
/// runs on a plant of its own as a registered mode's does; its run goes to the sink or `runs`
/// with ModeRun::external set. The external modes are checked before anything runs: a bad name
/// (see ExternalMode::name) or an empty `make` throws InputError naming the mode ("controller
/// 'x': ..."); a run whose ticks with theirs (PlannedTrackTicks) exceed kMaxTotalTicks throws
/// InputError. A `make` that returns no controller throws InputError naming it when its turn
/// comes. What `make` or an external controller throws propagates unchanged.
/// Throws InputError for bad input (config, robot, models), as the loaders do.
TrackResult RunTrackExperiment(const ExperimentConfig& config, const ModeRunSink& sink = {},
                               std::span<const ExternalMode> external = {});

/// The ticks RunTrackExperiment(config, sink, external) simulates at most: config.planned_ticks
/// and (warmup_steps + steps) x track.t_step_ticks per external mode. A progress display of a
/// run with external modes counts to this (config.planned_ticks alone would reach 100 % before
/// they run). Does not check the total against kMaxTotalTicks (RunTrackExperiment does).
long long PlannedTrackTicks(const ExperimentConfig& config, size_t external_modes);

/// Mean over steps of the per-step RMS of `foot_error_cm` (steps of `period` ticks), cm.
double MeanFootL2Cm(const std::vector<double>& foot_error_cm, int period);

}  // namespace leglab::experiments
