// The experiment pipeline on its seams: any plant behind the Plant interface. (Thread counts:
// programs_test.cc compares the output bytes of --threads 1 and 2.)
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"

namespace leglab::experiments {
namespace {

const std::string kConfigs = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";

// On the ideal plant the data are the model's own, without noise: identification must give
// the plant's parameters back (a model unlike the paper's, to show it is not the default).
TEST(Pipeline, IdentifyOnTheModelPlantRecoversItsModel) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "identify.yaml",
      {"plant=model",
       "plant_model={v_max_deg_per_tick: 3.0, theta0_deg: 5.0, lag_ticks: 5, accel_ticks: 4}",
       "identify.record_cycles=2", "identify.settle_cycles=2"});
  const auto joints = IdentifyLeg(config, LoadRobot(config.sim.urdf_path));
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = joints[j].fit.params;
    EXPECT_EQ(p.lag_ticks, 5) << kLegJointNames[j];
    EXPECT_EQ(p.accel_ticks, 4) << kLegJointNames[j];
    EXPECT_NEAR(p.v_max_deg_per_tick, 3.0, 1e-4) << kLegJointNames[j];
    EXPECT_NEAR(p.theta0_deg, 5.0, 1e-3) << kLegJointNames[j];
    EXPECT_LT(joints[j].fit.rms_residual_deg, 1e-4) << kLegJointNames[j];
  }
}

// Direct requests on the ideal plant: after the warm-up every measured step is the model's
// cyclic steady state under the desired cycle, computed here straight from eq. 3.
TEST(Pipeline, TrackOnTheModelPlantIsTheModelsSteadyState) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"plant=model", "controller.modes=[direct]", "warmup_steps=12", "steps=2",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  const TrackResult r = RunTrackExperiment(config);
  ASSERT_EQ(r.runs.size(), 1u);
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> cycle(r.period);
    for (int t = 0; t < r.period; ++t) cycle[t] = r.context.desired[t][j];
    const std::vector<double> steady = CyclicSteadyState(config.plant_model, cycle);
    for (size_t i = 0; i < r.runs[0].run.measured_deg.size(); ++i) {
      ASSERT_NEAR(r.runs[0].run.measured_deg[i][j], steady[i % r.period], 1e-6)
          << kLegJointNames[j] << " tick " << i;
    }
  }
}

// The walk-fitted models (optimal.model: walk, as track.yaml ships) on the ideal plant: the walk's
// data and the step tests' are the plant model's own, without noise, so the pooled fit must give
// that model back, as identification does above; the modes that do not ask for it run with the
// step tests' context.
TEST(Pipeline, TheWalkFitOnTheModelPlantRecoversItsModel) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"plant=model",
       "plant_model={v_max_deg_per_tick: 3.0, theta0_deg: 5.0, lag_ticks: 5, accel_ticks: 4}",
       "identify.record_cycles=2", "identify.settle_cycles=2", "controller.modes=[direct, optimal]",
       "optimal.model=walk", "warmup_steps=1", "steps=1"});
  const TrackResult r = RunTrackExperiment(config);
  ASSERT_TRUE(r.walk_context.has_value());
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = r.walk_context->models[j];
    EXPECT_EQ(p.lag_ticks, 5) << kLegJointNames[j];
    EXPECT_EQ(p.accel_ticks, 4) << kLegJointNames[j];
    EXPECT_NEAR(p.v_max_deg_per_tick, 3.0, 1e-4) << kLegJointNames[j];
    EXPECT_NEAR(p.theta0_deg, 5.0, 1e-3) << kLegJointNames[j];
  }
  ASSERT_EQ(r.runs.size(), 2u);
  EXPECT_EQ(&ContextFor(r, r.runs[0].spec), &r.context);
  EXPECT_EQ(&ContextFor(r, r.runs[1].spec), &*r.walk_context);
}

// A servo with a high gain for its top speed (150 deg/s, 72 per s, damping 0.3) runs at top
// speed until within a fraction of a degree of its request: the paper's model fits it best
// with v_max above 2 theta_0, which has no cyclic steady state (before the fit was bounded,
// kMaxFittedSpeedRatio, 21 of 192 such plants stopped track with "internal error: ... the model
// oscillates"). Now the step tests' and the walk's models settle, and optimal and ILC run.
TEST(Pipeline, AServoThatOvershootsStillGetsModelsThatSettle) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"servo.max_speed_deg_s=150", "servo.gain_per_s=72", "servo.damping=0.3",
       "controller.modes=[model_based, optimal, ilc]", "warmup_steps=1", "steps=1"});
  const TrackResult r = RunTrackExperiment(config);
  ASSERT_TRUE(r.walk_context.has_value());
  for (int j = 0; j < kLegJoints; ++j) {
    for (const JointModelParams& p : {r.context.models[j], r.walk_context->models[j]}) {
      EXPECT_LE(p.v_max_deg_per_tick, kMaxFittedSpeedRatio * p.theta0_deg) << kLegJointNames[j];
      EXPECT_TRUE(SettlesOnEveryCycle(p)) << kLegJointNames[j];
    }
  }
  ASSERT_EQ(r.runs.size(), 3u);
}

// The two ways of searching the time shift, on a config small enough for a test.
struct ShiftSearches {
  TrackResult shifted, exhaustive;
};
ShiftSearches RunBothSearches(std::vector<std::string> overrides) {
  overrides.insert(overrides.end(), {"controller.modes=[time_shift]", "track.search_shift=true"});
  ShiftSearches both;
  both.shifted = RunTrackExperiment(LoadExperimentConfig(kConfigs + "track.yaml", overrides));
  overrides.back() = "track.search_shift=exhaustive";
  both.exhaustive = RunTrackExperiment(LoadExperimentConfig(kConfigs + "track.yaml", overrides));
  return both;
}

// On the ideal plant (time-invariant, no noise) in steady state, requesting D(t + k) answers
// with the direct run's response k ticks later exactly: every candidate's score from the one
// run equals its score from its own run, and the search costs one run plus one step instead of
// T runs (ticks counted here from the config, not from the code).
TEST(Pipeline, ShiftSearchFromOneRunIsExactOnATimeInvariantPlant) {
  const ShiftSearches both = RunBothSearches(
      {"plant=model", "warmup_steps=12", "steps=2",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  ASSERT_EQ(both.shifted.searches.size(), 1u);
  ASSERT_EQ(both.exhaustive.searches.size(), 1u);
  const ModeSearch& fast = both.shifted.searches[0];
  const ModeSearch& slow = both.exhaustive.searches[0];
  EXPECT_TRUE(fast.scored_from_one_run);
  EXPECT_FALSE(slow.scored_from_one_run);
  const long period = both.shifted.period;
  ASSERT_EQ(fast.foot_l2_cm.size(), static_cast<size_t>(period));
  ASSERT_EQ(slow.foot_l2_cm.size(), static_cast<size_t>(period));
  for (long k = 0; k < period; ++k) {
    EXPECT_NEAR(fast.foot_l2_cm[k], slow.foot_l2_cm[k], 1e-9) << "k = " << k;
  }
  EXPECT_EQ(fast.best, slow.best);
  const long run_ticks = (12 + 2) * period;
  EXPECT_EQ(both.shifted.plant_ticks, (run_ticks + period) + run_ticks);
  EXPECT_EQ(both.exhaustive.plant_ticks, period * run_ticks + run_ticks);
}

// On the simulated leg (noise, physics) the one-run scores pick the same shift as the paper's
// exhaustive search and differ from each run's own score by less than the sensor noise can
// move the foot on one tick (reach x noise in radians, a bound on a mean of per-step RMS).
TEST(Pipeline, ShiftSearchFromOneRunAgreesWithTheExhaustiveSearchOnTheSim) {
  const ShiftSearches both = RunBothSearches(
      {"warmup_steps=3", "steps=4",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  const ExperimentConfig config = LoadExperimentConfig(kConfigs + "track.yaml");
  const LegGeometry& g = both.shifted.robot.geometry;
  const double reach_cm = (g.upper_leg_mm.norm() + g.lower_leg_mm.norm()) / 10.0;
  const double noise_bound_cm = reach_cm * config.sim.sensor.noise_deg * M_PI / 180.0;
  const ModeSearch& fast = both.shifted.searches.at(0);
  const ModeSearch& slow = both.exhaustive.searches.at(0);
  EXPECT_EQ(fast.best, slow.best);
  for (size_t k = 0; k < slow.foot_l2_cm.size(); ++k) {
    EXPECT_NEAR(fast.foot_l2_cm[k], slow.foot_l2_cm[k], noise_bound_cm) << "k = " << k;
  }
  // The reported run is the best candidate's own run either way: the same bits.
  EXPECT_EQ(both.shifted.runs.at(0).run.measured_deg, both.exhaustive.runs.at(0).run.measured_deg);
}

// A plant that counts its ticks and notes when its settings change.
class CountingPlant final : public Plant {
 public:
  void Reset(const LegAngles& pose_deg) override { reading_ = {pose_deg, pose_deg, pose_deg}; }
  const PlantReading& Tick(const LegAngles& request_deg) override {
    ++ticks_;
    reading_ = {request_deg, request_deg, request_deg};
    return reading_;
  }
  const PlantReading& Read() const override { return reading_; }
  std::string_view name() const override { return "counting"; }
  void ChangeSettings(std::span<const PlantSetting> settings) override {
    changes_.emplace_back(ticks_, settings[0].key);
  }
  std::vector<std::pair<long, std::string>> changes_;

 private:
  long ticks_ = 0;
  PlantReading reading_;
};

class Still final : public JointController {
 public:
  LegAngles Update(long /*tick*/, const LegAngles& measured_deg) override { return measured_deg; }
  std::string_view name() const override { return "still"; }
};

// Measured step N starts after (warm-up + N) whole steps of ticks.
TEST(Pipeline, PlantChangesApplyRightBeforeTheirMeasuredStep) {
  CountingPlant plant;
  Still controller;
  const DesiredCycle desired(10, LegAngles{1.0, 2.0, 3.0});
  const std::vector<PlantChange> changes = {{0, {{"a", 1.0}}}, {4, {{"b", 2.0}}}};
  RunTracking(plant, controller, desired, /*warmup_steps=*/3, /*steps=*/6, changes);
  ASSERT_EQ(plant.changes_.size(), 2u);
  EXPECT_EQ(plant.changes_[0], (std::pair<long, std::string>{30, "a"}));
  EXPECT_EQ(plant.changes_[1], (std::pair<long, std::string>{70, "b"}));
}

// On the model plant a change of its lag at step 1 shows exactly there: the direct requests'
// measured steps equal an unchanged run's before step 1 and differ from its first tick on.
TEST(Pipeline, AChangeMovesTheModelPlantAtTheNamedStep) {
  const std::vector<std::string> common = {
      "plant=model", "controller.modes=[direct]", "warmup_steps=1", "steps=3",
      "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"};
  std::vector<std::string> changed = common;
  changed.emplace_back("plant_changes=[{at_step: 1, set: {plant_model.lag_ticks: 6}}]");
  const TrackResult a = RunTrackExperiment(LoadExperimentConfig(kConfigs + "track.yaml", common));
  const TrackResult b = RunTrackExperiment(LoadExperimentConfig(kConfigs + "track.yaml", changed));
  const auto& ma = a.runs[0].run.measured_deg;
  const auto& mb = b.runs[0].run.measured_deg;
  const auto period = static_cast<size_t>(a.period);
  for (size_t t = 0; t < period; ++t) EXPECT_EQ(ma[t], mb[t]) << t;
  EXPECT_NE(ma[period], mb[period]);
}

// A plant that changes mid-run is not time-invariant: the shift search then runs every shift
// on its own (T runs of warm-up + steps, plus the best one's), not one run shifted.
TEST(Pipeline, PlantChangesMakeTheShiftSearchExhaustive) {
  const TrackResult r = RunTrackExperiment(LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"plant=model", "controller.modes=[time_shift]", "warmup_steps=1", "steps=2",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}",
       "plant_changes=[{at_step: 1, set: {plant_model.lag_ticks: 6}}]"}));
  ASSERT_EQ(r.searches.size(), 1u);
  EXPECT_FALSE(r.searches[0].scored_from_one_run);
  const long run_ticks = 3L * r.period;
  EXPECT_EQ(r.plant_ticks, r.period * run_ticks + run_ticks);
}

// A searched candidate's score kept without its run is the score of the kept run, bit for bit,
// on the noisy sim plant, for a feed-forward, a model-based and a learning mode.
// desired.locus.skew and body_pitch_deg place the locus as worked out by hand: the
// touch-down point (t = 0, the front end of the flat bottom, 24.465 mm ahead of the centre) in
// the level frame at the left front shoulder (59.5, 59.2, 0) is (49 + 24.465, 28 + 0.5 *
// 24.465, -90) mm; a body pitched 10 deg nose down sees a level (x, z) at (x cos 10 - z sin
// 10, x sin 10 + z cos 10) (level ground below the shoulder appears ahead of it).
TEST(Pipeline, SkewAndPitchPlaceTheLocusAsWorkedByHand) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml", {"desired.locus.ground_below_shoulder_mm=90",
                                "desired.locus.skew=0.5", "desired.locus.body_pitch_deg=10"});
  const Robot robot = LoadRobot(config.sim.urdf_path);
  const DesiredMotion d = LoadDesiredMotion(config.track, robot.geometry);
  const double x = 49.0 + 24.465, y = 28.0 + 0.5 * 24.465, z = -90.0;
  const double c = std::cos(10.0 * M_PI / 180.0), s = std::sin(10.0 * M_PI / 180.0);
  const Eigen::Vector3d expected(59.5 + x * c - z * s, 59.2 + y, x * s + z * c);
  EXPECT_NEAR((d.foot_mm[0] - expected).norm(), 0.0, 1e-9) << d.foot_mm[0].transpose();
  // The same numbers: (147.477, 99.433, -75.876) mm.
  EXPECT_NEAR(d.foot_mm[0].x(), 147.4772, 1e-3);
  EXPECT_NEAR(d.foot_mm[0].y(), 99.4325, 1e-3);
  EXPECT_NEAR(d.foot_mm[0].z(), -75.8756, 1e-3);
  // Without the two keys the locus is track.yaml's, bit for bit, whatever else is set.
  const ExperimentConfig plain = LoadExperimentConfig(kConfigs + "track.yaml");
  const ExperimentConfig zero = LoadExperimentConfig(
      kConfigs + "track.yaml", {"desired.locus.skew=0", "desired.locus.body_pitch_deg=0"});
  EXPECT_EQ(LoadDesiredMotion(plain.track, robot.geometry).foot_mm,
            LoadDesiredMotion(zero.track, robot.geometry).foot_mm);
}

// track_stand.yaml walks the matched swing (desired.locus.swing_end_speed_fraction 1, against
// the foot's slip on the stand): the foot, placed on the front leg, leaves and meets the ground
// moving backward at the belt's speed, which the loader derives from the locus alone (length_mm
// over the stance's time). On a step of 880 ticks a one-sided difference misses the end speed by at
// most (pi^2 / 2 + 6) / (2 x 440) = 1.24 % (trajectories_test); the belt then runs at a tenth of
// the shipped step's speed. Every tick is reachable within the joint limits, at 88 ticks too.
TEST(Pipeline, TheStandWalkMeetsTheBeltAtItsSpeed) {
  for (const int ticks : {88, 880}) {
    // The slow lift-off's ramp is counted in ticks: ten times as many on the finer step.
    const ExperimentConfig config = LoadExperimentConfig(
        kConfigs + "track_stand.yaml",
        {"track.t_step_ticks=" + std::to_string(ticks),
         "desired.locus.liftoff_ramp_ticks=" + std::to_string(ticks / 88 * 5)});
    EXPECT_EQ(config.track.locus.shape.swing_end_speed_fraction, 1.0);
    const Robot robot = LoadRobot(config.sim.urdf_path);
    const DesiredMotion d = LoadDesiredMotion(config.track, robot.geometry);
    ASSERT_EQ(d.foot_mm.size(), static_cast<size_t>(ticks));
    for (const LegAngles& q : d.angles_deg) {
      for (int j = 0; j < kLegJoints; ++j) {
        EXPECT_GE(q[j] * M_PI / 180.0, robot.geometry.limits[j].lower_rad - 1e-9) << j;
        EXPECT_LE(q[j] * M_PI / 180.0, robot.geometry.limits[j].upper_rad + 1e-9) << j;
      }
    }
    if (ticks != 880) continue;
    const double belt_mm_per_tick = config.sim.stand.belt_speed_mm_per_s * 0.008;
    EXPECT_NEAR(belt_mm_per_tick, 48.93 / 440.0, 1e-12);
    const double bound = (M_PI * M_PI / 2.0 + 6.0) / 880.0;
    // Lift-off (tick 440, the flat bottom's back end) and touch-down (tick 879 to tick 0).
    EXPECT_NEAR((d.foot_mm[440].x() - d.foot_mm[441].x()) / belt_mm_per_tick, 1.0, bound);
    EXPECT_NEAR((d.foot_mm[879].x() - d.foot_mm[0].x()) / belt_mm_per_tick, 1.0, bound);
    // The plain half-ellipse's speed there is near 0.
    const ExperimentConfig plain =
        LoadExperimentConfig(kConfigs + "track_stand.yaml",
                             {"track.t_step_ticks=880", "desired.locus.swing_end_speed_fraction=0",
                              "desired.locus.liftoff_ramp_mm=0"});
    const DesiredMotion p = LoadDesiredMotion(plain.track, robot.geometry);
    EXPECT_LT(std::abs(p.foot_mm[440].x() - p.foot_mm[441].x()) / belt_mm_per_tick, 0.01);
  }
}

TEST(Pipeline, AScoreWithoutTheRunIsTheRunsScore) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"warmup_steps=1", "steps=2", "controller.modes=[direct, model_based, ilc]",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  const Robot robot = LoadRobot(config.sim.urdf_path);
  const DesiredMotion desired = LoadDesiredMotion(config.track, robot.geometry);
  std::array<JointModelParams, kLegJoints> models;
  models.fill(*config.model);
  const ControllerContext context =
      MakeControllerContext(desired.angles_deg, models, robot.geometry, 8);
  for (const ControllerSpec& spec : config.controllers) {
    const auto kept_controller = MakeController(spec, context);
    const auto kept_plant = MakePlant(config, robot);
    const TrackingRun run = RunTracking(*kept_plant, *kept_controller, desired.angles_deg, 1, 2);
    const double kept = MeanFootL2Cm(FootErrorsCm(run, desired, robot.geometry),
                                     static_cast<int>(desired.angles_deg.size()));
    const auto controller = MakeController(spec, context);
    const auto plant = MakePlant(config, robot);
    EXPECT_EQ(TrackingFootL2Cm(*plant, *controller, desired, robot.geometry, 1, 2), kept)
        << ModeOf(spec).name;
  }
}

// track's main takes the runs one at a time (a sink): the tables are those of the kept runs.
TEST(Pipeline, RunsTakenOneAtATimeGiveTheSameTable) {
  const ExperimentConfig config = LoadExperimentConfig(
      kConfigs + "track.yaml",
      {"plant=model", "controller.modes=[direct, time_shift, ilc]", "warmup_steps=1", "steps=2",
       "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"});
  const Table2 whole = ComputeTable2(RunTrackExperiment(config));
  std::optional<Table2> streamed;
  int runs = 0;
  const TrackResult r = RunTrackExperiment(config, [&](const TrackResult& result, ModeRun&& run) {
    if (!streamed) streamed = BeginTable2(result);
    AddModeToTable2(*streamed, run, result);
    ++runs;
  });
  EXPECT_TRUE(r.runs.empty());
  EXPECT_EQ(runs, 3);
  ASSERT_TRUE(streamed);
  EXPECT_EQ(Table2Json(*streamed, config), Table2Json(whole, config));
}

// The plan (the progress display's 100 % and the run-size budget) counts the ticks that run:
// for every way of searching the time shift, with and without identification and the walk
// fit, it is exactly the plant ticks the experiment ran (counted by the experiment as it runs
// them, TrackResult::plant_ticks).
TEST(Pipeline, ThePlannedTicksAreTheTicksThatRun) {
  const std::string model =
      "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, "
      "accel_ticks: 6}";
  const std::vector<std::vector<std::string>> cases = {
      {"controller.modes=[direct, time_shift]", "track.search_shift=true"},
      {"controller.modes=[time_shift]", "track.search_shift=exhaustive", model},
      {"controller.modes=[time_shift]", "track.search_shift=false", model},
      {"controller.modes=[model_based, optimal]", model},
      {"controller.modes=[direct, time_shift]", model,
       "plant_changes=[{at_step: 1, set: {plant_model.lag_ticks: 6}}]"},
  };
  for (std::vector<std::string> overrides : cases) {
    overrides.insert(overrides.end(), {"plant=model", "warmup_steps=1", "steps=2",
                                       "identify.settle_cycles=1", "identify.record_cycles=2"});
    const ExperimentConfig config = LoadExperimentConfig(kConfigs + "track.yaml", overrides);
    const TrackResult r = RunTrackExperiment(config);
    EXPECT_EQ(config.planned_ticks, r.plant_ticks) << overrides.front() << " " << overrides[1];
  }
}

}  // namespace
}  // namespace leglab::experiments
