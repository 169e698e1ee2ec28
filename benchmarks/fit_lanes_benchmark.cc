// The log fit's two inner loops, recordings side by side in vector lanes, against the same
// arithmetic one recording at a time (the same bits; tests/servo/servo_rollouts_test.cc and
// paper_sensitivity_lanes_test.cc check that):
//
//   extended rollouts  one evaluation of the extended model's fit objective: every
//                      recording's squared prediction error (ServoRollouts), against
//                      servo_tick::Advance run over each recording in turn;
//   paper sweeps       one evaluation of the paper model's normal equations
//                      (PaperSensitivityLanes, l 2, a 20), against
//                      PredictRecordingSensitivities summed per recording (which also stores
//                      its four series: a little of its cost).
//
// Each on the baseline instructions and, where the processor has them, AVX2. The recordings: 12
// of the XL330 as the shipped logs are (nine of 1134 ticks, three of 378; kp 100, 400, 800;
// requests changing every tick), measured as the shipped model predicts plus 0.05 deg of seeded
// noise. Then medians of interleaved rounds, as ratios. Usage: fit_lanes_benchmark
// [--benchmark_* flags] [--rounds=N]

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>
#include <vector>

#include "leglab/model/identification.h"
#include "leglab/servo/servo_model.h"
#include "paper_sensitivity_lanes.h"
#include "rounds_flag.h"
#include "servo_model_tick.h"
#include "servo_rollouts.h"
#include "xl330_model.h"

namespace {

using namespace leglab;

constexpr double kTickS = benchmarks::kXl330TickS;
constexpr JointModelParams kPaper{
    .v_max_deg_per_tick = 3.0, .theta0_deg = 40.0, .lag_ticks = 2, .accel_ticks = 20};
constexpr int kWarmup = 48;  // the log fit's: l up to 11 and a up to 37 ticks at 5.3 ms

std::vector<ServoRecording> Recordings() {
  std::vector<ServoRecording> recordings;
  std::mt19937 random(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int k = 0; k < 12; ++k) {
    ServoRecording r;
    r.drive = {.kp = k % 3 == 0   ? 100.0
                     : k % 3 == 1 ? 400.0
                                  : 800.0,
               .mass_kg = 0.49,
               .length_m = 0.1};
    const size_t ticks = k < 9 ? 1134 : 378;
    ServoModelState state = ServoRestState(benchmarks::kXl330Extended, 0.0);
    for (size_t t = 0; t < ticks; ++t) {
      const double s = static_cast<double>(t) * kTickS;
      const double request = 60.0 * std::sin(2.0 * std::numbers::pi * (0.3 + 0.1 * k) * s) +
                             15.0 * std::sin(2.0 * std::numbers::pi * 2.1 * s);
      r.request_deg.push_back(request);
      r.measured_deg.push_back(
          StepServoModel(benchmarks::kXl330Extended, r.drive, kTickS, state, request) +
          noise(random));
      r.scored.push_back(1);
    }
    recordings.push_back(std::move(r));
  }
  return recordings;
}

// The extended model's squared errors, one recording after another.
double ScalarRollouts(std::span<const ServoRecording> recordings) {
  const ServoModelParams& p = benchmarks::kXl330Extended;
  const double blend = servo_tick::VelocityBlend(p, kTickS);
  const auto lag = static_cast<size_t>(p.lag_ticks);
  double total = 0.0;
  for (const ServoRecording& r : recordings) {
    const servo_tick::Coefficients c = servo_tick::CoefficientsOf(p, r.drive);
    double angle = r.measured_deg[0], velocity = 0.0, sum = 0.0;
    for (size_t t = 1; t < r.scored.size(); ++t) {
      servo_tick::Advance(c, kTickS, blend, r.request_deg[t > lag ? t - 1 - lag : 0], angle,
                          velocity);
      const double e = angle - r.measured_deg[t];
      sum += e * e;
    }
    total += sum;
  }
  return total;
}

struct Inputs {
  std::vector<ServoRecording> servo = Recordings();
  std::vector<JointRecording> joint;
  std::vector<std::vector<int>> run_ends;
  std::vector<SweptRecording> swept;

  Inputs() {
    for (const ServoRecording& r : servo) joint.push_back({r.request_deg, r.measured_deg, 1.0});
    for (const JointRecording& r : joint) {
      std::vector<int> end(r.request_deg.size());
      for (size_t t = end.size(); t-- > 0;) {
        end[t] = t + 1 < end.size() && r.request_deg[t] == r.request_deg[t + 1]
                     ? end[t + 1]
                     : static_cast<int>(t);
      }
      run_ends.push_back(std::move(end));
    }
    for (size_t k = 0; k < joint.size(); ++k) swept.push_back({&joint[k], run_ends[k]});
  }
};

const Inputs& TheInputs() {
  static const Inputs inputs;
  return inputs;
}

double LaneRollouts(LaneInstructions instructions) {
  static const ServoRollouts rollouts(TheInputs().servo, kTickS,
                                      benchmarks::kXl330Extended.lag_ticks);
  std::vector<double> sums;
  rollouts.SquaredErrors(benchmarks::kXl330Extended, sums, instructions);
  return sums[0];
}

double ScalarSweeps() {
  double total = 0.0;
  for (const JointRecording& r : TheInputs().joint) {
    const PredictionSensitivities s = PredictRecordingSensitivities(kPaper, r, kWarmup);
    for (size_t i = 0; i < s.angle_deg.size(); ++i) {
      const double e = r.measured_deg[static_cast<size_t>(kWarmup) + i] - s.angle_deg[i];
      total += e * e + s.d_log_v_max[i] * e;
    }
  }
  return total;
}

double LaneSweeps(LaneInstructions instructions) {
  static const PaperSensitivityLanes sweeps(TheInputs().swept, kWarmup);
  std::vector<PaperNormalEquations> equations;
  sweeps.Accumulate(kPaper, {}, false, equations, instructions);
  return equations[0].squared_error;
}

void BM_ExtendedScalar(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(ScalarRollouts(TheInputs().servo));
}
BENCHMARK(BM_ExtendedScalar)->Unit(benchmark::kMicrosecond);

void BM_ExtendedLanes(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(LaneRollouts(BestLaneInstructions()));
}
BENCHMARK(BM_ExtendedLanes)->Unit(benchmark::kMicrosecond);

void BM_PaperScalar(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(ScalarSweeps());
}
BENCHMARK(BM_PaperScalar)->Unit(benchmark::kMicrosecond);

void BM_PaperLanes(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(LaneSweeps(BestLaneInstructions()));
}
BENCHMARK(BM_PaperLanes)->Unit(benchmark::kMicrosecond);

// Microseconds per call of `run`, over enough calls for about 20 ms.
double Microseconds(const std::function<double()>& run) {
  int calls = 0;
  double sink = 0.0;
  const auto start = std::chrono::steady_clock::now();
  double elapsed = 0.0;
  while (elapsed < 2e4) {
    sink += run();
    ++calls;
    elapsed =
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  }
  benchmark::DoNotOptimize(sink);
  return elapsed / calls;
}

void Report(const char* what,
            const std::vector<std::pair<const char*, std::function<double()>>>& runs, int rounds) {
  std::vector<std::vector<double>> us(runs.size());
  for (int round = 0; round < rounds; ++round) {
    for (size_t k = 0; k < runs.size(); ++k) {
      const size_t i = (k + static_cast<size_t>(round)) % runs.size();
      us[i].push_back(Microseconds(runs[i].second));
    }
  }
  std::printf("%s, one evaluation, medians of %d interleaved rounds:\n", what, rounds);
  const double scalar = benchmarks::Median(us[0]);
  for (size_t i = 0; i < runs.size(); ++i) {
    const double x = benchmarks::Median(us[i]);
    std::printf("  %-22s %9.1f us  %5.2f x faster than one recording at a time\n", runs[i].first, x,
                scalar / x);
  }
}

void ReportSideBySide(int rounds) {
  const bool avx2 = BestLaneInstructions() == LaneInstructions::kAvx2;
  std::vector<std::pair<const char*, std::function<double()>>> extended = {
      {"one at a time", [] { return ScalarRollouts(TheInputs().servo); }},
      {"lanes, baseline", [] { return LaneRollouts(LaneInstructions::kBaseline); }}};
  std::vector<std::pair<const char*, std::function<double()>>> paper = {
      {"one at a time", ScalarSweeps},
      {"lanes, baseline", [] { return LaneSweeps(LaneInstructions::kBaseline); }}};
  if (avx2) {
    extended.emplace_back("lanes, avx2", [] { return LaneRollouts(LaneInstructions::kAvx2); });
    paper.emplace_back("lanes, avx2", [] { return LaneSweeps(LaneInstructions::kAvx2); });
  }
  Report("extended rollouts (12 recordings, 11,340 ticks)", extended, rounds);
  Report("paper sweeps (l 2, a 20; same recordings)", paper, rounds);
}

}  // namespace

int main(int argc, char** argv) {
  return leglab::benchmarks::RunThenReport(argc, argv, 5, ReportSideBySide);
}
