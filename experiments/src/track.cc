#include "leglab/experiments/track.h"

#include <algorithm>
#include <span>

#include "leglab/experiments/parallel.h"
#include "leglab/model/floor.h"
#include "leglab/model/metrics.h"

namespace leglab::experiments {
namespace {

ModeRun RunMode(const ExperimentConfig& config, const TrackResult& r, const ControllerSpec& spec) {
  const std::unique_ptr<JointController> controller = MakeController(spec, r.context);
  const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
  ModeRun run{spec, {}, {}};
  run.run = RunTracking(*plant, *controller, r.context.desired, config.track.warmup_steps,
                        config.track.steps);
  run.foot_error_cm = FootErrorsCm(run.run, r.desired, r.robot.geometry);
  return run;
}

// A candidate's score alone: RunMode's foot L2 without keeping the run (memory O(steps)).
double ScoreMode(const ExperimentConfig& config, const TrackResult& r, const ControllerSpec& spec) {
  const std::unique_ptr<JointController> controller = MakeController(spec, r.context);
  const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
  return TrackingFootL2Cm(*plant, *controller, r.desired, r.robot.geometry,
                          config.track.warmup_steps, config.track.steps);
}

}  // namespace

double MeanFootL2Cm(const std::vector<double>& foot_error_cm, int period) {
  std::vector<double> per_step;
  for (size_t s = 0; s * period < foot_error_cm.size(); ++s) {
    per_step.push_back(Rms(std::span<const double>(foot_error_cm).subspan(s * period, period)));
  }
  return MeanAndStd(per_step).mean;
}

TrackResult RunTrackExperiment(const ExperimentConfig& config, const ModeRunSink& sink) {
  TrackResult r;
  r.robot = LoadRobot(config.sim.urdf_path);
  r.desired = LoadDesiredMotion(config.track, r.robot.geometry);
  r.period = static_cast<int>(r.desired.angles_deg.size());
  r.steps = config.track.steps;
  MakePlant(config, r.robot);  // bad plant input fails here, before any run
  std::array<JointModelParams, kLegJoints> models;
  if (config.model) {
    models.fill(*config.model);
  } else {
    const auto identified = IdentifyLeg(config, r.robot);
    for (int j = 0; j < kLegJoints; ++j) models[j] = identified[j].fit.params;
    r.models_identified = true;
  }
  // The approximations P, fitted once: model_based follows them, every trace shows them.
  try {
    r.context = MakeControllerContext(r.desired.angles_deg, models, r.robot.geometry.limits,
                                      config.pwl_segments);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  r.context.warmup_steps = config.track.warmup_steps;
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> desired(r.period);
    for (int t = 0; t < r.period; ++t) desired[t] = r.context.desired[t][j];
    r.floor_deg[j] = FloorTrajectory(desired, models[j]);
  }

  for (const ControllerSpec& spec : config.controllers) {
    // Each run to the sink when there is one, so that only one is held at a time.
    auto keep = [&](ModeRun run) {
      sink ? sink(r, std::move(run)) : r.runs.push_back(std::move(run));
    };
    if (!config.track.search_shift || !ModeOf(spec).searchable) {
      keep(RunMode(config, r, spec));
      continue;
    }
    // Every candidate scored in parallel, keeping only its score; the best is run again
    // (same bits: a run depends only on its spec and the seed).
    ModeSearch search;
    search.candidates = SearchCandidates(spec, r.context);
    search.foot_l2_cm.resize(search.candidates.size());
    ParallelFor(static_cast<int>(search.candidates.size()), config.threads,
                [&](int k) { search.foot_l2_cm[k] = ScoreMode(config, r, search.candidates[k]); });
    const auto best = std::min_element(search.foot_l2_cm.begin(), search.foot_l2_cm.end()) -
                      search.foot_l2_cm.begin();
    search.best = search.candidates[best];
    keep(RunMode(config, r, search.best));
    r.searches.push_back(std::move(search));
  }
  return r;
}

}  // namespace leglab::experiments
