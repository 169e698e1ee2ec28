// Cost of the experiments against the physics they run.
//
//   BM_Track       the shipped track.yaml (identification, floor, five modes, the time-shift
//                  search from one run), on one thread;
//   BM_SweepPoint  one sweep point as the sweep program runs it: identification plus the
//                  paper's three modes (direct, time_shift, model_based), on one thread.
//
// Then, side by side in interleaved rounds (the machine is shared and noisy):
//   - track's wall time over the wall time of the plant ticks it runs, ticked alone on fresh
//     plants (the overhead of identification fits, QPs, controllers and bookkeeping);
//   - the plant ticks of a default track with track.search_shift true and exhaustive;
//   - a sweep's points per second on 1 and on 2 threads;
//   - the shipped track on DART over the same on ODE (sim.engine).
// Usage: track_benchmark [--benchmark_* flags] [--rounds=N]

#include <benchmark/benchmark.h>

#include "rounds_flag.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "leglab/controller/registry.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/sweep.h"
#include "leglab/experiments/track.h"
#include "leglab/sim/sim_config.h"

namespace {

using namespace leglab;

using namespace leglab::experiments;

const std::string kConfigs = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
const std::vector<std::string> kPaperModes = {"controller.modes=[direct, time_shift, model_based]"};

ExperimentConfig Config(const std::vector<std::string>& overrides = {}) {
  ExperimentConfig config = LoadExperimentConfig(kConfigs + "track.yaml", overrides);
  config.threads = 1;
  return config;
}

double Seconds(const std::chrono::steady_clock::time_point& start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BM_Track(benchmark::State& state) {
  const ExperimentConfig config = Config();
  for (auto _ : state) benchmark::DoNotOptimize(RunTrackExperiment(config).plant_ticks);
}
BENCHMARK(BM_Track)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_SweepPoint(benchmark::State& state) {
  const ExperimentConfig config = Config(kPaperModes);
  for (auto _ : state) benchmark::DoNotOptimize(RunTrackExperiment(config).plant_ticks);
}
BENCHMARK(BM_SweepPoint)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_TrackDart(benchmark::State& state) {
  if (!leglab::sim::BuiltWithDart()) {
    state.SkipWithError("this build has no DART (LEGLAB_WITH_DART=OFF)");
    return;
  }
  const ExperimentConfig config = Config({"sim.engine=dart"});
  for (auto _ : state) benchmark::DoNotOptimize(RunTrackExperiment(config).plant_ticks);
}
BENCHMARK(BM_TrackDart)->Unit(benchmark::kMillisecond)->Iterations(3);

// Wall time of `ticks` plant ticks on `plants` fresh plants of `config` (as many as a track run
// builds), direct requests of the desired cycle: the physics alone.
double TimePhysics(const ExperimentConfig& config, const TrackResult& shape, long ticks,
                   int plants) {
  const auto start = std::chrono::steady_clock::now();
  const long per_plant = ticks / plants;
  for (int p = 0; p < plants; ++p) {
    const auto plant = MakePlant(config, shape.robot);
    plant->Reset(shape.desired.angles_deg[0]);
    const long n = p + 1 < plants ? per_plant : ticks - per_plant * (plants - 1);
    for (long t = 0; t < n; ++t) {
      benchmark::DoNotOptimize(
          plant->Tick(shape.desired.angles_deg[t % shape.period]).measured_deg);
    }
  }
  return Seconds(start);
}

using leglab::benchmarks::Median;

// A default track against the physics of its plant ticks alone, interleaved.
void ReportTrackAgainstPhysics(const ExperimentConfig& config, const TrackResult& shape,
                               int rounds) {
  // Plants a default track ticks: identification's (joints x step heights), the walk fit's
  // (when a mode uses the walk-fitted models), the search's lead-0 run and every mode's run.
  const bool walk_fit =
      std::any_of(config.controllers.begin(), config.controllers.end(),
                  [](const leglab::ControllerSpec& spec) { return leglab::UsesWalkModels(spec); });
  const int plants = leglab::kLegJoints * static_cast<int>(config.identify.theta_test_deg.size()) +
                     (walk_fit ? 1 : 0) + static_cast<int>(config.controllers.size()) + 1;
  const int steps_per_tick = leglab::sim::PhysicsStepsPerTick(config.sim.physics_dt_ms);
  std::vector<double> track_s, physics_s, ratios;
  for (int round = 0; round < rounds; ++round) {
    double track = 0.0, physics = 0.0;
    auto time_track = [&] {
      const auto start = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(RunTrackExperiment(config).plant_ticks);
      track = Seconds(start);
    };
    auto time_physics = [&] { physics = TimePhysics(config, shape, shape.plant_ticks, plants); };
    if (round % 2 == 0) {
      time_track(), time_physics();
    } else {
      time_physics(), time_track();
    }
    track_s.push_back(track), physics_s.push_back(physics), ratios.push_back(track / physics);
  }
  std::printf(
      "track (track.yaml, 1 thread): %.3f s; its %ld plant ticks (%ld physics steps) alone: "
      "%.3f s; track/physics wall time %.2f (median of %d interleaved rounds; target <= 1.3)\n",
      Median(track_s), shape.plant_ticks, shape.plant_ticks * steps_per_tick, Median(physics_s),
      Median(ratios), rounds);
}

// The paper's search: every shift on its own plant (run once: it is the slow one).
void ReportExhaustiveSearch(const TrackResult& shape) {
  ExperimentConfig exhaustive = Config({"track.search_shift=exhaustive"});
  const auto start = std::chrono::steady_clock::now();
  const long exhaustive_ticks = RunTrackExperiment(exhaustive).plant_ticks;
  std::printf(
      "plant ticks of a default track: %ld with track.search_shift exhaustive (%.3f s), %ld "
      "with true: %.1fx fewer\n",
      exhaustive_ticks, Seconds(start), shape.plant_ticks,
      static_cast<double>(exhaustive_ticks) / static_cast<double>(shape.plant_ticks));
}

// A sweep's throughput: 8 points of equal cost (identification plus the paper's three modes,
// seeds 1..8) on 1 and on 2 threads, interleaved.
void ReportSweepThreads(int rounds) {
  SweepConfig sweep;
  sweep.path = "benchmark";
  sweep.base_path = kConfigs + "track.yaml";
  sweep.overrides = kPaperModes;
  sweep.keys = {"seed"};
  for (long i = 0; i < 8; ++i) sweep.points.push_back({i, {std::to_string(i + 1)}});
  std::vector<double> one, two;
  for (int round = 0; round < std::max(1, rounds / 2); ++round) {
    for (int threads : round % 2 == 0 ? std::vector<int>{1, 2} : std::vector<int>{2, 1}) {
      const auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(RunSweep(sweep, Shard{}, threads).rows.size());
      (threads == 1 ? one : two).push_back(8.0 / Seconds(t0));
    }
  }
  std::printf(
      "sweep points per second (identification + 3 paper modes): %.2f on 1 thread, %.2f on 2: "
      "%.2fx (target >= 1.8)\n",
      Median(one), Median(two), Median(two) / Median(one));
}

// The same track on the two engines, interleaved.
void ReportEngines(const ExperimentConfig& config, int rounds) {
  if (!leglab::sim::BuiltWithDart()) {
    std::printf("track on DART: not measured, this build has no DART (LEGLAB_WITH_DART=OFF)\n");
    return;
  }
  const ExperimentConfig dart = Config({"sim.engine=dart"});
  const auto time = [](const ExperimentConfig& c) {
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(RunTrackExperiment(c).plant_ticks);
    return Seconds(t0);
  };
  std::vector<double> ode_s, dart_s, engine_ratios;
  for (int round = 0; round < rounds; ++round) {
    // Alternate which engine goes first.
    double on_ode = round % 2 == 0 ? time(config) : 0.0;
    const double on_dart = time(dart);
    if (round % 2 == 1) on_ode = time(config);
    ode_s.push_back(on_ode), dart_s.push_back(on_dart), engine_ratios.push_back(on_dart / on_ode);
  }
  std::printf(
      "track (track.yaml, 1 thread) on ODE %.3f s, on DART %.3f s: dart/ode %.2f (median "
      "of %d interleaved rounds)\n",
      Median(ode_s), Median(dart_s), Median(engine_ratios), rounds);
}

void ReportSideBySide(int rounds) {
  const ExperimentConfig config = Config();
  const TrackResult shape = RunTrackExperiment(config);
  ReportTrackAgainstPhysics(config, shape, rounds);
  ReportExhaustiveSearch(shape);
  ReportSweepThreads(rounds);
  ReportEngines(config, rounds);
}

}  // namespace

int main(int argc, char** argv) {
  return leglab::benchmarks::RunThenReport(argc, argv, 5, ReportSideBySide);
}
