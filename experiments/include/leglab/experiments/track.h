#pragma once

#include <functional>
#include <string>
#include <vector>

#include "leglab/controller/registry.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/robot.h"

namespace leglab::experiments {

/// One controller mode's run on the plant.
struct ModeRun {
  ControllerSpec spec;  ///< the options used (a searched mode's best candidate)
  TrackingRun run;
  std::vector<double> foot_error_cm;  ///< per recorded tick
};

/// A searched mode's candidates (SearchCandidates, e.g. time_shift's k = 0..T-1), each with its
/// mean foot L2 over the measured steps, cm.
struct ModeSearch {
  ControllerSpec best;
  std::vector<ControllerSpec> candidates;
  std::vector<double> foot_l2_cm;
};

/// Everything `track` measured.
struct TrackResult {
  Robot robot;
  DesiredMotion desired;
  ControllerContext context;  ///< desired angles, models, limits, approximations P
  /// Each joint's floor (FloorTrajectory): the cyclic trajectory nearest the desired one within
  /// the model's speed and acceleration limits, deg, one step.
  std::array<std::vector<double>, kLegJoints> floor_deg;
  bool models_identified = false;    ///< identified on the plant (no model.* keys given)
  std::vector<ModeRun> runs;         ///< in the config's mode order
  std::vector<ModeSearch> searches;  ///< for the searched modes, in run order
  int steps = 0;
  int period = 0;
};

/// Takes each mode's run as it is done (`runs` of the TrackResult stays empty): a long run
/// writes and reduces one mode at a time instead of holding them all.
using ModeRunSink = std::function<void(const TrackResult&, ModeRun&&)>;

/// Runs Table 2's experiment: the robot, the desired cycle, the models (given or identified
/// as `identify` does), every configured mode (a searchable mode, e.g. time_shift, tries
/// every candidate and keeps the best by foot L2 when track.search_shift), warmup_steps then
/// steps measured steps. Parallel on config.threads threads; the result does not depend on
/// the count. With a `sink`, each mode's run goes to it, in order, instead of into `runs`; a
/// searched mode's candidates are scored without keeping their runs either way.
TrackResult RunTrackExperiment(const ExperimentConfig& config, const ModeRunSink& sink = {});

/// Mean over steps of the per-step RMS of `foot_error_cm` (steps of `period` ticks), cm.
double MeanFootL2Cm(const std::vector<double>& foot_error_cm, int period);

}  // namespace leglab::experiments
