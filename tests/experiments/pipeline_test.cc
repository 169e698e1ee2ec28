// The experiment pipeline on its seams: any plant behind the Plant interface. (Thread counts:
// programs_test.cc compares the output bytes of --threads 1 and 2.)
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
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

}  // namespace
}  // namespace leglab::experiments
