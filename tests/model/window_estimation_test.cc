#include "leglab/model/window_estimation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace leglab {
namespace {

// Two 88-tick cycles of a sine of `amplitude_deg` requested directly, run through the model
// `truth` from rest, with Gaussian noise of 0.1 deg on the measured angle.
JointRecording SineWindow(const JointModelParams& truth, double amplitude_deg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.1);
  JointRecording r;
  for (int t = 0; t < 3 * 88; ++t) {
    r.request_deg.push_back(20.0 + amplitude_deg * std::sin(2.0 * std::numbers::pi * t / 88.0));
  }
  r.measured_deg = SimulateJointModel(truth, r.request_deg, RestState(truth, 20.0));
  for (double& m : r.measured_deg) m += noise(rng);
  // The last two cycles: the joint is in its periodic motion, as in a walk.
  r.request_deg.erase(r.request_deg.begin(), r.request_deg.begin() + 88);
  r.measured_deg.erase(r.measured_deg.begin(), r.measured_deg.begin() + 88);
  return r;
}

const JointModelParams kTruth{2.0, 6.0, 5, 4};

// A 40 deg sine asks for up to 2.86 deg/tick, beyond v_max = 2: the joint saturates and every
// parameter shows. From the paper's model (l and a within the radius of 2) one window gives
// the truth back, to within what 0.1 deg of noise allows.
TEST(WindowEstimation, RecoversTheModelFromASaturatingWindowWithNoise) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const WindowEstimate e =
        EstimateJointModelInWindow(SineWindow(kTruth, 40.0, seed), JointModelParams{2.5, 7, 4, 6});
    EXPECT_TRUE(e.v_max_identified) << seed;
    EXPECT_EQ(e.fit.params.lag_ticks, 5) << seed;
    EXPECT_EQ(e.fit.params.accel_ticks, 4) << seed;
    EXPECT_NEAR(e.fit.params.v_max_deg_per_tick, 2.0, 0.05) << seed;
    EXPECT_NEAR(e.fit.params.theta0_deg, 6.0, 0.5) << seed;
    EXPECT_NEAR(e.fit.rms_residual_deg, 0.1, 0.02) << seed;  // the noise, nothing more
  }
}

// From far away (l = 0, a = 1) each update moves l and a by at most 2: three updates reach
// l = 5, a = 4.
TEST(WindowEstimation, SlidesTowardsTheTruthWithinItsRadius) {
  JointModelParams current{3.5, 3.0, 0, 1};
  for (int update = 0; update < 3; ++update) {
    const JointModelParams before = current;
    current = EstimateJointModelInWindow(SineWindow(kTruth, 40.0, 7 + update), current).fit.params;
    EXPECT_LE(std::abs(current.lag_ticks - before.lag_ticks), 2);
    EXPECT_LE(std::abs(current.accel_ticks - before.accel_ticks), 2);
  }
  EXPECT_EQ(current.lag_ticks, 5);
  EXPECT_EQ(current.accel_ticks, 4);
  EXPECT_NEAR(current.v_max_deg_per_tick, 2.0, 0.05);
}

// A 3 deg sine never takes the request theta_0 = 6 deg away from the angle: eq. 2 is the line
// (v_max / theta_0) x there, so only that slope (1/3 per tick) can be learned; v_max stays
// where it was.
TEST(WindowEstimation, KeepsVmaxAndLearnsTheSlopeWhenTheJointNeverSaturates) {
  const WindowEstimate e =
      EstimateJointModelInWindow(SineWindow(kTruth, 3.0, 4), JointModelParams{3.5, 7, 5, 4});
  EXPECT_FALSE(e.v_max_identified);
  EXPECT_EQ(e.fit.params.v_max_deg_per_tick, 3.5);
  EXPECT_NEAR(e.fit.params.v_max_deg_per_tick / e.fit.params.theta0_deg, 2.0 / 6.0, 0.03);
}

TEST(WindowEstimation, BadInputThrows) {
  EXPECT_THROW(EstimateJointModelInWindow(SineWindow(kTruth, 40.0, 1), JointModelParams{}),
               std::invalid_argument);
  JointRecording still{std::vector<double>(100, 1.0), std::vector<double>(100, 1.0)};
  EXPECT_THROW(EstimateJointModelInWindow(still, kTruth), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
