#include "leglab/model/identification.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "leglab/model/trajectories.h"

namespace leglab {
namespace {

// Step tests of eq. 1 (theta_test 40 and 110), `cycles` cycles each, run through the model
// `truth` with Gaussian noise of `noise_deg` on the measured angle.
std::vector<JointRecording> ModelStepTests(const JointModelParams& truth, double noise_deg,
                                           int cycles, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_deg);
  std::vector<JointRecording> recordings;
  for (double theta : {40.0, 110.0}) {
    const std::vector<double> cycle = StepTestRequests(theta);
    JointRecording r;
    for (int k = 0; k < cycles; ++k) {
      r.request_deg.insert(r.request_deg.end(), cycle.begin(), cycle.end());
    }
    r.measured_deg = SimulateJointModel(truth, r.request_deg, RestState(truth, 0.0));
    if (noise_deg > 0.0) {
      for (double& m : r.measured_deg) m += noise(rng);
    }
    recordings.push_back(std::move(r));
  }
  return recordings;
}

TEST(Identification, RecoversExactParametersFromCleanData) {
  const JointModelParams truth{2.5, 7.0, 4, 6};
  const IdentificationResult fit = IdentifyJointModel(ModelStepTests(truth, 0.0, 3, 1));
  EXPECT_EQ(fit.params.lag_ticks, 4);
  EXPECT_EQ(fit.params.accel_ticks, 6);
  EXPECT_NEAR(fit.params.v_max_deg_per_tick, 2.5, 1e-4);
  EXPECT_NEAR(fit.params.theta0_deg, 7.0, 1e-3);
  EXPECT_LT(fit.rms_residual_deg, 1e-4);
}

TEST(Identification, RecoversParametersFromNoisyData) {
  for (unsigned seed : {42u, 7u}) {
    for (const JointModelParams& truth :
         {JointModelParams{2.5, 7.0, 4, 6}, JointModelParams{3.2, 5.0, 7, 3},
          JointModelParams{1.6, 9.0, 1, 10}}) {
      const double noise = 0.2;
      const IdentificationResult fit = IdentifyJointModel(ModelStepTests(truth, noise, 3, seed));
      EXPECT_EQ(fit.params.lag_ticks, truth.lag_ticks);
      EXPECT_EQ(fit.params.accel_ticks, truth.accel_ticks);
      EXPECT_NEAR(fit.params.v_max_deg_per_tick, truth.v_max_deg_per_tick, 0.05);
      EXPECT_NEAR(fit.params.theta0_deg, truth.theta0_deg, 0.3);
      // The residual is the measurement noise: the RMS of N Gaussian samples has a standard
      // deviation of about sigma / sqrt(2 N); N = 2 recordings x (264 - 24 warm-up) ticks = 480,
      // so four of those are 4 * 0.2 / sqrt(960) = 0.026 deg.
      EXPECT_NEAR(fit.rms_residual_deg, noise, 4.0 * noise / std::sqrt(2.0 * 480.0));
    }
  }
}

TEST(Identification, PredictionStartsFromTheMeasurementAfterTheWarmUp) {
  const JointModelParams p{2.5, 7.0, 4, 6};
  const auto recordings = ModelStepTests(p, 0.0, 2, 1);
  const std::vector<double> predicted = PredictRecording(p, recordings[0], 24);
  ASSERT_EQ(predicted.size(), recordings[0].measured_deg.size());
  for (size_t t = 0; t < predicted.size(); ++t) {
    EXPECT_NEAR(predicted[t], recordings[0].measured_deg[t], 1e-9) << t;
  }
}

TEST(Identification, RejectsBadRecordings) {
  EXPECT_THROW(IdentifyJointModel({}), std::invalid_argument);
  std::vector<JointRecording> mismatched{{{1.0, 2.0, 3.0}, {1.0, 2.0}}};
  EXPECT_THROW(IdentifyJointModel(mismatched), std::invalid_argument);
  std::vector<JointRecording> short_one{
      {std::vector<double>(10, 1.0), std::vector<double>(10, 1.0)}};
  EXPECT_THROW(IdentifyJointModel(short_one), std::invalid_argument);
  std::vector<JointRecording> still{{std::vector<double>(100, 1.0), std::vector<double>(100, 1.0)}};
  EXPECT_THROW(IdentifyJointModel(still), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
