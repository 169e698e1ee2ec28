#include "run_budget.h"

#include "leglab/app/yaml_config.h"
#include "leglab/experiments/track.h"

namespace leglab::experiments {
namespace {

// The fit scores every (l, a) candidate over every recorded tick of every step height.
void CheckIdentificationWork(const IdentifyConfig& c) {
  const long long candidates =
      static_cast<long long>(c.search.lag_max_ticks - c.search.lag_min_ticks + 1) *
      (c.search.accel_max_ticks - c.search.accel_min_ticks + 1);
  const long long work = candidates * c.record_cycles * c.t_step_ticks *
                         static_cast<long long>(c.theta_test_deg.size());
  if (work > kMaxIdentificationWork) {
    FailConfig("identify: " + std::to_string(candidates) +
               " (l, a) candidates (lag_range_ticks x " + "accel_range_ticks) times " +
               std::to_string(c.record_cycles * c.t_step_ticks) +
               " recorded ticks (record_cycles x t_step_ticks) times " +
               std::to_string(c.theta_test_deg.size()) + " step heights is " +
               std::to_string(work) + ", more than the " + std::to_string(kMaxIdentificationWork) +
               " a fit may take; narrow the ranges or record fewer cycles");
  }
}

// One tracking run's ticks: its recorded trace is what track writes.
void CheckTicksPerRun(const TrackConfig& t) {
  const long long per_run =
      (static_cast<long long>(t.warmup_steps) + t.steps) * static_cast<long long>(t.t_step_ticks);
  if (per_run > kMaxTicksPerRun) {
    FailConfig("(warmup_steps + steps) x track.t_step_ticks = (" + std::to_string(t.warmup_steps) +
               " + " + std::to_string(t.steps) + ") x " + std::to_string(t.t_step_ticks) + " = " +
               std::to_string(per_run) + " ticks per run, more than " +
               std::to_string(kMaxTicksPerRun));
  }
}

// The tracking runs' ticks: one run per mode, and per searched candidate plus the best one's
// rerun, and the walk the walk-fitted models are fitted to, once for all the modes that use
// them.
long long TrackingTicks(const ExperimentConfig& config) {
  const long long run_ticks =
      (static_cast<long long>(config.track.warmup_steps) + config.track.steps) *
      config.track.t_step_ticks;
  long long total = 0;
  bool walk_fit = false;
  for (const ControllerSpec& spec : config.controllers) {
    const ControllerModeInfo& mode = ModeOf(spec);
    const ShiftSearch search = config.track.search_shift;
    if (!mode.searchable || search == ShiftSearch::kNone) {
      total += run_ticks;
    } else if (search == ShiftSearch::kShiftedRun && mode.searchable_by_lead &&
               config.plant_changes.empty()) {
      // Scored from one run of the lead-0 candidate, one step longer, then the best one's run
      // (as SearchMode does): what runs, not the candidates it scores.
      total += 2 * run_ticks + config.track.t_step_ticks;
    } else {
      // At most one candidate per tick of the step (time_shift's k), then the best one's run.
      total += (static_cast<long long>(config.track.t_step_ticks) + 1) * run_ticks;
    }
    walk_fit = walk_fit || UsesWalkModels(spec);
  }
  if (walk_fit) {
    total +=
        static_cast<long long>(kWalkFitWarmupSteps + kWalkFitSteps) * config.track.t_step_ticks;
  }
  return total;
}

}  // namespace

long long PlannedTicks(const ExperimentConfig& config, bool tracks) {
  CheckIdentificationWork(config.identify);
  CheckTicksPerRun(config.track);
  long long total = 0;
  if (!tracks || !config.model) {
    const IdentifyConfig& id = config.identify;
    total += static_cast<long long>(kLegJoints) * static_cast<long long>(id.theta_test_deg.size()) *
             (id.settle_cycles + id.record_cycles) * id.t_step_ticks;
  }
  if (tracks) total += TrackingTicks(config);
  if (total > kMaxTotalTicks) {
    FailConfig("the run would simulate " + std::to_string(total) + " ticks (every mode and " +
               "searched candidate, (warmup_steps + steps) x track.t_step_ticks each), more " +
               "than " + std::to_string(kMaxTotalTicks) + "; run fewer steps, fewer modes or " +
               "track.search_shift=false");
  }
  return total;
}

}  // namespace leglab::experiments
