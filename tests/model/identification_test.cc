#include "leglab/model/identification.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

// The prediction from measured(W - 1) + offset computed independently, by the joint model
// itself (SimulateJointModel) from the recorded requests before W.
std::vector<double> IndependentPrediction(const JointModelParams& p, const JointRecording& r,
                                          int warmup, double offset) {
  JointModelState start{r.measured_deg[warmup - 1] + offset, {}};
  for (int i = 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    start.past_requests_deg.push_back(r.request_deg[warmup - i]);
  }
  return SimulateJointModel(p, std::span(r.request_deg).subspan(warmup), start);
}

// A hand case that runs f both saturated and linear, and never within 1e-3 deg of a kink.
JointRecording HandRecording() {
  JointRecording r;
  r.request_deg = {0,   0,   0,   0,   0,   3,    3,   3,   12,  12,  12,  12,  -4,  -4,
                   -4,  -4,  -4,  1.5, 1.5, 2.5,  3.5, 4.5, 5.5, 6.5, 7.5, 8.5, 8.5, 8.5,
                   8.5, 8.5, 8.5, 8.5, 0.7, -2.1, 4.3, 4.3, 4.3, 4.3, 4.3, 4.3};
  for (size_t t = 0; t < r.request_deg.size(); ++t)
    r.measured_deg.push_back(0.1 * static_cast<double>(t) - 0.2);
  return r;
}

TEST(PredictionSensitivities, MatchCentralDifferencesAwayFromKinks) {
  const JointModelParams p{2.0, 6.0, 2, 3};
  const JointRecording r = HandRecording();
  const int warmup = 5;
  const double offset = 0.2;
  const std::vector<double> nominal = IndependentPrediction(p, r, warmup, offset);

  // Away from kinks: every term R(t-i) - M(t-1) at least 1e-3 deg from +-theta_0, and both
  // regimes of f exercised.
  int saturated = 0, linear = 0;
  for (size_t k = 0; k < nominal.size(); ++k) {
    const long t = warmup + static_cast<long>(k);
    const double previous = k == 0 ? r.measured_deg[warmup - 1] + offset : nominal[k - 1];
    for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
      const double x = r.request_deg[t - i] - previous;
      ASSERT_GT(std::abs(std::abs(x) - p.theta0_deg), 1e-3) << "tick " << t;
      (std::abs(x) > p.theta0_deg ? saturated : linear)++;
    }
  }
  ASSERT_GT(saturated, 10);
  ASSERT_GT(linear, 10);

  const PredictionSensitivities s = PredictRecordingSensitivities(p, r, warmup, offset);
  ASSERT_EQ(s.angle_deg.size(), nominal.size());
  ASSERT_EQ(s.d_log_v_max.size(), nominal.size());
  ASSERT_EQ(s.d_log_theta0.size(), nominal.size());
  ASSERT_EQ(s.d_start_offset.size(), nominal.size());
  const double h = 1e-6;
  auto scaled = [&](double v_factor, double theta_factor) {
    return JointModelParams{p.v_max_deg_per_tick * v_factor, p.theta0_deg * theta_factor,
                            p.lag_ticks, p.accel_ticks};
  };
  const auto v_up = IndependentPrediction(scaled(std::exp(h), 1.0), r, warmup, offset);
  const auto v_down = IndependentPrediction(scaled(std::exp(-h), 1.0), r, warmup, offset);
  const auto theta_up = IndependentPrediction(scaled(1.0, std::exp(h)), r, warmup, offset);
  const auto theta_down = IndependentPrediction(scaled(1.0, std::exp(-h)), r, warmup, offset);
  const auto start_up = IndependentPrediction(p, r, warmup, offset + h);
  const auto start_down = IndependentPrediction(p, r, warmup, offset - h);
  bool theta_matters = false;
  for (size_t k = 0; k < nominal.size(); ++k) {
    EXPECT_NEAR(s.angle_deg[k], nominal[k], 1e-12) << k;
    EXPECT_NEAR(s.d_log_v_max[k], (v_up[k] - v_down[k]) / (2 * h), 1e-7) << k;
    EXPECT_NEAR(s.d_log_theta0[k], (theta_up[k] - theta_down[k]) / (2 * h), 1e-7) << k;
    EXPECT_NEAR(s.d_start_offset[k], (start_up[k] - start_down[k]) / (2 * h), 1e-7) << k;
    theta_matters = theta_matters || std::abs(s.d_log_theta0[k]) > 0.1;
  }
  EXPECT_TRUE(theta_matters);
}

TEST(PredictionSensitivities, SaturatedRunIsLinearInTheTopSpeed) {
  // Every term saturated: M(t) = M(W-1) + v_max (t - W + 1), so dM/d ln v_max = v_max (t - W +
  // 1), dM/d ln theta_0 = 0 and dM/d start = 1.
  const JointModelParams p{2.0, 1.0, 1, 2};
  JointRecording r{std::vector<double>(20, 100.0), std::vector<double>(20, 0.0)};
  const int warmup = 4;
  const PredictionSensitivities s = PredictRecordingSensitivities(p, r, warmup);
  ASSERT_EQ(s.angle_deg.size(), 16u);
  for (size_t k = 0; k < s.angle_deg.size(); ++k) {
    EXPECT_DOUBLE_EQ(s.angle_deg[k], 2.0 * static_cast<double>(k + 1));
    EXPECT_DOUBLE_EQ(s.d_log_v_max[k], 2.0 * static_cast<double>(k + 1));
    EXPECT_EQ(s.d_log_theta0[k], 0.0);
    EXPECT_EQ(s.d_start_offset[k], 1.0);
  }
  EXPECT_THROW(PredictRecordingSensitivities(p, r, 2), std::invalid_argument);
}

// The squared error IdentifyJointModel minimises for fixed (l, a) and one recording, computed
// independently: the model started from measured(W - 1) + offset.
double IndependentSquaredError(const JointModelParams& p, const JointRecording& r, int warmup,
                               double offset) {
  const std::vector<double> predicted = IndependentPrediction(p, r, warmup, offset);
  double sum = 0.0;
  for (size_t k = 0; k < predicted.size(); ++k) {
    const double e = r.measured_deg[warmup + k] - predicted[k];
    sum += e * e;
  }
  return sum;
}

// Brute force over y = (ln v_max, ln theta_0, start offset): a 31^3 grid over center +- half,
// then 20 zooms, each 21^3 points spanning +-5 spacings of the previous grid around its best
// point (halving the spacing: a narrower zoom loses the minimum among the kinks of f), down to
// spacings of about 1e-7. Returns the best error, its point in `best`.
template <typename ErrorAt>
double GridZoomMinimum(const ErrorAt& error_at, double center[3], double half[3], double best[3]) {
  std::copy(center, center + 3, best);
  double best_error = error_at(best);
  const int kLevels = 20;
  const int kPoints = 21;
  const double kReach = 5.0;
  for (int level = 0; level <= kLevels; ++level) {
    const int points = level == 0 ? 31 : kPoints;
    for (int i = 0; i < points; ++i) {
      for (int j = 0; j < points; ++j) {
        for (int k = 0; k < points; ++k) {
          const int index[3] = {i, j, k};
          double y[3];
          for (int d = 0; d < 3; ++d) {
            y[d] = center[d] - half[d] + 2.0 * half[d] * index[d] / (points - 1);
          }
          const double e = error_at(y);
          if (e < best_error) best_error = e, std::copy(y, y + 3, best);
        }
      }
    }
    for (int d = 0; d < 3; ++d) {
      half[d] = kReach * (2.0 * half[d] / (points - 1));
      center[d] = best[d];
    }
  }
  return best_error;
}

// The fit of recording `r` (one, scored after `warmup`) is at least as low as the brute force's
// minimum of `error_at` from center +- half (they differ by about 1e-12 relative), at the same
// point (about 1e-7 apart in the logarithms).
template <typename ErrorAt>
void ExpectTheGridsMinimum(const IdentificationResult& fit, const JointRecording& r, int warmup,
                           const ErrorAt& error_at, double center[3], double half[3]) {
  double best[3];
  const double best_error = GridZoomMinimum(error_at, center, half, best);
  const double fit_error = fit.rms_residual_deg * fit.rms_residual_deg *
                           static_cast<double>(r.request_deg.size() - warmup);
  EXPECT_LE(fit_error, best_error * (1.0 + 1e-9));
  EXPECT_NEAR(std::log(fit.params.v_max_deg_per_tick), best[0], 1e-5);
  EXPECT_NEAR(std::log(fit.params.theta0_deg), best[1], 1e-5);
}

TEST(Identification, AgreesWithABruteForceGridOnASmallCase) {
  // One step-test cycle (after one to settle) of the model {2.5, 7, 2, 3} with 0.2 deg noise;
  // l and a fixed, so the fit is over v_max, theta_0 and the start offset only.
  const JointModelParams truth{2.5, 7.0, 2, 3};
  JointRecording r = ModelStepTests(truth, 0.2, 2, 3)[0];
  r.request_deg.erase(r.request_deg.begin(), r.request_deg.begin() + 88);
  r.measured_deg.erase(r.measured_deg.begin(), r.measured_deg.begin() + 88);
  IdentificationOptions options;
  options.lag_min_ticks = options.lag_max_ticks = 2;
  options.accel_min_ticks = options.accel_max_ticks = 3;
  const int warmup = 5;
  const IdentificationResult fit = IdentifyJointModel(std::vector<JointRecording>{r}, options);
  ASSERT_EQ(fit.params.lag_ticks, 2);
  ASSERT_EQ(fit.params.accel_ticks, 3);

  // ln v_max in [ln 1, ln 5], ln theta_0 in [ln 1, ln 20], the offset in [-1, 1] deg.
  auto error_at = [&](const double* y) {
    return IndependentSquaredError({std::exp(y[0]), std::exp(y[1]), 2, 3}, r, warmup, y[2]);
  };
  double center[3] = {0.5 * std::log(5.0), 0.5 * std::log(20.0), 0.0};
  double half[3] = {0.5 * std::log(5.0), 0.5 * std::log(20.0), 1.0};
  ExpectTheGridsMinimum(fit, r, warmup, error_at, center, half);
}

// A servo that runs at top speed until within a fraction of a degree of its request: one
// step-test cycle (after one to settle) of the model {2.5, 1.2, 3, 1} (v_max 2.08 theta_0, which
// swings about a request for ever) with 0.1 deg of noise. The fit keeps v_max <=
// kMaxFittedSpeedRatio theta_0, so its model settles; here the bound binds (the data ask for a
// sharper f), and the fit is the best model within it: the brute force of the test above over
// the same bounded set (a point beyond the ratio scores +infinity there too).
TEST(Identification, KeepsItsModelsSettlingAndIsTheBestThatDoes) {
  const JointModelParams truth{2.5, 1.2, 3, 1};
  ASSERT_FALSE(SettlesOnEveryCycle(truth));
  JointRecording r = ModelStepTests(truth, 0.1, 2, 5)[0];
  r.request_deg.erase(r.request_deg.begin(), r.request_deg.begin() + 88);
  r.measured_deg.erase(r.measured_deg.begin(), r.measured_deg.begin() + 88);
  IdentificationOptions options;
  options.lag_min_ticks = options.lag_max_ticks = truth.lag_ticks;
  options.accel_min_ticks = options.accel_max_ticks = truth.accel_ticks;
  const int warmup = truth.lag_ticks + truth.accel_ticks;
  const IdentificationResult fit = IdentifyJointModel(std::vector<JointRecording>{r}, options);
  EXPECT_TRUE(SettlesOnEveryCycle(fit.params));
  EXPECT_LE(fit.params.v_max_deg_per_tick, kMaxFittedSpeedRatio * fit.params.theta0_deg);
  EXPECT_GT(fit.params.v_max_deg_per_tick, (kMaxFittedSpeedRatio - 1e-4) * fit.params.theta0_deg);

  auto error_at = [&](const double* y) {
    const JointModelParams p{std::exp(y[0]), std::exp(y[1]), truth.lag_ticks, truth.accel_ticks};
    if (p.v_max_deg_per_tick > kMaxFittedSpeedRatio * p.theta0_deg) {
      return std::numeric_limits<double>::infinity();
    }
    return IndependentSquaredError(p, r, warmup, y[2]);
  };
  // ln v_max in [ln 1, ln 5], ln theta_0 in [ln 0.5, ln 8], which the ratio's line crosses.
  double center[3] = {0.5 * std::log(5.0), 0.5 * std::log(4.0), 0.0};
  double half[3] = {0.5 * std::log(5.0), 0.5 * std::log(16.0), 1.0};
  ExpectTheGridsMinimum(fit, r, warmup, error_at, center, half);
}

TEST(Identification, FindsThePreviousFitsOptimum) {
  // identification_benchmark's recordings: the step tests `identify` records (8 cycles after 5
  // to settle), through the model {2.5, 5.65, 4, 6}, plus 0.1 deg of noise (seed 1). Pinned:
  // what the previous fit (Nelder-Mead throughout, main at baec711) found on them, all digits.
  const JointModelParams truth{2.5, 5.65, 4, 6};
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<JointRecording> recordings;
  for (double theta : {40.0, 110.0}) {
    const std::vector<double> cycle = StepTestRequests(theta);
    std::vector<double> requests;
    for (int k = 0; k < 13; ++k) requests.insert(requests.end(), cycle.begin(), cycle.end());
    const std::vector<double> angles = SimulateJointModel(truth, requests, RestState(truth, 0.0));
    const long settled = 5L * 88;
    JointRecording r;
    r.request_deg.assign(requests.begin() + settled, requests.end());
    r.measured_deg.assign(angles.begin() + settled, angles.end());
    for (double& m : r.measured_deg) m += noise(rng);
    recordings.push_back(std::move(r));
  }
  const IdentificationResult fit = IdentifyJointModel(recordings);
  EXPECT_EQ(fit.params.lag_ticks, 4);
  EXPECT_EQ(fit.params.accel_ticks, 6);
  // The previous optimiser's own convergence on this kinked objective is about 1e-8.
  EXPECT_NEAR(fit.params.v_max_deg_per_tick, 2.5000111449146871, 1e-5 * 2.5);
  EXPECT_NEAR(fit.params.theta0_deg, 5.6489825444907336, 1e-5 * 5.65);
  EXPECT_NEAR(fit.rms_residual_deg, 0.099899525687072679, 1e-9 * 0.1);
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

TEST(AverageCycles, HandWorkedCase) {
  // Period 3, two cycles: the mean cycle is (11, 21, 31). With a warm-up of 4 ticks the
  // recording starts at the cycle's tick -4 mod 3 = 2, and 2 played cycles follow.
  const JointRecording run{{1, 2, 3, 1, 2, 3}, {10, 20, 30, 12, 22, 32}};
  const JointRecording averaged = AverageCycles(run, 3, 4, 2);
  EXPECT_EQ(averaged.request_deg, (std::vector<double>{3, 1, 2, 3, 1, 2, 3, 1, 2, 3}));
  EXPECT_EQ(averaged.measured_deg, (std::vector<double>{31, 11, 21, 31, 11, 21, 31, 11, 21, 31}));
  EXPECT_EQ(averaged.weight, 1.0);  // 2 cycles averaged, 2 played
  EXPECT_EQ(AverageCycles(run, 3, 0, 1).weight, 2.0);
  EXPECT_EQ(AverageCycles(run, 3, 0, 1).request_deg, (std::vector<double>{1, 2, 3}));
  EXPECT_THROW(AverageCycles(run, 4, 0, 1), std::invalid_argument);  // not whole cycles
  EXPECT_THROW(AverageCycles(run, 0, 0, 1), std::invalid_argument);
  EXPECT_THROW(AverageCycles(run, 3, -1, 1), std::invalid_argument);
  EXPECT_THROW(AverageCycles(run, 3, 0, 0), std::invalid_argument);
  const JointRecording changing{{1, 2, 3, 1, 2, 4}, {10, 20, 30, 12, 22, 32}};
  EXPECT_THROW(AverageCycles(changing, 3, 0, 1), std::invalid_argument);
  // The spread about the mean cycle: every sample 1 away from its tick's mean, 6 samples.
  EXPECT_EQ(CycleScatter(run, 3), 6.0);
  JointRecording weighted = run;
  weighted.weight = 2.5;
  EXPECT_EQ(CycleScatter(weighted, 3), 15.0);
  EXPECT_THROW(CycleScatter(run, 4), std::invalid_argument);
  EXPECT_THROW(CycleScatter(changing, 3), std::invalid_argument);
}

// A walk-like request cycle (a triangle wave with a plateau) of `period` ticks.
std::vector<double> WalkCycle(int period) {
  std::vector<double> cycle(period);
  for (int t = 0; t < period; ++t) {
    const double x = static_cast<double>(t) / period;
    cycle[t] = x < 0.4 ? 30.0 + 100.0 * x : (x < 0.5 ? 70.0 : 70.0 - 80.0 * (x - 0.5));
  }
  return cycle;
}

// `steps` cycles of `cycle` through the model `truth` after `warmup` cycles, with Gaussian noise.
JointRecording ModelWalk(const JointModelParams& truth, const std::vector<double>& cycle,
                         int warmup, int steps, double noise_deg, unsigned seed) {
  std::vector<double> requests;
  for (int k = 0; k < warmup + steps; ++k)
    requests.insert(requests.end(), cycle.begin(), cycle.end());
  const std::vector<double> angles =
      SimulateJointModel(truth, requests, RestState(truth, cycle[0]));
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_deg);
  JointRecording r;
  const size_t skip = static_cast<size_t>(warmup) * cycle.size();
  r.request_deg.assign(requests.begin() + static_cast<long>(skip), requests.end());
  r.measured_deg.assign(angles.begin() + static_cast<long>(skip), angles.end());
  for (double& m : r.measured_deg) m += noise(rng);
  return r;
}

TEST(AverageCycles, WeightedErrorIsThePooledOneUpToTheSpread) {
  // Against any prediction y that repeats every cycle (here the model's cyclic steady state),
  // by brute force: sum_k sum_t (m_k(t) - y(t))^2 = K sum_t (mean(t) - y(t))^2 + sum_k sum_t
  // (m_k(t) - mean(t))^2; the averaged recording's weighted error over its played cycles is
  // the first term on the right.
  const JointModelParams truth{2.5, 7.0, 4, 6};
  const std::vector<double> cycle = WalkCycle(40);
  const JointRecording run = ModelWalk(truth, cycle, 5, 6, 0.3, 11);
  const std::vector<double> y = CyclicSteadyState(JointModelParams{2.2, 5.0, 3, 5}, cycle);
  const int warmup = 7;
  const int played = 3;
  const JointRecording averaged = AverageCycles(run, 40, warmup, played);
  double pooled = 0.0;
  for (size_t i = 0; i < run.measured_deg.size(); ++i) {
    pooled += std::pow(run.measured_deg[i] - y[i % 40], 2);
  }
  double weighted = 0.0;
  for (size_t i = warmup; i < averaged.measured_deg.size(); ++i) {
    weighted += averaged.weight * std::pow(averaged.measured_deg[i] - y[(i - warmup) % 40], 2);
  }
  double spread = 0.0;
  for (size_t i = 0; i < run.measured_deg.size(); ++i) {
    spread += std::pow(run.measured_deg[i] - averaged.measured_deg[warmup + i % 40], 2);
  }
  EXPECT_NEAR(weighted + spread, pooled, 1e-9 * pooled);
  EXPECT_GT(spread, 0.0);
  EXPECT_NEAR(CycleScatter(run, 40), spread, 1e-9 * spread);
}

TEST(Identification, AWeightCountsARecordingThatManyTimes) {
  // A recording of weight 3 is the same objective as three copies of it: the same fit, up to
  // the optimiser's tolerance, and the same residual.
  const JointModelParams truth{2.5, 7.0, 4, 6};
  std::vector<JointRecording> copies = ModelStepTests(truth, 0.2, 2, 5);
  copies.push_back(copies[0]);
  copies.push_back(copies[0]);
  std::vector<JointRecording> weighted = ModelStepTests(truth, 0.2, 2, 5);
  weighted[0].weight = 3.0;
  const IdentificationResult a = IdentifyJointModel(copies);
  const IdentificationResult b = IdentifyJointModel(weighted);
  EXPECT_EQ(a.params.lag_ticks, b.params.lag_ticks);
  EXPECT_EQ(a.params.accel_ticks, b.params.accel_ticks);
  EXPECT_NEAR(a.params.v_max_deg_per_tick, b.params.v_max_deg_per_tick, 1e-4);
  EXPECT_NEAR(a.params.theta0_deg, b.params.theta0_deg, 1e-3);
  EXPECT_NEAR(a.rms_residual_deg, b.rms_residual_deg, 1e-6);
  JointRecording bad = weighted[0];
  for (const double w : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    bad.weight = w;
    EXPECT_THROW(IdentifyJointModel(std::vector<JointRecording>{bad}), std::invalid_argument) << w;
  }
}

TEST(Identification, AveragedWalkRecoversTheModel) {
  // A model plant walked 16 noisy cycles, pooled with its step tests: the fit to the averaged
  // cycle finds the model, as the fit to all 16 cycles does.
  for (const JointModelParams& truth :
       {JointModelParams{2.5, 7.0, 4, 6}, JointModelParams{3.2, 5.0, 6, 3}}) {
    const IdentificationOptions options{2, 8, 1, 10};
    const JointRecording walk = ModelWalk(truth, WalkCycle(88), 5, 16, 0.2, 3);
    std::vector<JointRecording> pooled = ModelStepTests(truth, 0.2, 2, 9);
    std::vector<JointRecording> averaged = pooled;
    pooled.push_back(walk);
    averaged.push_back(AverageCycles(walk, 88, 8 + 10, 2));
    const IdentificationResult full = IdentifyJointModel(pooled, options);
    const IdentificationResult fit = IdentifyJointModel(averaged, options);
    EXPECT_EQ(fit.params.lag_ticks, truth.lag_ticks);
    EXPECT_EQ(fit.params.accel_ticks, truth.accel_ticks);
    EXPECT_NEAR(fit.params.v_max_deg_per_tick, truth.v_max_deg_per_tick, 0.05);
    EXPECT_NEAR(fit.params.theta0_deg, truth.theta0_deg, 0.3);
    EXPECT_EQ(fit.params.lag_ticks, full.params.lag_ticks);
    EXPECT_EQ(fit.params.accel_ticks, full.params.accel_ticks);
    EXPECT_NEAR(fit.params.v_max_deg_per_tick, full.params.v_max_deg_per_tick, 0.02);
    EXPECT_NEAR(fit.params.theta0_deg, full.params.theta0_deg, 0.1);
  }
}

}  // namespace
}  // namespace leglab
