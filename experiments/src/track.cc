#include "leglab/experiments/track.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/app/parallel.h"
#include "leglab/app/progress.h"
#include "leglab/model/floor.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/metrics.h"

namespace leglab::experiments {
namespace {

// Plant ticks of one run: warm-up and measured steps.
long RunTicks(const ExperimentConfig& config, int period) {
  return static_cast<long>(config.track.warmup_steps + config.track.steps) * period;
}

// Plays a fixed request cycle (the walk that the walk-fitted models are fitted to).
class CyclePlayer final : public JointController {
 public:
  explicit CyclePlayer(DesiredCycle cycle) : cycle_(std::move(cycle)) {}
  LegAngles Update(long tick, const LegAngles& /*measured_deg*/) override {
    return CycleAt(cycle_, tick);
  }
  std::string_view name() const override { return "walk_probe"; }

 private:
  DesiredCycle cycle_;
};

// Each joint's model fitted to the plant's response to each of `walks` (request cycles played
// kWalkFitWarmupSteps steps, then kWalkFitSteps recorded and averaged into one cycle), pooled with
// `step_tests` (per joint; may be empty). The lag is searched near r.context's models'.
std::array<JointModelParams, kLegJoints> FitModelsToWalk(
    const ExperimentConfig& config, TrackResult& r,
    const std::array<std::vector<JointRecording>, kLegJoints>& step_tests,
    const std::vector<DesiredCycle>& walks) {
  std::vector<TrackingRun> runs;
  for (const DesiredCycle& requests : walks) {
    CyclePlayer player(requests);
    const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
    runs.push_back(
        RunTracking(*plant, player, r.context.desired, kWalkFitWarmupSteps, kWalkFitSteps));
    r.plant_ticks += static_cast<long>(kWalkFitWarmupSteps + kWalkFitSteps) * r.period;
  }
  SetProgressPhase("identification for control: the walk");  // after the run's "walking"
  std::array<JointModelParams, kLegJoints> models = r.context.models;
  ParallelFor(kLegJoints, config.threads, [&](int j) {
    // The same servo: its lag on the walk is searched near the one it has (see
    // kWalkFitLagRadiusTicks), the rest of the search as identify's.
    IdentificationOptions search = config.identify.search;
    const int lag = r.context.models[j].lag_ticks;
    search.lag_min_ticks = std::max(search.lag_min_ticks, lag - kWalkFitLagRadiusTicks);
    search.lag_max_ticks = std::min(search.lag_max_ticks, lag + kWalkFitLagRadiusTicks);
    if (search.lag_min_ticks > search.lag_max_ticks) search = config.identify.search;
    const int warmup = search.lag_max_ticks + search.accel_max_ticks;
    std::vector<JointRecording> walked(runs.size());
    for (size_t w = 0; w < runs.size(); ++w) {
      for (size_t t = 0; t < runs[w].request_deg.size(); ++t) {
        walked[w].request_deg.push_back(runs[w].request_deg[t][j]);
        walked[w].measured_deg.push_back(runs[w].measured_deg[t][j]);
      }
    }
    // A walk that hardly moves the joint says nothing about its model (and, without step tests
    // to pool with, cannot be fitted): the joint keeps the one it has.
    const std::vector<double>& first = walked.front().request_deg;
    const auto [low, high] = std::minmax_element(first.begin(), first.end());
    if (*high - *low < kWalkFitMinSwingDeg) return;
    try {
      std::vector<JointRecording> recordings =
          StepTestsForFit(step_tests[j], config.identify, warmup);
      // Synchronous averaging (kWalkFitPlayedCycles): each walk's recorded steps' mean cycle,
      // played after the fit's warm-up, weighted by the steps over the cycles played.
      for (const JointRecording& walk : walked) {
        recordings.push_back(AverageCycles(walk, r.period, warmup, kWalkFitPlayedCycles));
      }
      const JointModelParams fitted = IdentifyJointModel(recordings, search).params;
      ValidateJointModelParams(fitted);
      // The fit keeps v_max <= kMaxFittedSpeedRatio theta_0, so eq. 3 settles under every
      // cycle (SettlesOnEveryCycle); the modes that use it need its cyclic steady state under
      // the requests it was fitted to and under the desired angles, reached within
      // CyclicSteadyState's cycles (a contraction too slow for them throws: the joint keeps its
      // model).
      std::vector<double> desired(r.context.desired.size());
      for (size_t t = 0; t < desired.size(); ++t) desired[t] = r.context.desired[t][j];
      std::vector<double> played(r.period);
      (void)CyclicSteadyState(fitted, desired);
      for (const JointRecording& walk : walked) {
        for (int t = 0; t < r.period; ++t) played[t] = walk.request_deg[t];
        (void)CyclicSteadyState(fitted, played);
      }
      models[j] = fitted;
    } catch (const std::invalid_argument&) {
      // Not identifiable from these recordings: the joint keeps the model it has.
    } catch (const std::runtime_error&) {
      // The fitted model does not settle (CyclicSteadyState): the joint keeps the model it has.
    }
  });
  return models;
}

}  // namespace

const ControllerContext& ContextFor(const TrackResult& r, const ControllerSpec& spec) {
  return UsesWalkModels(spec) && r.walk_context ? *r.walk_context : r.context;
}

const ControllerContext& ContextFor(const TrackResult& r, const ModeRun& run) {
  return run.external.empty() ? ContextFor(r, run.spec) : r.context;
}

ControllerModeInfo ModeInfo(const ModeRun& run) {
  if (run.external.empty()) return ModeOf(run.spec);
  return ControllerModeInfo{.name = run.external,
                            .label = run.external,
                            .feed_forward = false,
                            .follows_approximation = false,
                            .searchable = false,
                            .searchable_by_lead = false,
                            .search_file = "",
                            .config_section = "",
                            .estimates_model = false};
}

long long PlannedTrackTicks(const ExperimentConfig& config, size_t external_modes) {
  const long long per_run =
      (static_cast<long long>(config.track.warmup_steps) + config.track.steps) *
      config.track.t_step_ticks;
  const long long room = std::numeric_limits<long long>::max() - config.planned_ticks;
  if (per_run > 0 && external_modes > static_cast<unsigned long long>(room / per_run)) {
    return std::numeric_limits<long long>::max();
  }
  return config.planned_ticks + static_cast<long long>(external_modes) * per_run;
}

namespace {

// One run of `controller` on a plant of its own (the same for every mode, registered or
// external): warm-up, measured steps and the plant's changes, and the foot's error.
ModeRun RunController(const ExperimentConfig& config, const TrackResult& r,
                      JointController& controller, ModeRun run) {
  const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
  run.run = RunTracking(*plant, controller, r.context.desired, config.track.warmup_steps,
                        config.track.steps, config.plant_changes);
  run.foot_error_cm = FootErrorsCm(run.run, r.desired, r.robot.geometry);
  return run;
}

ModeRun RunMode(const ExperimentConfig& config, const TrackResult& r, const ControllerSpec& spec) {
  const std::unique_ptr<JointController> controller = MakeController(spec, ContextFor(r, spec));
  return RunController(config, r, *controller, ModeRun{spec, {}, {}, {}});
}

// A finished run: its ticks counted, then to the sink when there is one (so that only one run
// is held at a time), else into r.runs.
void KeepRun(const ExperimentConfig& config, const ModeRunSink& sink, TrackResult& r, ModeRun run) {
  r.plant_ticks += RunTicks(config, r.period);
  sink ? sink(r, std::move(run)) : r.runs.push_back(std::move(run));
}

// A candidate's score alone: RunMode's foot L2 without keeping the run (memory O(steps)).
double ScoreMode(const ExperimentConfig& config, const TrackResult& r, const ControllerSpec& spec) {
  const std::unique_ptr<JointController> controller = MakeController(spec, ContextFor(r, spec));
  const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
  return TrackingFootL2Cm(*plant, *controller, r.desired, r.robot.geometry,
                          config.track.warmup_steps, config.track.steps, config.plant_changes);
}

// The paper's procedure: every candidate on its own plant, in parallel, keeping only its score.
std::vector<double> ScoreEveryCandidate(const ExperimentConfig& config, TrackResult& r,
                                        const ModeSearch& search) {
  std::vector<double> scores(search.candidates.size());
  ParallelFor(static_cast<int>(search.candidates.size()), config.threads,
              [&](int k) { scores[k] = ScoreMode(config, r, search.candidates[k]); });
  r.plant_ticks += static_cast<long>(search.candidates.size()) * RunTicks(config, r.period);
  return scores;
}

// One run of the lead-0 candidate, one step longer than the measured steps, scores every
// candidate: candidate k's measured tick t is taken as that run's tick t + k (the plant is
// time-invariant, so in steady state requesting R_0(t + k) answers with M_0(t + k)).
std::vector<double> ScoreFromLeadZeroRun(const ExperimentConfig& config, TrackResult& r,
                                         const ModeSearch& search) {
  const auto base = std::find_if(search.candidates.begin(), search.candidates.end(),
                                 [](const ControllerSpec& c) { return RequestLeadTicks(c) == 0; });
  assert(base != search.candidates.end() && "a lead-searched mode has a lead-0 candidate");
  const std::unique_ptr<JointController> controller = MakeController(*base, ContextFor(r, *base));
  const std::unique_ptr<Plant> plant = MakePlant(config, r.robot);
  const std::vector<Eigen::Vector3d> foot_mm =
      TrackingFootPathMm(*plant, *controller, r.context.desired, r.robot.geometry,
                         config.track.warmup_steps, config.track.steps + 1);
  r.plant_ticks += RunTicks(config, r.period) + r.period;
  const auto recorded = static_cast<size_t>(r.steps) * r.period;
  std::vector<double> scores;
  std::vector<double> errors(recorded);
  for (const ControllerSpec& candidate : search.candidates) {
    const int lead = *RequestLeadTicks(candidate);
    assert(lead >= 0 && lead <= r.period && "a lead fits in the extra step");
    for (size_t t = 0; t < recorded; ++t) {
      errors[t] = (foot_mm[t + lead] - r.desired.foot_mm[t % r.period]).norm() / 10.0;
    }
    scores.push_back(MeanFootL2Cm(errors, r.period));
  }
  return scores;
}

}  // namespace

double MeanFootL2Cm(const std::vector<double>& foot_error_cm, int period) {
  std::vector<double> per_step;
  for (size_t s = 0; s * period < foot_error_cm.size(); ++s) {
    per_step.push_back(Rms(std::span<const double>(foot_error_cm).subspan(s * period, period)));
  }
  return MeanAndStd(per_step).mean;
}

namespace {

using StepTests = std::array<std::vector<JointRecording>, kLegJoints>;

// The run's robot, desired cycle and sizes; bad plant input fails here, before any run.
TrackResult PrepareTrack(const ExperimentConfig& config) {
  TrackResult r;
  r.robot = LoadRobot(config.sim.urdf_path);
  r.desired = LoadDesiredMotion(config.track, r.robot.geometry);
  r.period = static_cast<int>(r.desired.angles_deg.size());
  r.steps = config.track.steps;
  if (config.sim.stand.enabled && config.plant == PlantKind::kSim) {
    r.stand_weight_n = (config.sim.stand.load_kg + r.robot.leg_mass_kg) * 9.81;
  }
  MakePlant(config, r.robot);
  return r;
}

// What identify finds on `plant` (the config, or the config after some of its changes) from
// measured step `from_step` on. The first identification's step-test recordings go to
// `step_tests` (for the walk-fitted models).
PlantIdentification IdentifyPlant(const ExperimentConfig& config, const ExperimentConfig& plant,
                                  int from_step, TrackResult& r, StepTests& step_tests) {
  PlantIdentification p{from_step, {}};
  const auto identified = IdentifyLeg(plant, r.robot);
  r.plant_ticks += kLegJoints * static_cast<long>(plant.identify.theta_test_deg.size()) *
                   StepTestTicks(plant.identify);
  for (int j = 0; j < kLegJoints; ++j) {
    p.joints[j] = identified[j].fit;
    // Pooled with the walk only when they gave the models (a model given as model.* has no
    // step tests of its own; an estimating mode's identification is for comparison only).
    if (!config.model && from_step == -config.track.warmup_steps && step_tests[j].empty()) {
      for (const StepTestRun& run : identified[j].runs) step_tests[j].push_back(run.recording);
    }
  }
  return p;
}

// r.plant_models: the plant identified before any change when the models are to be identified
// or an estimating mode is compared, and after each change for the comparison.
void IdentifyPlants(const ExperimentConfig& config, bool compare_estimates, TrackResult& r,
                    StepTests& step_tests) {
  if (compare_estimates || !config.model) {
    r.plant_models.push_back(
        IdentifyPlant(config, config, -config.track.warmup_steps, r, step_tests));
  }
  if (compare_estimates) {
    for (size_t i = 0; i < config.plant_changes.size(); ++i) {
      r.plant_models.push_back(IdentifyPlant(config, ConfigAfterChanges(config, i + 1),
                                             config.plant_changes[i].at_step, r, step_tests));
    }
  }
}

// A model the user gives is used as it is; one under which eq. 3 never settles on the walk
// (v_max at least 2 theta_0 can overshoot every tick, SettlesOnEveryCycle) is no model of a
// joint: the user's error. (Identified models always settle, kMaxFittedSpeedRatio.)
void CheckGivenModelSettles(const ExperimentConfig& config, const TrackResult& r) {
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> desired(r.period);
    for (int t = 0; t < r.period; ++t) desired[t] = r.desired.angles_deg[t][j];
    try {
      (void)CyclicSteadyState(*config.model, desired);
    } catch (const std::runtime_error&) {
      throw InputError("model: eq. 3 under this model never settles on the desired walk (" +
                       std::string(kLegJointNames[j]) + "; v_max " +
                       FormatDouble(config.model->v_max_deg_per_tick) +
                       " deg/tick against theta0 " + FormatDouble(config.model->theta0_deg) +
                       " deg)");
    }
  }
}

// Each joint's model: the config's model.* when given, else the one identified on the plant
// (r.plant_models' first).
std::array<JointModelParams, kLegJoints> TrackModels(const ExperimentConfig& config,
                                                     TrackResult& r) {
  std::array<JointModelParams, kLegJoints> models;
  if (config.model) {
    models.fill(*config.model);
    CheckGivenModelSettles(config, r);
  } else {
    for (int j = 0; j < kLegJoints; ++j) models[j] = r.plant_models.front().joints[j].params;
    r.models_identified = true;
  }
  return models;
}

// r.context, and r.walk_context when a mode UsesWalkModels.
void MakeContexts(const ExperimentConfig& config,
                  const std::array<JointModelParams, kLegJoints>& models,
                  const StepTests& step_tests, TrackResult& r) {
  // The approximations P, fitted once on first use: model_based follows them, every trace shows
  // them (a context whose modes follow none and whose traces are not written never fits them).
  try {
    r.context =
        MakeControllerContext(r.desired.angles_deg, models, r.robot.geometry, config.pwl_segments);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  r.context.warmup_steps = config.track.warmup_steps;
  if (std::none_of(config.controllers.begin(), config.controllers.end(),
                   [](const ControllerSpec& spec) { return UsesWalkModels(spec); })) {
    return;
  }
  try {
    const std::vector<DesiredCycle> walks{ModelBasedRequestCycle(r.context, CmMethod::kExact)};
    r.walk_context =
        MakeControllerContext(r.desired.angles_deg, FitModelsToWalk(config, r, step_tests, walks),
                              r.robot.geometry, config.pwl_segments);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  r.walk_context->warmup_steps = config.track.warmup_steps;
  // The same desired cycle and segments: its P shares the first context's normal equations.
  std::array<double, kLegJoints> walk_v_max{};
  for (int j = 0; j < kLegJoints; ++j) {
    walk_v_max[j] = r.walk_context->models[j].v_max_deg_per_tick;
  }
  r.walk_context->approximations = r.context.approximations->ForOtherModels(walk_v_max);
}

// r.floor_deg: each joint's floor under its model.
void FloorTrajectories(const std::array<JointModelParams, kLegJoints>& models, TrackResult& r) {
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> desired(r.period);
    for (int t = 0; t < r.period; ++t) desired[t] = r.context.desired[t][j];
    r.floor_deg[j] = FloorTrajectory(desired, models[j]);
  }
}

// A searchable mode's candidates, each scored as track.search_shift says; the best by foot L2.
ModeSearch SearchMode(const ExperimentConfig& config, TrackResult& r, const ControllerSpec& spec) {
  ModeSearch search;
  search.candidates = SearchCandidates(spec, ContextFor(r, spec));
  search.scored_from_one_run =
      config.track.search_shift == ShiftSearch::kShiftedRun && ModeOf(spec).searchable_by_lead &&
      config.plant_changes.empty();  // a plant that changes mid-run is not time-invariant
  search.foot_l2_cm = search.scored_from_one_run ? ScoreFromLeadZeroRun(config, r, search)
                                                 : ScoreEveryCandidate(config, r, search);
  const auto best = std::min_element(search.foot_l2_cm.begin(), search.foot_l2_cm.end()) -
                    search.foot_l2_cm.begin();
  search.best = search.candidates[best];
  return search;
}

// Every configured mode's run, in the config's order (a searched mode's best candidate's).
void RunModes(const ExperimentConfig& config, const ModeRunSink& sink, TrackResult& r) {
  for (const ControllerSpec& spec : config.controllers) {
    if (config.track.search_shift == ShiftSearch::kNone || !ModeOf(spec).searchable) {
      KeepRun(config, sink, r, RunMode(config, r, spec));
      continue;
    }
    ModeSearch search = SearchMode(config, r, spec);
    // The best candidate is run on its own (same bits: a run depends only on its spec and the
    // seed), so its row in Table 2 is a real run whichever way it was found.
    KeepRun(config, sink, r, RunMode(config, r, search.best));
    r.searches.push_back(std::move(search));
  }
}

// Each external mode's run, after the configured ones, with the step tests' (or given) models.
void RunExternalModes(const ExperimentConfig& config, const ModeRunSink& sink,
                      std::span<const ExternalMode> external, TrackResult& r) {
  for (const ExternalMode& mode : external) {
    const std::unique_ptr<JointController> controller = mode.make(r.context);
    if (!controller) {
      throw InputError("controller '" + mode.name + "': its make function returned no controller");
    }
    KeepRun(config, sink, r, RunController(config, r, *controller, ModeRun{{}, {}, {}, mode.name}));
  }
}

bool IsNameChar(char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_'; }

// The external modes as ExternalMode documents them, and the run's ticks with theirs, before
// anything runs.
void CheckExternalModes(const ExperimentConfig& config, std::span<const ExternalMode> external) {
  for (size_t i = 0; i < external.size(); ++i) {
    const std::string& name = external[i].name;
    auto bad = [&name](const std::string& what) {
      throw InputError("controller '" + name + "': " + what);
    };
    if (name.empty() || !std::all_of(name.begin(), name.end(), IsNameChar)) {
      bad("a name is letters a-z, digits and _ (at least one)");
    }
    if (name.size() > kMaxExternalModeNameChars) {
      bad("a name of " + std::to_string(name.size()) + " characters, more than " +
          std::to_string(kMaxExternalModeNameChars));
    }
    for (const ControllerModeInfo& mode : ControllerModes()) {
      if (mode.name == name) bad("the name of a registered mode");
    }
    if (name == "floor") bad("the name of the foot table's row of the floor");
    for (size_t k = 0; k < i; ++k) {
      if (external[k].name == name) bad("the name of another external mode");
    }
    if (!external[i].make) bad("no make function");
  }
  const long long total = PlannedTrackTicks(config, external.size());
  if (!external.empty() && total > kMaxTotalTicks) {
    throw InputError("the run would simulate " + std::to_string(total) + " ticks with its " +
                     std::to_string(external.size()) + " external modes, more than " +
                     std::to_string(kMaxTotalTicks) + "; run fewer steps or fewer modes");
  }
}

}  // namespace

TrackResult RunTrackExperiment(const ExperimentConfig& config, const ModeRunSink& sink,
                               std::span<const ExternalMode> external) {
  CheckExternalModes(config, external);
  TrackResult r = PrepareTrack(config);
  // A mode that estimates the model is compared with what identify finds on the plant before
  // and after each change.
  const bool compare_estimates =
      std::any_of(config.controllers.begin(), config.controllers.end(),
                  [](const ControllerSpec& spec) { return ModeOf(spec).estimates_model; });
  StepTests step_tests;
  IdentifyPlants(config, compare_estimates, r, step_tests);
  const std::array<JointModelParams, kLegJoints> models = TrackModels(config, r);
  if (!compare_estimates) r.plant_models.clear();
  MakeContexts(config, models, step_tests, r);
  FloorTrajectories(models, r);
  RunModes(config, sink, r);
  RunExternalModes(config, sink, external, r);
  return r;
}

}  // namespace leglab::experiments
