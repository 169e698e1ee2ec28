// FitSample: which ticks a log fit sees when the training logs hold more than logs.fit_ticks.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "leglab/servo/log_fit.h"

namespace {

using leglab::FitSample;
using leglab::kFitChunkTicks;
using leglab::ServoRecording;

// A recording whose request at tick t is t, so that a sample says which ticks it took.
ServoRecording Numbered(size_t n, double kp = 100.0) {
  ServoRecording r;
  r.drive = {.kp = kp, .mass_kg = 0.5, .length_m = 0.1};
  for (size_t t = 0; t < n; ++t) {
    r.request_deg.push_back(static_cast<double>(t));
    r.measured_deg.push_back(-static_cast<double>(t));
    r.scored.push_back(1);
  }
  return r;
}

TEST(FitSampleTest, AtOrUnderTheBudgetTheRecordingsAreAsTheyAre) {
  const std::vector<ServoRecording> train = {Numbered(30), Numbered(20)};
  for (const long budget : {0L, 50L, 1000L}) {
    const std::vector<ServoRecording> sample = FitSample(train, budget, 3);
    ASSERT_EQ(sample.size(), 2u);
    EXPECT_EQ(sample[0].request_deg, train[0].request_deg) << budget;
    EXPECT_EQ(sample[1].scored, train[1].scored) << budget;
  }
}

// 10 ticks, a budget of 4: one chunk of 4 in the middle (ticks 3..6), after one lead tick
// (tick 2) marked undriven.
TEST(FitSampleTest, OneChunkSitsInTheMiddleAfterItsLead) {
  const std::vector<ServoRecording> sample = FitSample(std::vector{Numbered(10, 7.0)}, 4, 1);
  ASSERT_EQ(sample.size(), 1u);
  EXPECT_EQ(sample[0].request_deg, (std::vector<double>{2, 3, 4, 5, 6}));
  EXPECT_EQ(sample[0].measured_deg, (std::vector<double>{-2, -3, -4, -5, -6}));
  EXPECT_EQ(sample[0].scored, (std::vector<uint8_t>{0, 1, 1, 1, 1}));
  EXPECT_EQ(sample[0].drive.kp, 7.0);
}

// 5000 ticks, a budget of 2500: ceil(2500 / 1000) = 3 chunks of 833, at 0, (5000 - 833) / 2 =
// 2083 and 4167 (the last ends at the recording's end), the later two after a lead of 2.
TEST(FitSampleTest, ChunksSpreadFromTheStartToTheEnd) {
  ASSERT_EQ(kFitChunkTicks, 1000);
  const std::vector<ServoRecording> sample = FitSample(std::vector{Numbered(5000)}, 2500, 2);
  const ServoRecording& s = sample.at(0);
  ASSERT_EQ(s.request_deg.size(), 3u * 833u + 2u * 2u);
  EXPECT_EQ(s.request_deg.front(), 0.0);
  EXPECT_EQ(s.request_deg[832], 832.0);
  EXPECT_EQ(s.request_deg[833], 2081.0);  // the second chunk's lead
  EXPECT_EQ(s.scored[833], 0);
  EXPECT_EQ(s.scored[834], 0);
  EXPECT_EQ(s.request_deg[835], 2083.0);
  EXPECT_EQ(s.scored[835], 1);
  EXPECT_EQ(s.request_deg.back(), 4999.0);
  long driven = 0;
  for (const uint8_t on : s.scored) driven += on;
  EXPECT_EQ(driven, 3 * 833);
}

// Shares in proportion to length: 3000 and 1000 ticks, a budget of 2000, keep 1500 and 500.
// An undriven tick in a chunk stays undriven.
TEST(FitSampleTest, EachRecordingKeepsItsShare) {
  std::vector<ServoRecording> train = {Numbered(3000), Numbered(1000)};
  train[1].scored[500] = 0;
  const std::vector<ServoRecording> sample = FitSample(train, 2000, 0);
  ASSERT_EQ(sample.size(), 2u);
  EXPECT_EQ(sample[0].request_deg.size(), 1500u);  // 2 chunks of 750
  EXPECT_EQ(sample[0].request_deg[750], 2250.0);
  ASSERT_EQ(sample[1].request_deg.size(), 500u);  // 1 chunk, ticks 250..749
  EXPECT_EQ(sample[1].request_deg.front(), 250.0);
  EXPECT_EQ(sample[1].scored[250], 0);
}

TEST(FitSampleTest, ANegativeBudgetOrLeadIsRefused) {
  const std::vector<ServoRecording> train = {Numbered(10)};
  EXPECT_THROW(FitSample(train, -1, 0), std::invalid_argument);
  EXPECT_THROW(FitSample(train, 5, -1), std::invalid_argument);
}

}  // namespace
