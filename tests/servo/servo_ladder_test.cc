#include "leglab/servo/servo_ladder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

const ServoDrive kDrive{.kp = 10.0, .mass_kg = 0.0, .length_m = 0.0};

// Errors 1, -2, (100 unscored), 3: MAE (1 + 2 + 3) / 3 = 2, RMS sqrt((1 + 4 + 9) / 3).
TEST(ServoLadderTest, ScorePredictionWorkedByHand) {
  const ServoRecording recording{.drive = kDrive,
                                 .request_deg = {0, 0, 0, 0},
                                 .measured_deg = {10, 20, 30, 40},
                                 .scored = {1, 1, 0, 1}};
  const std::vector<double> predicted = {11, 18, 130, 43};
  const PredictionScore score = ScorePrediction(predicted, recording);
  EXPECT_NEAR(score.mae_deg, 2.0, 1e-12);
  EXPECT_NEAR(score.rms_deg, std::sqrt(14.0 / 3.0), 1e-12);
  EXPECT_EQ(score.ticks_scored, 3);
}

TEST(ServoLadderTest, ScorePredictionRejectsBadInput) {
  ServoRecording recording{
      .drive = kDrive, .request_deg = {0, 0}, .measured_deg = {1, 2}, .scored = {0, 0}};
  EXPECT_THROW(ScorePrediction(std::vector<double>{1, 2}, recording), std::invalid_argument);
  recording.scored = {1, 1};
  EXPECT_THROW(ScorePrediction(std::vector<double>{1, 2, 3}, recording), std::invalid_argument);
}

// The MAE over driven ticks of predicting the angle at t as R(max(t - s, 0)), by brute force.
double ShiftMae(const ServoRecording& recording, int s) {
  double sum = 0.0;
  int count = 0;
  for (int t = 0; t < static_cast<int>(recording.request_deg.size()); ++t) {
    if (recording.scored[t] == 0) continue;
    sum += std::abs(recording.request_deg[std::max(t - s, 0)] - recording.measured_deg[t]);
    ++count;
  }
  return sum / count;
}

TEST(ServoLadderTest, BestShiftAgreesWithBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(-30.0, 30.0);
  std::uniform_real_distribution<double> noise(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    ServoRecording recording{.drive = kDrive};
    const int delay = trial % 6;
    double request = 0.0;
    for (int t = 0; t < 60; ++t) {
      if (t % 7 == 0) request = angle(rng);
      recording.request_deg.push_back(request);
      recording.scored.push_back(t % 11 == 5 ? 0 : 1);
    }
    for (int t = 0; t < 60; ++t) {
      recording.measured_deg.push_back(recording.request_deg[std::max(t - delay, 0)] + noise(rng));
    }
    int best = 0;
    for (int s = 1; s <= 8; ++s) {
      if (ShiftMae(recording, s) < ShiftMae(recording, best)) best = s;
    }
    const ShiftPrediction shift = BestShiftPrediction(recording, 8);
    EXPECT_EQ(shift.shift_ticks, best) << trial;
    ASSERT_EQ(shift.angle_deg.size(), 60u);
    for (int t = 0; t < 60; ++t) {
      EXPECT_EQ(shift.angle_deg[t], recording.request_deg[std::max(t - best, 0)]) << t;
    }
  }
}

// The measured angle is the request 4 ticks before (R(0) before tick 0); ticks with the torque
// off measure nonsense, which must not count.
TEST(ServoLadderTest, BestShiftFindsAnExactDelay) {
  ServoRecording recording{.drive = kDrive};
  for (int t = 0; t < 50; ++t) {
    recording.request_deg.push_back(20.0 * std::sin(0.2 * t) + 0.1 * t);
    const bool driven = t < 20 || t >= 26;
    recording.scored.push_back(driven ? 1 : 0);
  }
  for (int t = 0; t < 50; ++t) {
    recording.measured_deg.push_back(
        recording.scored[t] != 0 ? recording.request_deg[std::max(t - 4, 0)] : 1e6);
  }
  const ShiftPrediction shift = BestShiftPrediction(recording, 10);
  EXPECT_EQ(shift.shift_ticks, 4);
  EXPECT_EQ(ShiftMae(recording, 4), 0.0);
  EXPECT_EQ(ScorePrediction(shift.angle_deg, recording).mae_deg, 0.0);
}

// Requests alternating 0, 10 (period 2), measured a tick late, the first three ticks undriven:
// shifts 1, 3 and 5 all predict every driven tick exactly; the smallest, 1, is chosen. A
// constant request ties every shift: 0.
TEST(ServoLadderTest, BestShiftTiesPickTheSmallest) {
  ServoRecording recording{.drive = kDrive};
  for (int t = 0; t < 20; ++t) {
    recording.request_deg.push_back(t % 2 == 0 ? 0.0 : 10.0);
    recording.measured_deg.push_back(t % 2 == 0 ? 10.0 : 0.0);
    recording.scored.push_back(t < 3 ? 0 : 1);
  }
  EXPECT_EQ(ShiftMae(recording, 1), 0.0);
  EXPECT_EQ(ShiftMae(recording, 3), 0.0);
  EXPECT_EQ(BestShiftPrediction(recording, 6).shift_ticks, 1);

  recording.request_deg.assign(20, 5.0);
  EXPECT_EQ(BestShiftPrediction(recording, 6).shift_ticks, 0);
}

// l = 0, a = 1, v_max 2, theta_0 4: f(x) = x / 2 inside +-4. Tick 0 starts at measured 0
// remembering R(0) = 3: M(1) = 0 + f(3) = 1.5. Ticks 2, 3 undriven (as measured); tick 4
// restarts at measured 5 remembering R(4) = 8: M(5) = 5 + f(3) = 6.5.
TEST(ServoLadderTest, PaperModelPredictionWorkedByHand) {
  const JointModelParams p{2.0, 4.0, 0, 1};
  const ServoRecording recording{.drive = kDrive,
                                 .request_deg = {3, 3, 0, 0, 8, 8},
                                 .measured_deg = {0, 1, 9, 9, 5, 6},
                                 .scored = {1, 1, 0, 0, 1, 1}};
  const std::vector<double> predicted = PredictWithJointModel(p, recording);
  const std::vector<double> expected = {0, 1.5, 9, 9, 5, 6.5};
  ASSERT_EQ(predicted.size(), expected.size());
  for (size_t t = 0; t < expected.size(); ++t) EXPECT_NEAR(predicted[t], expected[t], 1e-12) << t;
}

// l = 1, a = 2: each driven run is eq. 3 stepped from the measured angle at its first tick t0,
// remembering R(t0), R(t0 - 1), R(t0 - 2) (R(0) before tick 0).
TEST(ServoLadderTest, PaperModelPredictionAgreesWithSteppingTheModel) {
  const JointModelParams p{3.0, 10.0, 1, 2};
  ServoRecording recording{.drive = kDrive};
  for (int t = 0; t < 40; ++t) {
    recording.request_deg.push_back(25.0 * std::sin(0.25 * t));
    recording.measured_deg.push_back(-5.0 + 0.7 * t);
    recording.scored.push_back(t < 18 || t >= 23 ? 1 : 0);
  }
  const std::vector<double> predicted = PredictWithJointModel(p, recording);
  const std::vector<double>& r = recording.request_deg;
  JointModelState first{recording.measured_deg[0], {r[0], r[0], r[0]}};
  JointModelState second{recording.measured_deg[23], {r[23], r[22], r[21]}};
  for (size_t t = 0; t < 40; ++t) {
    double expected = recording.measured_deg[t];
    if (t >= 1 && t < 18) expected = StepJointModel(p, first, r[t]);
    if (t >= 24) expected = StepJointModel(p, second, r[t]);
    EXPECT_EQ(predicted[t], expected) << t;
  }
  EXPECT_THROW(PredictWithJointModel({0.0, 10.0, 1, 2}, recording), std::invalid_argument);
}

// Steps of several sizes and a sine past the top speed, simulated by eq. 3 from rest at 0;
// ticks 80..89 are undriven and measure nonsense, splitting the recording into two runs.
ServoRecording PaperModelRecording(const JointModelParams& truth) {
  ServoRecording recording{.drive = kDrive};
  for (int t = 0; t < 170; ++t) {
    const double step = t < 10 ? 0.0 : t < 30 ? 4.0 : t < 50 ? 20.0 : t < 70 ? -15.0 : 5.0;
    recording.request_deg.push_back(t < 95 ? step
                                           : 30.0 * std::sin(2 * std::numbers::pi * t / 20.0));
  }
  JointModelState state = RestState(truth, 0.0);
  for (int t = 0; t < 170; ++t) {
    const double angle = StepJointModel(truth, state, recording.request_deg[t]);
    const bool driven = t < 80 || t >= 90;
    recording.measured_deg.push_back(driven ? angle : 1000.0);
    recording.scored.push_back(driven ? 1 : 0);
  }
  return recording;
}

TEST(ServoLadderTest, PaperModelFitRecoversTheModel) {
  const JointModelParams truth{3.0, 10.0, 1, 2};
  const std::vector<ServoRecording> recordings = {PaperModelRecording(truth)};
  const IdentificationOptions options{
      .lag_min_ticks = 0, .lag_max_ticks = 3, .accel_min_ticks = 1, .accel_max_ticks = 4};
  const IdentificationResult fit = FitJointModelToRecordings(recordings, options);
  EXPECT_EQ(fit.params.lag_ticks, 1);
  EXPECT_EQ(fit.params.accel_ticks, 2);
  EXPECT_NEAR(fit.params.v_max_deg_per_tick, 3.0, 1e-4);
  EXPECT_NEAR(fit.params.theta0_deg, 10.0, 1e-4);
  EXPECT_LT(fit.rms_residual_deg, 1e-4);
}

// lag_max + accel_max = 7: runs of 7 driven ticks are too short to score, one of 8 is not.
TEST(ServoLadderTest, PaperModelFitNeedsARunLongerThanTheWarmUp) {
  const IdentificationOptions options{
      .lag_min_ticks = 0, .lag_max_ticks = 3, .accel_min_ticks = 1, .accel_max_ticks = 4};
  ServoRecording recording{.drive = kDrive};
  for (int t = 0; t < 23; ++t) {
    recording.request_deg.push_back(t < 3 ? 0.0 : 10.0);
    recording.measured_deg.push_back(0.5 * t);
    recording.scored.push_back(t == 7 || t == 15 ? 0 : 1);  // runs of 7, 7 and 7
  }
  EXPECT_THROW(FitJointModelToRecordings(std::vector{recording}, options), std::invalid_argument);
  recording.scored[7] = 1;  // runs of 8, 6 and 7
  recording.scored[8] = 0;
  EXPECT_NO_THROW(FitJointModelToRecordings(std::vector{recording}, options));
}

// The runs are cut by the scored ticks: a recording whose columns differ in length must be
// rejected before any is read past its end.
TEST(ServoLadderTest, PaperModelFitRejectsMismatchedSizes) {
  const IdentificationOptions options{
      .lag_min_ticks = 0, .lag_max_ticks = 1, .accel_min_ticks = 1, .accel_max_ticks = 1};
  ServoRecording recording = PaperModelRecording({3.0, 10.0, 1, 2});
  recording.measured_deg.resize(100);
  EXPECT_THROW(FitJointModelToRecordings(std::vector{recording}, options), std::invalid_argument);
  recording = PaperModelRecording({3.0, 10.0, 1, 2});
  recording.request_deg.resize(60);
  EXPECT_THROW(FitJointModelToRecordings(std::vector{recording}, options), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
