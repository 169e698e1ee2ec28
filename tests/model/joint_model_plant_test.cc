#include "leglab/model/joint_model_plant.h"

#include <gtest/gtest.h>

#include <cmath>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/model/paper.h"
#include "test_legs.h"

namespace leglab {
namespace {

const std::array<JointModelParams, kLegJoints> kModels = {
    paper::kTable1, JointModelParams{3.0, 5.0, 2, 3}, JointModelParams{1.5, 9.0, 6, 1}};

// The plant is eq. 3 run on the clamped requests: compare each joint with SimulateJointModel
// over a random-ish request sequence that also asks beyond the limits.
TEST(JointModelPlant, EachJointIsItsModelOnTheClampedRequests) {
  JointModelPlant plant(kModels, testing::FrontLeftLeg().limits);
  const LegAngles start{10.0, 5.0, 40.0};
  plant.Reset(start);
  std::array<std::vector<double>, kLegJoints> applied;
  std::vector<PlantReading> readings;
  for (int t = 0; t < 300; ++t) {
    const LegAngles request{150.0 * std::sin(0.05 * t), 100.0 * std::cos(0.03 * t),
                            80.0 + 90.0 * std::sin(0.07 * t)};
    readings.push_back(plant.Tick(request));
    for (int j = 0; j < kLegJoints; ++j) {
      // Clamped by hand: -117..117, -11..89, -27..147 deg.
      const double lo[] = {-117.0, -11.0, -27.0}, hi[] = {117.0, 89.0, 147.0};
      const double expected = std::min(std::max(request[j], lo[j]), hi[j]);
      EXPECT_NEAR(readings.back().applied_deg[j], expected, 1e-9) << t << " " << j;
      applied[j].push_back(readings.back().applied_deg[j]);
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    const std::vector<double> model =
        SimulateJointModel(kModels[j], applied[j], RestState(kModels[j], start[j]));
    for (int t = 0; t < 300; ++t) {
      EXPECT_EQ(readings[t].true_deg[j], model[t]) << t << " " << j;
      EXPECT_EQ(readings[t].measured_deg[j], model[t]) << "an ideal sensor";
    }
  }
}

TEST(JointModelPlant, ARequestActsAfterLPlusOneTicks) {
  JointModelPlant plant(kModels, testing::FrontLeftLeg().limits);
  plant.Reset({0.0, 0.0, 0.0});
  EXPECT_EQ(plant.Read().measured_deg, (LegAngles{0.0, 0.0, 0.0}));
  // Joint j first moves at tick l_j + 1 after a step request at tick 0 (l = 4, 2, 6).
  std::array<int, kLegJoints> first_move{-1, -1, -1};
  for (int t = 0; t < 12; ++t) {
    const PlantReading& r = plant.Tick({20.0, 20.0, 20.0});
    for (int j = 0; j < kLegJoints; ++j) {
      if (first_move[j] < 0 && r.true_deg[j] != 0.0) first_move[j] = t;
    }
  }
  EXPECT_EQ(first_move, (std::array<int, kLegJoints>{5, 3, 7}));
}

TEST(JointModelPlant, BadInputNamesTheJoint) {
  std::array<JointModelParams, kLegJoints> bad = kModels;
  bad[kKnee].accel_ticks = 0;
  try {
    JointModelPlant plant(bad, testing::FrontLeftLeg().limits);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("knee"), std::string::npos) << e.what();
  }
  JointModelPlant plant(kModels, testing::FrontLeftLeg().limits);
  EXPECT_THROW(plant.Reset({0.0, 95.0, 0.0}), std::invalid_argument);  // abductor limit 89
  EXPECT_THROW(plant.Tick({0.0, NAN, 0.0}), std::invalid_argument);
  EXPECT_EQ(plant.name(), "model");
}

// A change at tick N: until N the plant is eq. 3 with the old model, from N on eq. 3 with the
// new one, stepped here by hand on the same state (each joint's lag grown to 6: its oldest
// remembered request repeated for the extra ticks).
TEST(JointModelPlant, ChangedModelActsFromTheNextTick) {
  JointModelPlant plant(kModels, testing::FrontLeftLeg().limits);
  const LegAngles start{10.0, 5.0, 40.0};
  plant.Reset(start);
  std::array<JointModelState, kLegJoints> states;
  for (int j = 0; j < kLegJoints; ++j) states[j] = RestState(kModels[j], start[j]);
  std::array<JointModelParams, kLegJoints> models = kModels;
  constexpr int kChangeTick = 40;
  for (int t = 0; t < 100; ++t) {
    if (t == kChangeTick) {
      const std::vector<PlantSetting> wear = {{"plant_model.v_max_deg_per_tick", 2.0},
                                              {"plant_model.lag_ticks", 6.0}};
      plant.ChangeSettings(wear);
      for (int j = 0; j < kLegJoints; ++j) {
        const double oldest = states[j].past_requests_deg.back();
        for (int k = models[j].lag_ticks; k < 6; ++k) states[j].past_requests_deg.push_back(oldest);
        models[j].v_max_deg_per_tick = 2.0;
        models[j].lag_ticks = 6;
      }
    }
    const LegAngles request{40.0 * std::sin(0.1 * t), 20.0 + 15.0 * std::cos(0.05 * t),
                            60.0 + 40.0 * std::sin(0.08 * t)};
    const PlantReading& reading = plant.Tick(request);
    for (int j = 0; j < kLegJoints; ++j) {
      EXPECT_EQ(reading.true_deg[j], StepJointModel(models[j], states[j], request[j]))
          << t << " " << j;
    }
  }
  EXPECT_EQ(plant.model(2).v_max_deg_per_tick, 2.0);
  EXPECT_EQ(plant.model(2).lag_ticks, 6);
}

TEST(JointModelPlant, BadChangesNameTheKeyAndChangeNothing) {
  JointModelPlant plant(kModels, testing::FrontLeftLeg().limits);
  for (const PlantSetting& bad :
       {PlantSetting{"servo.delay_ms", 56.0}, PlantSetting{"plant_model.lag_ticks", 1.5},
        PlantSetting{"plant_model.theta0_deg", -1.0}}) {
    try {
      plant.ChangeSettings(std::span(&bad, 1));
      FAIL() << bad.key;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad.key), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(plant.model(0), kModels[0]);
}

}  // namespace
}  // namespace leglab
