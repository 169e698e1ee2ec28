// The extended model's rollouts side by side (an internal class of the fit) against the model's
// own prediction, PredictServoRecording, recording by recording: the same bits, on both
// instruction sets, for any mix of lengths, gaps, lags and drives.

#include "servo_rollouts.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

namespace leglab {
namespace {

// Sum of squared errors of the model's own prediction, tick by tick in order (ticks it predicts
// as measured add exactly 0).
double ReferenceSquaredError(const ServoModelParams& p, const ServoRecording& r, double tick_s) {
  const std::vector<double> predicted = PredictServoRecording(p, r, tick_s);
  double sum = 0.0;
  for (size_t t = 0; t < predicted.size(); ++t) {
    if (r.scored[t] == 0) continue;
    const double e = predicted[t] - r.measured_deg[t];
    sum += e * e;
  }
  return sum;
}

// The instruction sets this processor runs, saying so when AVX2's is not among them.
std::vector<LaneInstructions> InstructionSets() {
  std::vector<LaneInstructions> sets = AvailableLaneInstructions();
  if (sets.size() == 1) std::printf("note: no AVX2 here: the baseline's lanes alone checked\n");
  return sets;
}

// Recordings of random lengths (1 to max_length ticks), drives and requests, measured as a
// smoothed request plus noise, with undriven stretches.
std::vector<ServoRecording> RandomRecordings(std::mt19937& rng, size_t count, size_t max_length) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<ServoRecording> recordings(count);
  for (ServoRecording& r : recordings) {
    r.drive = {.kp = 10.0 + 990.0 * unit(rng),
               .mass_kg = unit(rng) < 0.2 ? 0.0 : unit(rng),
               .length_m = 0.3 * unit(rng)};
    const auto n = 1 + static_cast<size_t>(unit(rng) * static_cast<double>(max_length));
    const double amplitude = 200.0 * unit(rng), rate = 0.2 * unit(rng);
    double measured = 0.0;
    bool driven = true;
    for (size_t t = 0; t < n; ++t) {
      if (unit(rng) < 0.01) driven = !driven;
      const double request = amplitude * std::sin(rate * static_cast<double>(t)) +
                             (unit(rng) < 0.05 ? 90.0 * (unit(rng) - 0.5) : 0.0);
      measured += 0.2 * (request - measured);
      r.request_deg.push_back(request);
      r.measured_deg.push_back(measured + unit(rng) - 0.5);
      r.scored.push_back(driven ? 1 : 0);
    }
  }
  return recordings;
}

ServoModelParams RandomParams(std::mt19937& rng, double tick_s) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return {.gain_per_deg_kp = std::exp(-12.0 + 8.0 * unit(rng)),
          .v_max_deg_s = 50.0 + 2000.0 * unit(rng),
          .stall_torque_nm = 0.05 + 3.0 * unit(rng),
          .friction_duty = unit(rng) < 0.2 ? 0.0 : 0.2 * unit(rng),
          .friction_load_ratio = 2.0 * unit(rng),
          .velocity_lag_s = tick_s * std::exp(-3.0 + 8.0 * unit(rng)),
          .lag_ticks = static_cast<int>(unit(rng) * 16.0)};
}

void ExpectSameBits(const ServoModelParams& p, std::span<const ServoRecording> recordings,
                    double tick_s) {
  const ServoRollouts rollouts(recordings, tick_s, p.lag_ticks);
  for (LaneInstructions instructions : InstructionSets()) {
    std::vector<double> sums;
    rollouts.SquaredErrors(p, sums, instructions);
    ASSERT_EQ(sums.size(), recordings.size());
    for (size_t k = 0; k < recordings.size(); ++k) {
      const double expected = ReferenceSquaredError(p, recordings[k], tick_s);
      EXPECT_EQ(std::bit_cast<uint64_t>(sums[k]), std::bit_cast<uint64_t>(expected))
          << "recording " << k << " of " << recordings.size() << " (" << recordings[k].scored.size()
          << " ticks), lag " << p.lag_ticks << ", instructions "
          << (instructions == LaneInstructions::kAvx2 ? "avx2" : "baseline") << ": " << sums[k]
          << " against " << expected;
    }
  }
}

TEST(ServoRolloutsTest, EachRecordingsErrorIsTheModelsOwnPredictionsBitForBit) {
  std::mt19937 rng(20261128);
  const double tick_s = 0.0053;
  for (size_t count : {1, 2, 3, 4, 5, 8, 9, 12, 13, 25, 40}) {
    for (size_t max_length : {1, 7, 300, 1500}) {
      const std::vector<ServoRecording> recordings = RandomRecordings(rng, count, max_length);
      for (int trial = 0; trial < 3; ++trial) {
        ExpectSameBits(RandomParams(rng, tick_s), recordings, tick_s);
      }
    }
  }
}

// An angle too large for the degrees' reduction sends its lane the scalar way (std::sin); the
// other lanes of its vector and its later ticks are unchanged.
TEST(ServoRolloutsTest, AnAngleBeyondTheReductionGoesTheScalarWayInItsLaneAlone) {
  std::mt19937 rng(7);
  const double tick_s = 0.0053;
  std::vector<ServoRecording> recordings = RandomRecordings(rng, 6, 400);
  for (ServoRecording& r : recordings) r.scored.assign(r.scored.size(), 1);
  recordings[2].measured_deg[0] = 3e15;  // the run starts there
  recordings[4].measured_deg.assign(recordings[4].measured_deg.size(), -2e16);
  for (int trial = 0; trial < 5; ++trial)
    ExpectSameBits(RandomParams(rng, tick_s), recordings, tick_s);
}

// The vectors chosen, by hand: a step of one vector costs as much as one of two, then one per
// vector. Nine equal recordings: 1 vector (4 lanes) takes 3 lengths (cost 2 x 3), 2 vectors take
// 2 (cost 2 x 2), 3 vectors take 1 (cost 3): 3. Three: 1 vector takes 1 length (cost 2), as 2
// and 3 do at a higher cost: 1. Nine of length 100 and three of 300: 3 vectors take 300 steps
// (cost 900), 2 vectors: 8 lanes, the three long ones and then the nine short ones on the
// others and on the long ones' lanes as they free: 300 steps (cost 600): 2.
TEST(ServoRolloutsTest, ChoosesTheVectorsOfTheFewestVectorSteps) {
  std::mt19937 rng(3);
  auto recordings_of = [&](std::vector<size_t> lengths) {
    std::vector<ServoRecording> recordings = RandomRecordings(rng, lengths.size(), 1);
    for (size_t k = 0; k < lengths.size(); ++k) {
      ServoRecording& r = recordings[k];
      r.request_deg.assign(lengths[k], 1.0);
      r.measured_deg.assign(lengths[k], 0.0);
      r.scored.assign(lengths[k], 1);
    }
    return recordings;
  };
  EXPECT_EQ(ServoRollouts(recordings_of(std::vector<size_t>(9, 50)), 0.01, 0).vectors(), 3u);
  EXPECT_EQ(ServoRollouts(recordings_of(std::vector<size_t>(3, 50)), 0.01, 0).vectors(), 1u);
  std::vector<size_t> mixed(9, 100);
  mixed.insert(mixed.end(), {300, 300, 300});
  EXPECT_EQ(ServoRollouts(recordings_of(mixed), 0.01, 0).vectors(), 2u);
}

}  // namespace
}  // namespace leglab
