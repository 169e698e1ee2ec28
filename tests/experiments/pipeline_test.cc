// The experiment pipeline on its seams: any plant behind the Plant interface. (Thread counts:
// programs_test.cc compares the output bytes of --threads 1 and 2.)
#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"
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

// A searched candidate's score kept without its run is the score of the kept run, bit for bit,
// on the noisy sim plant, for a feed-forward, a model-based and a learning mode.
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
      MakeControllerContext(desired.angles_deg, models, robot.geometry.limits, 8);
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
  EXPECT_EQ(Table2Json(*streamed), Table2Json(whole));
}

}  // namespace
}  // namespace leglab::experiments
