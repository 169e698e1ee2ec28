#include "leglab/servo/servo_log.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

// Samples at `times` (s) with request 10 * i deg, measured 4 * i deg and torque on.
std::vector<ServoLogSample> At(const std::vector<double>& times) {
  std::vector<ServoLogSample> samples;
  for (size_t i = 0; i < times.size(); ++i) {
    const double n = static_cast<double>(i);
    samples.push_back({.time_s = times[i], .request_deg = 10.0 * n, .measured_deg = 4.0 * n});
  }
  return samples;
}

TEST(Resample, ARequestStepBetweenSamplesIsHeldNotInterpolated) {
  // Requests 0, 10, 20 sent at 0, 1, 2 s; ticks of 0.25 s: 0, 0.25, ..., 2.
  const ResampledLog r = Resample(At({0.0, 1.0, 2.0}), 0.25);
  EXPECT_EQ(r.tick_s, 0.25);
  const std::vector<double> request{0, 0, 0, 0, 10, 10, 10, 10, 20};
  EXPECT_EQ(r.request_deg, request);
  // Measured 0, 4, 8 at the samples: 1 deg per quarter second between them.
  const std::vector<double> measured{0, 1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(r.measured_deg, measured);
  EXPECT_EQ(r.torque_enabled, std::vector<uint8_t>(9, 1));
}

TEST(Resample, AMeasuredRampIsInterpolatedExactlyOnJitteredSamples) {
  // Uneven sampling of measured = 3 t + 1 deg; every tick lies on the same line.
  const std::vector<double> times{0.0, 0.0061, 0.0098, 0.0171, 0.0205, 0.0262, 0.0330};
  std::vector<ServoLogSample> samples = At(times);
  for (ServoLogSample& s : samples) s.measured_deg = 3.0 * s.time_s + 1.0;
  const ResampledLog r = Resample(samples, 0.005);
  ASSERT_EQ(r.measured_deg.size(), 7u);  // 0, 5, ..., 30 ms; 35 ms is past the last sample
  for (size_t k = 0; k < r.measured_deg.size(); ++k) {
    EXPECT_NEAR(r.measured_deg[k], 3.0 * 0.005 * static_cast<double>(k) + 1.0, 1e-12) << k;
  }
  // The requests held: at 10 and 15 ms the latest sent is the one at 9.8 ms (index 2, 20 deg),
  // at 30 ms the one at 26.2 ms (index 5, 50 deg).
  const std::vector<double> request{0, 0, 20, 20, 30, 40, 50};
  EXPECT_EQ(r.request_deg, request);
}

TEST(Resample, TheGridEndsAtTheLastSampleWithin1e9Seconds) {
  EXPECT_EQ(Resample(At({10.0, 11.0}), 0.3).request_deg.size(), 4u);   // 10, 10.3, 10.6, 10.9
  EXPECT_EQ(Resample(At({10.0, 11.0}), 0.25).request_deg.size(), 5u);  // 11 itself included
  EXPECT_EQ(Resample(At({10.0, 11.0}), 2.0).request_deg.size(), 1u);   // the first sample only
  // 3 * 0.1 is 0.30000000000000004 in doubles: still at the last sample, within 1e-9 s.
  const ResampledLog r = Resample(At({0.0, 0.3}), 0.1);
  ASSERT_EQ(r.measured_deg.size(), 4u);
  EXPECT_EQ(r.measured_deg.back(), 4.0);
  EXPECT_EQ(r.request_deg.back(), 10.0);
  EXPECT_EQ(Resample(At({0.0, 1.0 - 0.5e-9}), 0.5).request_deg.size(), 3u);
  EXPECT_EQ(Resample(At({0.0, 1.0 - 2e-9}), 0.5).request_deg.size(), 2u);
}

TEST(Resample, ATorqueOffSampleMarksTheTicksAroundIt) {
  std::vector<ServoLogSample> samples = At({0.0, 1.0, 2.0, 3.0, 4.0});
  samples[2].torque_enabled = false;
  const ResampledLog r = Resample(samples, 0.5);
  // Ticks 0, 0.5, ..., 4: off from 1.5 (between on and off) to 2.5 (between off and on).
  const std::vector<uint8_t> torque{1, 1, 1, 0, 0, 0, 1, 1, 1};
  EXPECT_EQ(r.torque_enabled, torque);
}

TEST(Resample, BadInputThrows) {
  const std::vector<ServoLogSample> ok = At({0.0, 1.0});
  for (double tick : {0.0, -0.1, std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::infinity()}) {
    EXPECT_THROW(Resample(ok, tick), std::invalid_argument) << tick;
  }
  EXPECT_THROW(Resample(At({}), 0.1), std::invalid_argument);
  EXPECT_THROW(Resample(At({0.0}), 0.1), std::invalid_argument);
  EXPECT_THROW(Resample(At({0.0, 1.0, 1.0}), 0.1), std::invalid_argument);  // duplicated
  EXPECT_THROW(Resample(At({0.0, 1.0, 0.5}), 0.1), std::invalid_argument);  // going back
  EXPECT_THROW(Resample(At({0.0, std::numeric_limits<double>::infinity()}), 0.1),
               std::invalid_argument);
  EXPECT_THROW(Resample(At({0.0, 1e6}), 1e-6), std::invalid_argument);  // 1e12 ticks
}

TEST(MedianSampleInterval, OfAHandList) {
  // Differences 1, 2, 0.5, 4: the middle two of 0.5, 1, 2, 4 are 1 and 2.
  EXPECT_EQ(MedianSampleInterval(At({0.0, 1.0, 3.0, 3.5, 7.5})), 1.5);
  // Differences 0.5, 2, 0.5: the middle one is 0.5.
  EXPECT_EQ(MedianSampleInterval(At({0.0, 0.5, 2.5, 3.0})), 0.5);
  EXPECT_EQ(MedianSampleInterval(At({2.0, 2.25})), 0.25);
  EXPECT_THROW(MedianSampleInterval(At({0.0})), std::invalid_argument);
}

TEST(MedianSampleInterval, PoolsTheDifferencesOfAllLogs) {
  // Differences 1, 1 and 3, 4, 5 pooled: 1, 1, 3, 4, 5 -> 3 (the median of the two logs'
  // medians would be 2.5). A log of one sample adds nothing.
  std::vector<ServoLog> logs(3);
  logs[0].samples = At({0.0, 1.0, 2.0});
  logs[1].samples = At({0.0, 3.0, 7.0, 12.0});
  logs[2].samples = At({5.0});
  EXPECT_EQ(MedianSampleInterval(std::span<const ServoLog>(logs)), 3.0);
  logs.resize(1);
  EXPECT_EQ(MedianSampleInterval(std::span<const ServoLog>(logs)), 1.0);
  EXPECT_THROW(MedianSampleInterval(std::span<const ServoLog>()), std::invalid_argument);
  logs[0].samples = At({5.0});
  EXPECT_THROW(MedianSampleInterval(std::span<const ServoLog>(logs)), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
