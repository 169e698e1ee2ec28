#include "leglab/servo/servo_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "leglab/servo/servo_model.h"

namespace leglab {
namespace {

constexpr double kTickS = 0.01;
constexpr double kFitTickS = 0.008;

// The truth the fit should find: saturation at 12.5 deg of error at kp 10 (25 at kp 5), 3.2 deg
// a tick of top speed, both frictions, a 25 ms velocity lag and two ticks of delay.
const ServoModelParams kTruth{.gain_per_deg_kp = 0.008,
                              .v_max_deg_s = 400.0,
                              .stall_torque_nm = 1.2,
                              .friction_duty = 0.03,
                              .friction_load_ratio = 0.3,
                              .velocity_lag_s = 0.025,
                              .lag_ticks = 2};

// Steps of 3, 8, 20, 45 and 6 deg about `base_deg`, each held, then a sine of 30 deg over 16
// ticks (up to 11.8 deg a tick, far past the top speed).
std::vector<double> RichRequests(double base_deg) {
  std::vector<double> requests;
  const auto hold = [&](double offset, int ticks) {
    for (int i = 0; i < ticks; ++i) requests.push_back(base_deg + offset);
  };
  hold(0, 5);
  hold(3, 20);
  hold(11, 20);
  hold(-9, 25);
  hold(36, 30);
  hold(30, 20);
  for (int i = 0; i < 48; ++i)
    requests.push_back(base_deg + 30.0 * std::sin(2 * std::numbers::pi * i / 16));
  return requests;
}

// The recording `truth` makes of the requests, from rest at the first request (as the
// prediction starts it: at rest, remembering R(0)), every tick driven.
ServoRecording Simulate(const ServoModelParams& truth, const ServoDrive& drive,
                        const std::vector<double>& requests) {
  ServoRecording recording{.drive = drive, .request_deg = requests};
  ServoModelState state = ServoRestState(truth, requests[0]);
  recording.measured_deg.push_back(requests[0]);
  for (size_t t = 1; t < requests.size(); ++t) {
    recording.measured_deg.push_back(StepServoModel(truth, drive, kFitTickS, state, requests[t]));
  }
  recording.scored.assign(requests.size(), 1);
  return recording;
}

double RmsError(const ServoModelParams& p, const ServoRecording& recording) {
  const std::vector<double> predicted = PredictServoRecording(p, recording, kFitTickS);
  double sum = 0.0;
  for (size_t t = 0; t < predicted.size(); ++t) {
    sum += std::pow(predicted[t] - recording.measured_deg[t], 2);
  }
  return std::sqrt(sum / static_cast<double>(predicted.size()));
}

std::vector<ServoRecording> TruthRecordings() {
  return {Simulate(kTruth, {.kp = 10.0, .mass_kg = 0.0, .length_m = 0.0}, RichRequests(0.0)),
          Simulate(kTruth, {.kp = 5.0, .mass_kg = 0.5, .length_m = 0.1}, RichRequests(40.0))};
}

// Both recordings determine the gain (the error at which the speed saturates, through two kps),
// v_max (the sine saturates it), the velocity lag and the delay; only the loaded one the stall
// torque (the load duty scales with 1 / stall) and the friction's growth with load; the steps'
// settling the friction band. On noiseless data from the model itself the fit should find all
// of them, and predict to well under a hundredth of the truth's error scale.
TEST(ServoFitTest, FitRecoversAKnownModel) {
  const std::vector<ServoRecording> recordings = TruthRecordings();
  const ServoFitOptions options{.lag_max_ticks = 3, .restarts = 2, .iterations = 1500};
  const ServoModelParams fit = FitServoModel(recordings, kFitTickS, options);
  for (const ServoRecording& r : recordings) EXPECT_LT(RmsError(fit, r), 0.05);
  EXPECT_EQ(fit.lag_ticks, kTruth.lag_ticks);
  EXPECT_NEAR(fit.gain_per_deg_kp, kTruth.gain_per_deg_kp, 0.01 * kTruth.gain_per_deg_kp);
  EXPECT_NEAR(fit.v_max_deg_s, kTruth.v_max_deg_s, 0.01 * kTruth.v_max_deg_s);
  EXPECT_NEAR(fit.velocity_lag_s, kTruth.velocity_lag_s, 0.02 * kTruth.velocity_lag_s);
  EXPECT_NEAR(fit.stall_torque_nm, kTruth.stall_torque_nm, 0.05 * kTruth.stall_torque_nm);
  EXPECT_NEAR(fit.friction_duty, kTruth.friction_duty, 0.005);
  EXPECT_NEAR(fit.friction_load_ratio, kTruth.friction_load_ratio, 0.05);
}

// Held at 350 (not the truth's 400), v_max comes back as given, bit for bit.
TEST(ServoFitTest, FitHoldsAGivenTopSpeed) {
  const std::vector<ServoRecording> recordings = TruthRecordings();
  const ServoFitOptions options{
      .lag_max_ticks = 0, .v_max_deg_s = 350.0, .restarts = 1, .iterations = 100};
  EXPECT_EQ(FitServoModel(recordings, kFitTickS, options).v_max_deg_s, 350.0);
}

TEST(ServoFitTest, FitRejectsBadInput) {
  const ServoFitOptions options{.lag_max_ticks = 0, .restarts = 1, .iterations = 10};
  const ServoRecording good{.drive = {.kp = 10.0, .mass_kg = 0.0, .length_m = 0.0},
                            .request_deg = {0, 5, 5, 5},
                            .measured_deg = {0, 1, 2, 3},
                            .scored = {1, 1, 1, 1}};
  EXPECT_NO_THROW(FitServoModel(std::vector{good}, kTickS, options));
  EXPECT_THROW(FitServoModel({}, kTickS, options), std::invalid_argument);
  EXPECT_THROW(FitServoModel(std::vector{good}, 0.0, options), std::invalid_argument);
  ServoRecording mismatched = good;
  mismatched.scored.pop_back();
  EXPECT_THROW(FitServoModel(std::vector{mismatched}, kTickS, options), std::invalid_argument);
  ServoRecording undriven = good;
  undriven.scored.assign(4, 0);
  EXPECT_THROW(FitServoModel(std::vector{good, undriven}, kTickS, options), std::invalid_argument);
  // A search with no lag, no run or no iteration would return a model never fitted.
  for (const ServoFitOptions empty :
       {ServoFitOptions{.lag_max_ticks = -1}, ServoFitOptions{.restarts = 0},
        ServoFitOptions{.iterations = 0}}) {
    EXPECT_THROW(FitServoModel(std::vector{good}, kTickS, empty), std::invalid_argument);
  }
}

}  // namespace
}  // namespace leglab
