#include "leglab/sim/sim_config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace leglab::sim {
namespace {

SimConfig ValidConfig() {
  SimConfig config;
  config.urdf_path = "leg.urdf";
  return config;
}

std::string RejectionOf(const std::function<void(SimConfig&)>& mutate) {
  SimConfig config = ValidConfig();
  mutate(config);
  try {
    ValidateSimConfig(config);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "accepted";
}

TEST(SimConfigTest, DefaultsWithAUrdfAreValid) {
  EXPECT_NO_THROW(ValidateSimConfig(ValidConfig()));
  EXPECT_EQ(PhysicsStepsPerTick(1.0), 8);
  EXPECT_EQ(PhysicsStepsPerTick(0.5), 16);
  EXPECT_EQ(PhysicsStepsPerTick(8.0), 1);
}

TEST(SimConfigTest, DelayMessageNamesKeyExpectationAndValue) {
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.servo.delay_ms = 30; }),
            "servo.delay_ms must be a non-negative multiple of 8 ms, got 30");
}

TEST(SimConfigTest, EachBadValueNamesItsKey) {
  const struct {
    std::function<void(SimConfig&)> mutate;
    std::string key;
  } cases[] = {
      {[](SimConfig& c) { c.urdf_path.clear(); }, "urdf"},
      {[](SimConfig& c) { c.physics_dt_ms = 3; }, "sim.physics_dt_ms"},
      {[](SimConfig& c) { c.physics_dt_ms = 0; }, "sim.physics_dt_ms"},
      {[](SimConfig& c) { c.physics_dt_ms = 16; }, "sim.physics_dt_ms"},
      {[](SimConfig& c) { c.servo.delay_ms = -8; }, "servo.delay_ms"},
      {[](SimConfig& c) { c.servo.max_speed_deg_s = 0; }, "servo.max_speed_deg_s"},
      {[](SimConfig& c) { c.servo.max_speed_deg_s = std::nan(""); }, "servo.max_speed_deg_s"},
      {[](SimConfig& c) { c.servo.gain_per_s = -1; }, "servo.gain_per_s"},
      {[](SimConfig& c) { c.servo.smoothing_ms = 2.5; }, "servo.smoothing_ms"},
      {[](SimConfig& c) { c.servo.smoothing_ms = 44; }, "servo.smoothing_ms"},  // not 8 ms frames
      {[](SimConfig& c) { c.servo.damping = -0.1; }, "servo.damping"},
      {[](SimConfig& c) { c.servo.smoothing_ms = -1; }, "servo.smoothing_ms"},
      {[](SimConfig& c) { c.servo.max_torque_nm = 0; }, "servo.max_torque_nm"},
      {[](SimConfig& c) { c.sensor.noise_deg = -0.1; }, "sensor.noise_deg"},
  };
  for (const auto& c : cases) {
    const std::string message = RejectionOf(c.mutate);
    EXPECT_EQ(message.rfind(c.key + " must ", 0), 0u) << message;
  }
}

// A joint may turn at most 2 deg in one physics step: 2000 deg/s at 1 ms, 4000 at 0.5 ms,
// 1000 at the coarsest step, 2 ms; just above each pair is refused naming both keys.
std::string TurnRejectionOf(const std::function<void(SimConfig&)>& mutate) {
  SimConfig config = ValidConfig();
  mutate(config);
  try {
    CheckTurnPerPhysicsStep(config);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "accepted";
}

TEST(SimConfigTest, TopSpeedTimesPhysicsStepIsBounded) {
  const struct {
    double dt_ms;
    double top_deg_s;
  } pairs[] = {{1.0, 2000.0}, {0.5, 4000.0}, {2.0, 1000.0}, {0.1, 20000.0}};
  for (const auto& p : pairs) {
    EXPECT_EQ(TurnRejectionOf([&](SimConfig& c) {
                c.physics_dt_ms = p.dt_ms;
                c.servo.max_speed_deg_s = p.top_deg_s;
              }),
              "accepted")
        << p.dt_ms;
    const std::string message = TurnRejectionOf([&](SimConfig& c) {
      c.physics_dt_ms = p.dt_ms;
      c.servo.max_speed_deg_s = p.top_deg_s * 1.0001;
    });
    EXPECT_EQ(message.rfind("servo.max_speed_deg_s ", 0), 0u) << message;
    EXPECT_NE(message.find(" with sim.physics_dt_ms "), std::string::npos) << message;
    EXPECT_NE(message.find("must be at most 2000"), std::string::npos) << message;
  }
  EXPECT_EQ(TurnRejectionOf([](SimConfig& c) {
              c.physics_dt_ms = 1.0;
              c.servo.max_speed_deg_s = 2200;
            }),
            "servo.max_speed_deg_s 2200 with sim.physics_dt_ms 1 turns a joint 2.2 deg in one "
            "physics step; at most 2 deg holds ODE's leg together: "
            "servo.max_speed_deg_s x sim.physics_dt_ms must be at most 2000 (sim.engine: dart "
            "takes it)");
  // ValidateSimConfig leaves it to the loader: a LegSim built directly may be driven apart.
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.servo.max_speed_deg_s = 3600; }), "accepted");
}

// The stand is ODE's: on DART it is refused, naming the section and the key to change.
TEST(SimConfigTest, TheStandOnDartIsRefusedNamingTheEngine) {
  if (!BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  EXPECT_EQ(RejectionOf([](SimConfig& c) {
              c.engine = PhysicsEngine::kDart;
              c.stand.enabled = true;
            }).rfind("stand: sim.engine dart has no stand", 0),
            0u);
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.stand.enabled = true; }), "accepted");
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.engine = PhysicsEngine::kDart; }), "accepted");
}

// A build without DART refuses the engine as bad input, in one line naming the key, the stand
// or not (a LegWorld built directly: leg_world_test.cc).
TEST(SimConfigTest, DartInABuildWithoutItIsRefusedNamingTheKey) {
  if (BuiltWithDart()) GTEST_SKIP() << "this build has DART";
  const std::string expected =
      "sim.engine: dart, but this build of leglab has no DART (configured with "
      "LEGLAB_WITH_DART=OFF or without DART 6.12 installed); use sim.engine: ode";
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.engine = PhysicsEngine::kDart; }), expected);
  EXPECT_EQ(RejectionOf([](SimConfig& c) {
              c.engine = PhysicsEngine::kDart;
              c.stand.enabled = true;
            }),
            expected);
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.engine = PhysicsEngine::kOde; }), "accepted");
}

TEST(SimConfigTest, AcceptsEdgeValues) {
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.servo.delay_ms = 0; }), "accepted");
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.servo.smoothing_ms = 0; }), "accepted");
  EXPECT_EQ(RejectionOf([](SimConfig& c) { c.sensor.noise_deg = 0; }), "accepted");
  EXPECT_EQ(RejectionOf([](SimConfig& c) {
              c.physics_dt_ms = 0.1;
              c.servo.smoothing_ms = 48;
            }),
            "accepted");
}

}  // namespace
}  // namespace leglab::sim
