#pragma once

#include <array>
#include <string>
#include <vector>

#include "leglab/experiments/config.h"
#include "leglab/experiments/output.h"
#include "leglab/experiments/rig.h"
#include "leglab/model/piecewise_linear.h"

namespace leglab::experiments {

/// One controller mode's run on the leg.
struct ModeRun {
  std::string mode;
  int shift_ticks = 0;  ///< time_shift: the k used (the best one when searched)
  TrackingRun run;
  std::vector<double> foot_error_cm;  ///< per recorded tick
};

/// Everything `track` measured.
struct TrackResult {
  DesiredMotion desired;
  std::array<JointModelParams, kLegJoints> models;
  bool models_identified = false;  ///< identified on the plant (no model.* keys given)
  std::array<PiecewiseLinear, kLegJoints> approximations;  ///< model_based's P per joint
  std::vector<ModeRun> runs;                               ///< in controller.modes order
  std::vector<double> shift_search_foot_l2_cm;  ///< mean foot L2 for k = 0..T-1 (if searched)
  int steps = 0;
  int period = 0;
};

/// Runs Table 2's experiment: the desired cycle, the models (given or identified as
/// `identify` does), every mode in controller.modes (time_shift searching every k by foot
/// L2 across cores when track.search_shift), warmup_steps then steps measured steps.
TrackResult RunTrackExperiment(const ExperimentConfig& config);

/// Writes table2.json, table2.md, trace_<mode>.csv and foot_<mode>.csv (and the time-shift
/// search, shift_search.csv) into `out`. Returns the Markdown tables.
std::string WriteTable2(const TrackResult& result, const OutputDir& out);

}  // namespace leglab::experiments
