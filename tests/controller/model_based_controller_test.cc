#include "leglab/controller/model_based_controller.h"

#include "leglab/controller/direct_controller.h"
#include "leglab/model/joint_model_plant.h"
#include "test_context.h"

#include <gtest/gtest.h>

#include <cmath>

#include "leglab/model/metrics.h"
#include "leglab/model/paper.h"

namespace leglab {
namespace {

constexpr JointModelParams kPaper = paper::kTable1;
const std::array<JointModelParams, kLegJoints> kPaperModels = {kPaper, kPaper, kPaper};

// Faster than v_max = 2.5 deg/tick in places on every joint (peak slopes 6.4, 3.3, 4.9).
DesiredCycle FastCycle() {
  DesiredCycle d(88);
  for (int t = 0; t < 88; ++t) {
    const double phase = 2.0 * M_PI * t / 88.0;
    d[t] = {50.0 * std::sin(phase) + 20.0 * std::sin(2.0 * phase),
            30.0 + 25.0 * std::cos(phase) + 5.0 * std::sin(3.0 * phase),
            70.0 + 45.0 * std::sin(phase + 0.7) + 8.0 * std::cos(2.0 * phase)};
  }
  return d;
}

struct PlantRun {
  std::array<std::vector<double>, kLegJoints> actual;
};

// Runs the controller on the ideal plant (the paper's model on every joint) for 10 cycles and
// returns the last one.
PlantRun RunOnModelPlant(JointController& controller, const DesiredCycle& desired) {
  JointModelPlant plant(kPaperModels, testing::Ers210aLimits());
  plant.Reset(desired[0]);
  LegAngles measured = desired[0];
  PlantRun run;
  for (long t = 0; t < 10L * 88; ++t) {
    measured = plant.Tick(controller.Update(t, measured)).measured_deg;
    if (t >= 9L * 88) {
      for (int j = 0; j < kLegJoints; ++j) run.actual[j].push_back(measured[j]);
    }
  }
  return run;
}

TEST(ModelBasedController, FollowsItsPiecewiseLinearTargetOnTheModelPlant) {
  const DesiredCycle desired = FastCycle();
  const ControllerContext context = testing::PaperContext(desired);
  for (CmMethod cm : {CmMethod::kExact, CmMethod::kClosed}) {
    ModelBasedController mb({cm}, context);
    DirectController direct({}, context);
    const PlantRun with_model = RunOnModelPlant(mb, desired);
    const PlantRun plain = RunOnModelPlant(direct, desired);
    for (int j = 0; j < kLegJoints; ++j) {
      std::vector<double> des(88);
      for (int t = 0; t < 88; ++t) des[t] = desired[t][j];
      const std::vector<double> pwl = context.Approximation(j).Sample();
      // A bound of our own, above the 2.7 deg the paper measured on the real leg.
      EXPECT_LE(RmsDistance(pwl, with_model.actual[j]), 3.5) << "joint " << j;
      // And the paper's point: closer to the desired angles than requesting them directly.
      EXPECT_LT(RmsDistance(des, with_model.actual[j]), 0.5 * RmsDistance(des, plain.actual[j]))
          << "joint " << j;
    }
  }
}

TEST(ModelBasedController, ApproximationsRespectVmax) {
  const ControllerContext context = testing::PaperContext(FastCycle());
  for (int j = 0; j < kLegJoints; ++j) {
    for (int k = 0; k < context.Approximation(j).num_segments(); ++k) {
      EXPECT_LE(std::abs(context.Approximation(j).Slope(k)), 2.5 + 1e-9);
    }
  }
}

// The approximations are fitted on first use: the same bits as fitting each joint directly, the
// copies of a context share them, and their segment count is known without fitting; a bad
// cycle still fails when the context is made.
TEST(ModelBasedController, ApproximationsAreFittedOnFirstUseWithTheSameBits) {
  const DesiredCycle desired = FastCycle();
  const ControllerContext context = testing::PaperContext(desired);
  ControllerContext copy = context;
  copy.warmup_steps = 3;  // a copy, changed otherwise, still shares them
  EXPECT_EQ(context.ApproximationSegments(), 8);
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> column(desired.size());
    for (size_t t = 0; t < desired.size(); ++t) column[t] = desired[t][j];
    const PiecewiseLinear direct = FitPiecewiseLinear(column, 2.5, {.segments = 8});
    EXPECT_EQ(copy.Approximation(j).breakpoints_tick, direct.breakpoints_tick);
    EXPECT_EQ(copy.Approximation(j).values_deg, direct.values_deg);
    EXPECT_EQ(&copy.Approximation(j), &context.Approximation(j));
    EXPECT_EQ(context.Approximation(j).num_segments(), context.ApproximationSegments());
  }
  EXPECT_EQ(ControllerContext{}.Approximation(0).num_segments(), 0);
  DesiredCycle bad = desired;
  bad[5][1] = std::nan("");
  EXPECT_THROW(testing::PaperContext(bad), std::invalid_argument);
  EXPECT_THROW(testing::PaperContext(DesiredCycle(1)), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
