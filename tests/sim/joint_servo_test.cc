#include "leglab/sim/joint_servo.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace leglab::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ServoConfig Config(double delay_ms, double smoothing_ms) {
  ServoConfig config;
  config.delay_ms = delay_ms;
  config.max_speed_deg_s = 312.5;
  config.gain_per_s = 50.0;
  config.smoothing_ms = smoothing_ms;
  return config;
}

TEST(JointServoTest, ActsOnARequestExactlyDelayTicksLater) {
  JointServo servo(Config(32.0, 0.0), -2.0, 2.0);
  EXPECT_EQ(servo.delay_ticks(), 4);
  for (int tick = 0; tick < 10; ++tick) {
    servo.PushRequest(0.1 * tick);
    // The request pushed at tick t is acted on from tick t + 4; before tick 4 the hold (0).
    const double expected = tick >= 4 ? 0.1 * (tick - 4) : 0.0;
    EXPECT_DOUBLE_EQ(servo.target_rad(), expected) << "tick " << tick;
    EXPECT_DOUBLE_EQ(servo.latest_request_rad(), 0.1 * tick);
  }
}

TEST(JointServoTest, ZeroDelayActsAtOnce) {
  JointServo servo(Config(0.0, 0.0), -2.0, 2.0);
  servo.PushRequest(0.5);
  EXPECT_DOUBLE_EQ(servo.target_rad(), 0.5);
}

TEST(JointServoTest, ClampsTargetsIntoTheLimits) {
  JointServo servo(Config(0.0, 0.0), -0.2, 1.5);
  servo.PushRequest(3.0);
  EXPECT_DOUBLE_EQ(servo.target_rad(), 1.5);
  servo.PushRequest(-3.0);
  EXPECT_DOUBLE_EQ(servo.target_rad(), -0.2);
}

TEST(JointServoTest, SpeedIsProportionalThenCapped) {
  JointServo servo(Config(0.0, 0.0), -2.0, 2.0);
  servo.PushRequest(1.0 * kDeg);
  // 50/s * 1 deg = 50 deg/s, under the 312.5 deg/s cap.
  EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 0.0), 50.0 * kDeg, 1e-12);
  servo.PushRequest(-40.0 * kDeg);
  EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 0.0), -312.5 * kDeg, 1e-12);
}

TEST(JointServoTest, DampingSubtractsFromTheProportionalCommand) {
  ServoConfig config = Config(0.0, 0.0);
  config.damping = 0.5;
  JointServo servo(config, -2.0, 2.0);
  servo.PushRequest(1.0 * kDeg);
  // 50/s * 1 deg - 0.5 * 40 deg/s = 30 deg/s.
  EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 40.0 * kDeg), 30.0 * kDeg, 1e-12);
  // Moving fast towards the target, the command reverses: 50 - 0.5 * 200 = -50 deg/s.
  EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 200.0 * kDeg), -50.0 * kDeg, 1e-12);
  // And it is capped like the proportional part: 50 + 0.5 * 1000 -> 312.5 deg/s.
  EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, -1000.0 * kDeg), 312.5 * kDeg, 1e-12);
}

TEST(JointServoTest, SmoothingRampsLinearlyOverTheWindow) {
  // An 80 ms window is 10 frames: a saturated command is reached in 10 equal increments.
  JointServo servo(Config(0.0, 80.0), -2.0, 2.0);
  servo.PushRequest(1.5);
  const double top = 312.5 * kDeg;
  for (int step = 1; step <= 15; ++step) {
    const double expected = top * std::min(step, 10) / 10.0;
    EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 0.0), expected, 1e-12) << "step " << step;
  }
  // Reversing takes the same window, from +top to -top (not twice as long).
  servo.PushRequest(-1.5);
  for (int step = 1; step <= 10; ++step) {
    EXPECT_NEAR(servo.FrameSpeedRadPerS(0.0, 0.0), top - 2.0 * top * step / 10.0, 1e-12);
  }
}

TEST(JointServoTest, HoldForgetsQueueAndSpeedHistory) {
  JointServo servo(Config(16.0, 40.0), -2.0, 2.0);
  servo.PushRequest(1.0);
  servo.PushRequest(1.0);
  servo.PushRequest(1.0);
  EXPECT_GT(servo.FrameSpeedRadPerS(0.0, 0.0), 0.0);
  servo.Hold(0.3);
  EXPECT_DOUBLE_EQ(servo.target_rad(), 0.3);
  EXPECT_DOUBLE_EQ(servo.latest_request_rad(), 0.3);
  EXPECT_DOUBLE_EQ(servo.FrameSpeedRadPerS(0.3, 0.0), 0.0);
}

TEST(JointServoTest, MeanIsExactOnceTheWindowHoldsOneValue) {
  JointServo servo(Config(0.0, 40.0), -2.0, 2.0);
  servo.PushRequest(0.01);
  double angle = 0.0;
  for (int frame = 0; frame < 1000; ++frame) {
    angle = std::fmod(angle + 0.0123456789, 0.02);
    servo.FrameSpeedRadPerS(angle, 0.0);
  }
  // Five frames of the same command (50/s * 0.01 rad = 0.5 rad/s) average to it exactly.
  for (int frame = 0; frame < 5; ++frame) servo.FrameSpeedRadPerS(0.0, 0.0);
  EXPECT_EQ(servo.FrameSpeedRadPerS(0.0, 0.0), 0.5);
}

}  // namespace
}  // namespace leglab::sim
