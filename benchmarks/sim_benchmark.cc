// Cost of the simulated plant against the bare ODE step underneath it.
//
//   BM_OdeStep    one dWorldStep of the leg's world (LegWorld: same bodies, hinges and powered
//                 motors, no firmware, no sensing);
//   BM_SimTick    one LegSim::Tick (8 physics steps with firmware, then the state check and a
//                 sensor reading), following a walking-like request pattern.
//
// Then, because the machine is shared and noisy, the two are timed side by side in
// interleaved rounds and the final line gives the median ratio
//   sim/ode step cost ratio = (time per physics step inside LegSim) / (time per bare step),
// which must stay at or below kMaxRatio: firmware, sensing and checks may add at most a fifth
// to what ODE itself costs.
//
//   BM_StandTick  one LegSim::Tick of the leg on the single-leg test stand (carriage on a
//                 slider on the sled's cross slide, floor contact through an ODE space), the
//                 same requests, which put the foot on the floor for part of each cycle;
//
// and, side by side in the same way, the stand's cost per physics step over the air leg's
//   stand/air step cost ratio = (time per physics step of LegSim on the stand) / (in the air),
// which must stay at or below kMaxStandRatio (2);
//
//   BM_DartStep, BM_DartSimTick  the same on DART (sim.engine: dart), and side by side
//   dart/ode step cost ratio = (time per physics step of LegSim on DART) / (on ODE).
//
// Usage: sim_benchmark [--benchmark_* flags] [--rounds=N]

#include <benchmark/benchmark.h>

#include "rounds_flag.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "leglab/sim/leg_sim.h"

namespace {

using leglab::kLegJoints;
using leglab::LegAngles;
using leglab::sim::LegSim;
using leglab::sim::LegWorld;
using leglab::sim::PhysicsEngine;
using leglab::sim::SimConfig;

constexpr double kMaxRatio = 1.2;
constexpr double kMaxStandRatio = 2.0;
const std::string kUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";

SimConfig Config() {
  SimConfig config;
  config.urdf_path = kUrdf;
  return config;
}

// The leg on the test stand: StandConfig's defaults are robots/ers210a_stand/robot.yaml's values;
// the sled is track_stand.yaml's, the walk's stand.
SimConfig StandConfig() {
  SimConfig config = Config();
  config.stand.enabled = true;
  config.stand.sled_stiffness_n_per_m = 200.0;
  config.stand.sled_damping_n_s_per_m = 16.0;
  return config;
}

SimConfig DartConfig() {
  SimConfig config = Config();
  config.engine = PhysicsEngine::kDart;
  return config;
}

// The bare world in the state the sim keeps it in: every motor powered (one constraint row
// each, as in LegSim), holding still.
LegWorld BareWorld(PhysicsEngine engine = PhysicsEngine::kOde) {
  LegWorld world(kUrdf, {}, engine);
  world.SetConfigurationRad({0.3, 0.3, 1.0});
  for (int j = 0; j < kLegJoints; ++j) {
    world.SetMotor(j, 0.0, Config().servo.max_torque_nm);
  }
  return world;
}

// A walking-like request: each joint follows a cycle of 88 ticks (the paper's step).
LegAngles Request(long tick) {
  const double phase = 2.0 * std::numbers::pi * static_cast<double>(tick % 88) / 88.0;
  return {30.0 * std::sin(phase), 20.0 + 15.0 * std::cos(phase),
          60.0 + 40.0 * std::sin(2.0 * phase)};
}

// Bare physics steps of `engine`'s world.
void StepBareWorld(benchmark::State& state, PhysicsEngine engine) {
  LegWorld world = BareWorld(engine);
  const double dt_s = Config().physics_dt_ms / 1000.0;
  for (auto _ : state) {
    world.Step(dt_s);
  }
  state.SetItemsProcessed(state.iterations());  // physics steps
}

// LegSim ticks of `config` walking Request's pattern.
void TickSim(benchmark::State& state, const SimConfig& config) {
  LegSim sim(config);
  for (auto _ : state) {
    sim.SetRequestsDeg(Request(sim.tick()));
    sim.Tick();
    benchmark::DoNotOptimize(sim.MeasuredDeg());
  }
  // Physics steps, so items/s compares with the bare steps'.
  state.SetItemsProcessed(state.iterations() *
                          leglab::sim::PhysicsStepsPerTick(sim.config().physics_dt_ms));
}

void BM_OdeStep(benchmark::State& state) { StepBareWorld(state, PhysicsEngine::kOde); }
BENCHMARK(BM_OdeStep);

void BM_SimTick(benchmark::State& state) { TickSim(state, Config()); }
BENCHMARK(BM_SimTick);

void BM_StandTick(benchmark::State& state) { TickSim(state, StandConfig()); }
BENCHMARK(BM_StandTick);

// False, the benchmark skipped, in a build without DART.
bool HasDart(benchmark::State& state) {
  if (leglab::sim::BuiltWithDart()) return true;
  state.SkipWithError("this build has no DART (LEGLAB_WITH_DART=OFF)");
  return false;
}

void BM_DartStep(benchmark::State& state) {
  if (HasDart(state)) StepBareWorld(state, PhysicsEngine::kDart);
}
BENCHMARK(BM_DartStep);

void BM_DartSimTick(benchmark::State& state) {
  if (HasDart(state)) TickSim(state, DartConfig());
}
BENCHMARK(BM_DartSimTick);

// Seconds per physics step over `steps` bare ODE steps.
double TimeBare(LegWorld& world, int steps, double dt_s) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) {
    world.Step(dt_s);
  }
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  return elapsed.count() / steps;
}

// Seconds per physics step over `ticks` sim ticks.
double TimeSim(LegSim& sim, int ticks, int steps_per_tick) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < ticks; ++i) {
    sim.SetRequestsDeg(Request(sim.tick()));
    sim.Tick();
    benchmark::DoNotOptimize(sim.MeasuredDeg());
  }
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  return elapsed.count() / (static_cast<double>(ticks) * steps_per_tick);
}

using leglab::benchmarks::Median;

// Times `first` and `second` (each returns seconds) in `rounds` interleaved rounds, the
// order alternating: the per-round ratios second / first and both times, ns.
struct Interleaved {
  std::vector<double> ratios;
  std::vector<double> first_ns;
  std::vector<double> second_ns;
};
template <typename First, typename Second>
Interleaved TimeInterleaved(int rounds, First first, Second second) {
  Interleaved out;
  for (int round = 0; round < rounds; ++round) {
    double a = 0.0;
    double b = 0.0;
    if (round % 2 == 0) {
      a = first();
      b = second();
    } else {
      b = second();
      a = first();
    }
    out.ratios.push_back(b / a);
    out.first_ns.push_back(a * 1e9);
    out.second_ns.push_back(b * 1e9);
  }
  return out;
}

// Interleaved rounds, alternating which of the two goes first, each round's ratio taken from
// timings a few milliseconds apart so that load changes on the machine hit both.
void ReportSideBySideRatio(int rounds) {
  LegWorld world = BareWorld();
  LegSim sim(Config());
  const double dt_s = sim.config().physics_dt_ms / 1000.0;
  const int steps_per_tick = leglab::sim::PhysicsStepsPerTick(sim.config().physics_dt_ms);
  constexpr int kTicksPerRound = 250;  // 2 s of simulated time, a few ms of wall time
  const int steps_per_round = kTicksPerRound * steps_per_tick;
  TimeBare(world, steps_per_round, dt_s);  // warm up
  TimeSim(sim, kTicksPerRound, steps_per_tick);
  const Interleaved t = TimeInterleaved(
      rounds, [&] { return TimeBare(world, steps_per_round, dt_s); },
      [&] { return TimeSim(sim, kTicksPerRound, steps_per_tick); });
  const double ratio = Median(t.ratios);
  std::printf(
      "bare ODE step: %.0f ns (median), sim per physics step: %.0f ns (median), "
      "%d interleaved rounds of %d steps\n",
      Median(t.first_ns), Median(t.second_ns), rounds, steps_per_round);
  std::printf("sim/ode step cost ratio: %.3f (limit %.2f: %s)\n", ratio, kMaxRatio,
              ratio <= kMaxRatio ? "ok" : "EXCEEDED");
}

// The stand against the air leg, both as LegSims walking the same requests, in interleaved
// rounds as above.
void ReportStandRatio(int rounds) {
  LegSim air(Config());
  LegSim stand(StandConfig());
  const int steps_per_tick = leglab::sim::PhysicsStepsPerTick(air.config().physics_dt_ms);
  constexpr int kTicksPerRound = 250;
  TimeSim(air, kTicksPerRound, steps_per_tick);  // warm up
  TimeSim(stand, kTicksPerRound, steps_per_tick);
  const Interleaved t = TimeInterleaved(
      rounds, [&] { return TimeSim(air, kTicksPerRound, steps_per_tick); },
      [&] { return TimeSim(stand, kTicksPerRound, steps_per_tick); });
  const double ratio = Median(t.ratios);
  std::printf(
      "air sim per physics step: %.0f ns (median), stand sim per physics step: %.0f ns "
      "(median), %d interleaved rounds of %d ticks\n",
      Median(t.first_ns), Median(t.second_ns), rounds, kTicksPerRound);
  std::printf("stand/air step cost ratio: %.3f (limit %.2f: %s)\n", ratio, kMaxStandRatio,
              ratio <= kMaxStandRatio ? "ok" : "EXCEEDED");
}

// The leg in the air on DART against ODE, both as LegSims walking the same requests.
void ReportEngineRatio(int rounds) {
  if (!leglab::sim::BuiltWithDart()) {
    std::printf("dart/ode step cost ratio: not measured, this build has no DART\n");
    return;
  }
  LegSim ode(Config());
  LegSim dart(DartConfig());
  const int steps_per_tick = leglab::sim::PhysicsStepsPerTick(ode.config().physics_dt_ms);
  constexpr int kTicksPerRound = 250;
  TimeSim(ode, kTicksPerRound, steps_per_tick);  // warm up
  TimeSim(dart, kTicksPerRound, steps_per_tick);
  const Interleaved t = TimeInterleaved(
      rounds, [&] { return TimeSim(ode, kTicksPerRound, steps_per_tick); },
      [&] { return TimeSim(dart, kTicksPerRound, steps_per_tick); });
  std::printf(
      "ODE sim per physics step: %.0f ns (median), DART sim per physics step: %.0f ns "
      "(median), %d interleaved rounds of %d ticks\n",
      Median(t.first_ns), Median(t.second_ns), rounds, kTicksPerRound);
  std::printf("dart/ode step cost ratio: %.3f\n", Median(t.ratios));
}

}  // namespace

int main(int argc, char** argv) {
  return leglab::benchmarks::RunThenReport(argc, argv, 41, [](int rounds) {
    ReportSideBySideRatio(rounds);
    ReportStandRatio(rounds);
    ReportEngineRatio(rounds);
  });
}
