// Cost per tick as a servo log or a desired motion grows, so that a log of any length costs in
// proportion to its length:
//
//   BM_LogFit/N      identify's log fit (FitServoLogs: resampling, both models' fits, every
//                    score and both plans) of one synthetic XL330 log of N samples, without
//                    cross-validation, at logs.iterations=100 (N = 10^3 .. 10^6);
//   BM_OptimalPlan/N the batch optimal plan (PlanServoRequests, kOptimal) of N ticks of a
//                    desired motion (N = 10^2 .. 10^5);
//   BM_Floor/N       the floor (FloorTrajectory) of a desired cycle of N ticks for the paper's
//                    Table 1 joint, a motion five times too fast for it (N = 10^2 .. 10^5).
//
// Then the sizes side by side in interleaved rounds (the machine is shared and noisy): each
// one's time per tick and its ratio to the smallest size's. Usage: long_log_benchmark
// [--benchmark_* flags] [--rounds=N]
//
// The log is the extended model fitted to the shipped XL330 logs (xl330_model.h),
// at kp 400 with the shipped pendulum, driven by a sum of four sines with drifting amplitudes,
// with 0.05 deg of seeded Gaussian noise on the measurement.

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "leglab/model/floor.h"
#include "leglab/model/paper.h"
#include "leglab/servo/log_fit.h"
#include "leglab/servo/servo_model.h"
#include "leglab/servo/servo_plan.h"
#include "rounds_flag.h"
#include "xl330_model.h"

namespace {

using namespace leglab;

constexpr double kTickS = benchmarks::kXl330TickS;
constexpr const ServoModelParams& kModel = benchmarks::kXl330Extended;
const ServoDrive kDrive{.kp = 400.0, .mass_kg = 0.49, .length_m = 0.1};

// The desired motion or request at tick t (deg).
double Motion(size_t t) {
  const double s = static_cast<double>(t) * kTickS;
  const double drift = 0.6 + 0.4 * std::sin(2.0 * std::numbers::pi * 0.01 * s);
  double angle = 0.0;
  for (const auto& [hz, deg] : {std::pair{0.3, 40.0}, {0.9, 20.0}, {2.1, 10.0}, {4.7, 4.0}}) {
    angle += deg * drift * std::sin(2.0 * std::numbers::pi * hz * s);
  }
  return angle;
}

GivenServoLog SyntheticLog(size_t samples) {
  GivenServoLog given;
  ServoLog& log = given.log;
  log.file = "synthetic_" + std::to_string(samples) + ".csv";
  log.motor = "xl330";
  log.trajectory = "sines";
  log.kp = kDrive.kp;
  log.mass_kg = kDrive.mass_kg;
  log.length_m = kDrive.length_m;
  std::mt19937 random(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  ServoModelState state = ServoRestState(kModel, Motion(0));
  for (size_t t = 0; t < samples; ++t) {
    const double request = Motion(t);
    const double angle = StepServoModel(kModel, kDrive, kTickS, state, request);
    log.samples.push_back({.time_s = static_cast<double>(t) * kTickS,
                           .request_deg = request,
                           .measured_deg = angle + noise(random),
                           .torque_enabled = true});
  }
  return given;
}

LogFitConfig FitConfig() {
  LogFitConfig config;
  config.given = true;
  config.iterations = 100;
  return config;
}

void FitOnce(const GivenServoLog& log) {
  benchmark::DoNotOptimize(FitServoLogs(FitConfig(), 1, {log}).json.size());
}

std::vector<double> Desired(size_t ticks) {
  std::vector<double> desired(ticks);
  for (size_t t = 0; t < ticks; ++t) desired[t] = Motion(t);
  return desired;
}

void PlanOnce(const std::vector<double>& desired) {
  benchmark::DoNotOptimize(PlanServoRequests(kModel, kDrive, kTickS, desired,
                                             {-180.0, 180.0, kModel.v_max_deg_s},
                                             PlanMethod::kOptimal)
                               .request_deg.data());
}

// Five times Motion, at up to about 11 deg a tick against Table 1's 2.5: most rows of the
// floor's program are active somewhere in the cycle.
std::vector<double> FastCycle(size_t ticks) {
  std::vector<double> desired(ticks);
  for (size_t t = 0; t < ticks; ++t) desired[t] = 5.0 * Motion(t);
  return desired;
}

void FloorOnce(const std::vector<double>& desired) {
  benchmark::DoNotOptimize(FloorTrajectory(desired, paper::kTable1).data());
}

void BM_LogFit(benchmark::State& state) {
  const GivenServoLog log = SyntheticLog(static_cast<size_t>(state.range(0)));
  for (auto _ : state) FitOnce(log);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_LogFit)->Arg(1000)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(
    benchmark::kMillisecond);

void BM_OptimalPlan(benchmark::State& state) {
  const std::vector<double> desired = Desired(static_cast<size_t>(state.range(0)));
  for (auto _ : state) PlanOnce(desired);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_OptimalPlan)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10'000)
    ->Arg(100'000)
    ->Unit(benchmark::kMillisecond);

void BM_Floor(benchmark::State& state) {
  const std::vector<double> desired = FastCycle(static_cast<size_t>(state.range(0)));
  for (auto _ : state) FloorOnce(desired);
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_Floor)->Arg(100)->Arg(1000)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMillisecond);

using leglab::benchmarks::Median;

template <typename F>
double MicrosecondsPerTick(const F& run, size_t ticks) {
  const auto start = std::chrono::steady_clock::now();
  run();
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
             .count() /
         static_cast<double>(ticks);
}

// Each size's time per tick, interleaved round by round, and its ratio to the first size's.
template <typename Input, typename Make, typename Run>
void SideBySide(const char* what, const std::vector<size_t>& sizes, int rounds, Make make,
                Run run) {
  std::vector<Input> inputs;
  inputs.reserve(sizes.size());
  for (const size_t n : sizes) inputs.push_back(make(n));
  std::vector<std::vector<double>> us(sizes.size());
  for (std::vector<double>& times : us) times.reserve(static_cast<size_t>(rounds));
  for (int round = 0; round < rounds; ++round) {
    for (size_t k = 0; k < sizes.size(); ++k) {
      const size_t i = (k + static_cast<size_t>(round)) % sizes.size();
      us[i].push_back(MicrosecondsPerTick([&] { run(inputs[i]); }, sizes[i]));
    }
  }
  std::printf("%s, per tick, medians of %d interleaved rounds:\n", what, rounds);
  const double first = Median(us[0]);
  for (size_t i = 0; i < sizes.size(); ++i) {
    const double x = Median(us[i]);
    std::printf("  %9zu ticks  %10.3f us  %6.2f x the %zu-tick cost\n", sizes[i], x, x / first,
                sizes[0]);
  }
}

void ReportSideBySide(int rounds) {
  SideBySide<std::vector<double>>("optimal plan", {100, 1000, 10'000, 100'000}, rounds, Desired,
                                  PlanOnce);
  SideBySide<std::vector<double>>("floor", {100, 1000, 10'000, 100'000}, rounds, FastCycle,
                                  FloorOnce);
  SideBySide<GivenServoLog>("log fit (identify, no cross-validation)",
                            {1000, 10'000, 100'000, 1'000'000}, rounds, SyntheticLog, FitOnce);
}

}  // namespace

int main(int argc, char** argv) {
  return leglab::benchmarks::RunThenReport(argc, argv, 3, ReportSideBySide);
}
