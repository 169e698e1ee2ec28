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
