// The paper model's sweeps in lanes (an internal class of the fit) against the model's own
// sensitivities, PredictRecordingSensitivities, summed tick by tick: the same bits on both
// instruction sets, for held and changing requests, any lag, window and start offset.

#include "paper_sensitivity_lanes.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

namespace leglab {
namespace {

// The fit's sums over the model's own sweep, in tick order.
PaperNormalEquations Reference(const JointModelParams& p, const JointRecording& r, int warmup,
                               double offset) {
  const PredictionSensitivities s = PredictRecordingSensitivities(p, r, warmup, offset);
  PaperNormalEquations q;
  for (size_t i = 0; i < s.angle_deg.size(); ++i) {
    const double e = r.measured_deg[static_cast<size_t>(warmup) + i] - s.angle_deg[i];
    const double d_v = s.d_log_v_max[i], d_theta = s.d_log_theta0[i], d_s = s.d_start_offset[i];
    q.squared_error += e * e;
    q.vv += d_v * d_v, q.vt += d_v * d_theta, q.tt += d_theta * d_theta;
    q.ve += d_v * e, q.te += d_theta * e;
    q.vs += d_v * d_s, q.ts += d_theta * d_s, q.ss += d_s * d_s;
    q.se += d_s * e;
  }
  return q;
}

std::vector<int> RunEndsOf(const std::vector<double>& requests) {
  std::vector<int> end(requests.size());
  for (size_t t = requests.size(); t-- > 0;) {
    end[t] = t + 1 < requests.size() && requests[t] == requests[t + 1] ? end[t + 1]
                                                                       : static_cast<int>(t);
  }
  return end;
}

// Recordings longer than `warmup`: requests held for runs of 1 to `max_run` ticks (1: changing
// every tick, as a servo's log; more: as a step test), measured as a smoothed request plus noise.
std::vector<JointRecording> RandomRecordings(std::mt19937& rng, size_t count, int warmup,
                                             int max_run) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<JointRecording> recordings(count);
  for (JointRecording& r : recordings) {
    const size_t n = static_cast<size_t>(warmup) + 1 + static_cast<size_t>(unit(rng) * 600.0);
    double request = 0.0, measured = 0.0;
    int held = 0;
    for (size_t t = 0; t < n; ++t) {
      if (held-- <= 0) {
        request = 100.0 * (unit(rng) - 0.5);
        held = static_cast<int>(unit(rng) * max_run);
      }
      measured += 0.3 * (request - measured);
      r.request_deg.push_back(request);
      r.measured_deg.push_back(measured + 0.2 * (unit(rng) - 0.5));
    }
  }
  return recordings;
}

uint64_t BitsOf(double x) { return std::bit_cast<uint64_t>(x); }

TEST(PaperSensitivityLanesTest, EachRecordingsSumsAreTheModelsOwnSensitivitiesBitForBit) {
  std::mt19937 rng(20261128);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::vector<LaneInstructions> sets = AvailableLaneInstructions();
  if (sets.size() == 1) std::printf("note: no AVX2 here: the baseline's lanes alone checked\n");
  for (int max_run : {1, 2, 30}) {
    for (size_t count : {1, 3, 4, 5, 9, 13}) {
      const int warmup = 2 + static_cast<int>(unit(rng) * 40.0);
      const std::vector<JointRecording> recordings = RandomRecordings(rng, count, warmup, max_run);
      std::vector<std::vector<int>> run_ends(count);
      std::vector<SweptRecording> swept(count);
      for (size_t k = 0; k < count; ++k) {
        run_ends[k] = RunEndsOf(recordings[k].request_deg);
        swept[k] = {&recordings[k], run_ends[k]};
      }
      const PaperSensitivityLanes sweeps(swept, warmup);
      for (int trial = 0; trial < 4; ++trial) {
        JointModelParams p;
        p.accel_ticks = 1 + static_cast<int>(unit(rng) * (warmup - 1));
        p.lag_ticks = static_cast<int>(unit(rng) * (warmup - p.accel_ticks + 1));
        p.theta0_deg = std::exp(-1.0 + 6.0 * unit(rng));
        p.v_max_deg_per_tick = p.theta0_deg * 2.0 * unit(rng);
        std::vector<double> offsets;
        const bool with_starts = trial % 2 == 1;
        if (with_starts) {
          for (size_t k = 0; k < count; ++k) offsets.push_back(4.0 * (unit(rng) - 0.5));
        }
        for (LaneInstructions instructions : sets) {
          std::vector<PaperNormalEquations> got;
          sweeps.Accumulate(p, offsets, with_starts, got, instructions);
          ASSERT_EQ(got.size(), count);
          for (size_t k = 0; k < count; ++k) {
            const PaperNormalEquations want =
                Reference(p, recordings[k], warmup, with_starts ? offsets[k] : 0.0);
            const PaperNormalEquations& q = got[k];
            SCOPED_TRACE(::testing::Message()
                         << "runs up to " << max_run << ", recording " << k << " of " << count
                         << ", l " << p.lag_ticks << ", a " << p.accel_ticks << ", warm-up "
                         << warmup << (instructions == LaneInstructions::kAvx2 ? ", avx2" : ""));
            EXPECT_EQ(BitsOf(q.squared_error), BitsOf(want.squared_error));
            EXPECT_EQ(BitsOf(q.vv), BitsOf(want.vv));
            EXPECT_EQ(BitsOf(q.vt), BitsOf(want.vt));
            EXPECT_EQ(BitsOf(q.tt), BitsOf(want.tt));
            EXPECT_EQ(BitsOf(q.ve), BitsOf(want.ve));
            EXPECT_EQ(BitsOf(q.te), BitsOf(want.te));
            if (with_starts) {
              EXPECT_EQ(BitsOf(q.vs), BitsOf(want.vs));
              EXPECT_EQ(BitsOf(q.ts), BitsOf(want.ts));
              EXPECT_EQ(BitsOf(q.ss), BitsOf(want.ss));
              EXPECT_EQ(BitsOf(q.se), BitsOf(want.se));
            } else {
              EXPECT_EQ(q.vs, 0.0);
              EXPECT_EQ(q.se, 0.0);
            }
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace leglab
