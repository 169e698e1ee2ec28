#include "leglab/servo/servo_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace leglab {
namespace {

constexpr double kTickS = 0.01;
constexpr double kGravity = 9.81;  // m/s^2, as the model's

// gain 0.01 at kp 10: duty 0.1 per degree of error, saturating at 10 deg; 500 deg/s at full
// duty; velocity_lag_s = tick / ln 2, so the blend 1 - exp(-tick / lag) = 1 - 1/2 = 1/2.
ServoModelParams HandParams(int lag_ticks = 0) {
  return {.gain_per_deg_kp = 0.01,
          .v_max_deg_s = 500.0,
          .stall_torque_nm = 1.0,
          .friction_duty = 0.0,
          .friction_load_ratio = 0.0,
          .velocity_lag_s = kTickS / std::numbers::ln2,
          .lag_ticks = lag_ticks};
}

const ServoDrive kNoLoad{.kp = 10.0, .mass_kg = 0.0, .length_m = 0.0};

// A load of m g L = 0.4 N m: at 30 deg (sin = 1/2) it takes g = 0.2 of the 1 N m stall duty.
const ServoDrive kLoad{.kp = 10.0, .mass_kg = 1.0, .length_m = 0.4 / kGravity};

ServoModelState StateAt(double angle_deg, std::vector<double> past_requests_deg) {
  return {.angle_deg = angle_deg,
          .velocity_deg_s = 0.0,
          .past_requests_deg = std::move(past_requests_deg)};
}

// l = 0, from rest at 0 with R(-1) = 2 (held):
//   tick 0: e = 2,   u = 0.2,  w* = 100, w = 0 + (100 - 0) / 2 = 50,    M = 0 + 0.5 = 0.5
//   tick 1: e = 1.5, u = 0.15, w* = 75,  w = 50 + (75 - 50) / 2 = 62.5, M = 0.5 + 0.625 = 1.125
TEST(ServoModelTest, TwoTicksWorkedByHand) {
  ServoModelState state = StateAt(0.0, {2.0});
  EXPECT_NEAR(StepServoModel(HandParams(), kNoLoad, kTickS, state, 2.0), 0.5, 1e-12);
  EXPECT_NEAR(state.velocity_deg_s, 50.0, 1e-12);
  EXPECT_NEAR(StepServoModel(HandParams(), kNoLoad, kTickS, state, 2.0), 1.125, 1e-12);
  EXPECT_NEAR(state.velocity_deg_s, 62.5, 1e-12);
  EXPECT_EQ(state.past_requests_deg, std::vector<double>{2.0});
}

// The load at 30 deg takes g = 0.2; friction 0.05 + 0.25 * |g| = 0.1. The net duty u - 0.2 is
// inside the band for u in [0.1, 0.3], i.e. errors of 1..3 deg: the joint holds.
// Outside: e = 3.5 gives n = 0.15, w* = 500 * (0.15 - 0.1) = 25 (up); e = 0.5 gives
// n = -0.15, w* = -25 (the load pulls it down); e = 0 gives n = -0.2, w* = -50.
TEST(ServoModelTest, LoadAndFrictionBandWorkedByHand) {
  ServoModelParams p = HandParams();
  p.friction_duty = 0.05;
  p.friction_load_ratio = 0.25;
  EXPECT_NEAR(ServoLoadDuty(p, kLoad, 30.0), 0.2, 1e-12);
  EXPECT_NEAR(ServoLoadDuty(p, kLoad, -30.0), -0.2, 1e-12);
  for (double e : {1.1, 1.5, 2.0, 2.5, 2.9}) {
    EXPECT_EQ(ServoTargetSpeed(p, kLoad, 30.0, e), 0.0) << e;
  }
  EXPECT_NEAR(ServoTargetSpeed(p, kLoad, 30.0, 3.5), 25.0, 1e-9);
  EXPECT_NEAR(ServoTargetSpeed(p, kLoad, 30.0, 0.5), -25.0, 1e-9);
  EXPECT_NEAR(ServoTargetSpeed(p, kLoad, 30.0, 0.0), -50.0, 1e-9);

  // Held at 32 deg of request (e = 2), the joint stays at 30 tick after tick.
  ServoModelState held = StateAt(30.0, {32.0});
  for (int t = 0; t < 5; ++t) {
    EXPECT_EQ(StepServoModel(p, kLoad, kTickS, held, 32.0), 30.0) << t;
    EXPECT_EQ(held.velocity_deg_s, 0.0) << t;
  }
  // One tick outside the band: w = 25 / 2 = 12.5 up, or -12.5 down; M = 30 +- 0.125.
  ServoModelState up = StateAt(30.0, {33.5});
  EXPECT_NEAR(StepServoModel(p, kLoad, kTickS, up, 33.5), 30.125, 1e-9);
  ServoModelState down = StateAt(30.0, {30.5});
  EXPECT_NEAR(StepServoModel(p, kLoad, kTickS, down, 30.5), 29.875, 1e-9);
}

// l = 3, at rest at 0, R(0) = 10 onwards: M(0..3) stay 0; at tick 4 the error of 10 deg
// saturates the duty (u = 1, w* = 500), so w = 250 and M(4) = 2.5.
TEST(ServoModelTest, RequestFirstActsAfterTheLag) {
  const ServoModelParams p = HandParams(3);
  ServoModelState state = ServoRestState(p, 0.0);
  ASSERT_EQ(state.past_requests_deg, std::vector<double>(4, 0.0));
  EXPECT_EQ(state.velocity_deg_s, 0.0);
  for (int t = 0; t <= 3; ++t) {
    EXPECT_EQ(StepServoModel(p, kNoLoad, kTickS, state, 10.0), 0.0) << t;
  }
  EXPECT_NEAR(StepServoModel(p, kNoLoad, kTickS, state, 10.0), 2.5, 1e-12);
}

// gain * kp = 0.1 per deg: beyond 10 deg of error the duty is 1 and the speed stays
// v_max - friction = 500 * (1 - 0.05) = 475.
TEST(ServoModelTest, TargetSpeedSaturatesWithTheDuty) {
  ServoModelParams p = HandParams();
  p.friction_duty = 0.05;
  EXPECT_NEAR(ServoTargetSpeed(p, kNoLoad, 0.0, 5.0), 500.0 * (0.5 - 0.05), 1e-9);
  EXPECT_NEAR(ServoTargetSpeed(p, kNoLoad, 0.0, 10.0), 475.0, 1e-9);
  EXPECT_EQ(ServoTargetSpeed(p, kNoLoad, 0.0, 15.0), ServoTargetSpeed(p, kNoLoad, 0.0, 40.0));
  EXPECT_NEAR(ServoTargetSpeed(p, kNoLoad, 0.0, 15.0), 475.0, 1e-9);
  EXPECT_EQ(ServoTargetSpeed(p, kNoLoad, 0.0, -15.0), ServoTargetSpeed(p, kNoLoad, 0.0, -90.0));
  EXPECT_NEAR(ServoTargetSpeed(p, kNoLoad, 0.0, -15.0), -475.0, 1e-9);
}

// Eq. 2: f(x) = v_max * x / theta_0 inside (-theta_0, theta_0), +-v_max outside.
double PaperF(double v_max, double theta0, double x) {
  if (x >= theta0) return v_max;
  if (x <= -theta0) return -v_max;
  return v_max * x / theta0;
}

// gain 0.01 at kp 4: theta_0 = 1 / 0.04 = 25 deg. A load hanging straight down (angle 0) takes
// no duty, so it changes nothing either.
TEST(ServoModelTest, WithoutLoadAndFrictionTargetSpeedIsThePapersF) {
  const ServoModelParams p = HandParams();
  const ServoDrive drive{.kp = 4.0, .mass_kg = 0.0, .length_m = 0.0};
  const ServoDrive hanging{.kp = 4.0, .mass_kg = 2.0, .length_m = 0.3};
  for (double x = -60.0; x <= 60.0; x += 0.25) {
    EXPECT_NEAR(ServoTargetSpeed(p, drive, 17.0, x), PaperF(500.0, 25.0, x), 1e-9) << x;
    EXPECT_NEAR(ServoTargetSpeed(p, hanging, 0.0, x), PaperF(500.0, 25.0, x), 1e-9) << x;
  }
}

TEST(ServoModelTest, ParamsProblemNamesTheBadField) {
  const ServoModelParams good = HandParams(2);
  EXPECT_EQ(ServoModelParamsProblem(good), "");
  const auto problem = [&](auto change) {
    ServoModelParams p = good;
    change(p);
    return ServoModelParamsProblem(p);
  };
  EXPECT_NE(problem([](ServoModelParams& p) { p.gain_per_deg_kp = 0.0; }).find("gain_per_deg_kp"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) { p.v_max_deg_s = std::nan(""); }).find("v_max_deg_s"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) { p.stall_torque_nm = -1.0; }).find("stall_torque_nm"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) { p.friction_duty = -0.01; }).find("friction_duty"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) {
              p.friction_load_ratio = -0.5;
            }).find("friction_load_ratio"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) { p.velocity_lag_s = -0.1; }).find("velocity_lag_s"),
            std::string::npos);
  EXPECT_NE(problem([](ServoModelParams& p) { p.lag_ticks = -1; }).find("lag_ticks"),
            std::string::npos);
  // Zero is in range for the frictions and the lag in ticks.
  EXPECT_EQ(problem([](ServoModelParams& p) {
              p.friction_duty = 0.0;
              p.lag_ticks = 0;
            }),
            "");
}

// l = 0 (HandParams), scored 1,1,1,0,0,1,1. Tick 0 starts at measured 0 remembering R(0) = 2:
// M(1) = 0.5 and M(2) = 1.125 as in TwoTicksWorkedByHand. Ticks 3, 4 are undriven (as measured);
// tick 5 restarts at measured 3 remembering R(5) = 5: e = 2, w = 50, M(6) = 3 + 0.5 = 3.5.
TEST(ServoModelTest, PredictRestartsAtTheMeasuredAngleWorkedByHand) {
  const ServoRecording recording{.drive = kNoLoad,
                                 .request_deg = {2, 2, 2, 0, 0, 5, 5},
                                 .measured_deg = {0, 0.4, 1, 7, 8, 3, 3.2},
                                 .scored = {1, 1, 1, 0, 0, 1, 1}};
  const std::vector<double> predicted = PredictServoRecording(HandParams(), recording, kTickS);
  const std::vector<double> expected = {0, 0.5, 1.125, 7, 8, 3, 3.5};
  ASSERT_EQ(predicted.size(), expected.size());
  for (size_t t = 0; t < expected.size(); ++t) EXPECT_NEAR(predicted[t], expected[t], 1e-12) << t;
}

// With l = 2 and a load, the prediction is the model stepped from the measured angle at the
// start of each driven run, at rest, remembering R(t), R(t-1), R(t-2) (R(0) before tick 0).
TEST(ServoModelTest, PredictAgreesWithSteppingTheModel) {
  ServoModelParams p = HandParams(2);
  p.friction_duty = 0.02;
  p.friction_load_ratio = 0.3;
  ServoRecording recording{.drive = kLoad};
  for (int t = 0; t < 40; ++t) {
    recording.request_deg.push_back(20.0 + 15.0 * std::sin(0.3 * t));
    recording.measured_deg.push_back(18.0 + 0.5 * t);
    recording.scored.push_back(t < 25 || t >= 30 ? 1 : 0);
  }
  const std::vector<double> predicted = PredictServoRecording(p, recording, kTickS);
  const std::vector<double>& r = recording.request_deg;
  ServoModelState first = StateAt(recording.measured_deg[0], {r[0], r[0], r[0]});
  ServoModelState second = StateAt(recording.measured_deg[30], {r[30], r[29], r[28]});
  for (size_t t = 0; t < 40; ++t) {
    double expected = recording.measured_deg[t];
    if (t >= 1 && t < 25) expected = StepServoModel(p, kLoad, kTickS, first, r[t]);
    if (t >= 31) expected = StepServoModel(p, kLoad, kTickS, second, r[t]);
    EXPECT_EQ(predicted[t], expected) << t;
  }
}

TEST(ServoModelTest, PredictRejectsBadInput) {
  ServoRecording recording{
      .drive = kNoLoad, .request_deg = {0, 1, 2}, .measured_deg = {0, 1, 2}, .scored = {1, 1, 1}};
  EXPECT_THROW(PredictServoRecording(HandParams(), recording, 0.0), std::invalid_argument);
  recording.measured_deg.pop_back();
  EXPECT_THROW(PredictServoRecording(HandParams(), recording, kTickS), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
