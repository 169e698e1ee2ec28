// Cost of driving a plant tick by tick from C++: the counterpart of the Python package's
// Plant.run and Plant.tick (benchmarks/python_benchmark.py times both side by side).
//
//   BM_PlantRun1760    the shipped track.yaml's plant (plant: sim): Reset to the walk's first
//                      pose, then 1760 ticks (20 steps of the 88-tick walk) of the desired
//                      angles, copying each reading into preallocated vectors, as Plant.run's
//                      loop does;
//   BM_ModelPlantTick  one tick of the `plant: model` plant (the joint model as an ideal plant).
// Usage: plant_loop_benchmark [--benchmark_* flags]

#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "leglab/core/plant.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/robot.h"

namespace {

using namespace leglab;

using namespace leglab::experiments;
using leglab::LegAngles;

const std::string kTrackConfig = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/track.yaml";

// Ticks of one run: 20 steps of 88 ticks, the paper's measured steps.
constexpr int kRunTicks = 1760;

// The desired angles of the walk, repeated to `ticks` rows.
std::vector<LegAngles> RequestTable(const ExperimentConfig& config, const Robot& robot, int ticks) {
  const DesiredMotion motion = LoadDesiredMotion(config.track, robot.geometry);
  std::vector<LegAngles> requests(ticks);
  for (int t = 0; t < ticks; ++t) requests[t] = motion.angles_deg[t % motion.angles_deg.size()];
  return requests;
}

void BM_PlantRun1760(benchmark::State& state) {
  const ExperimentConfig config = LoadExperimentConfig(kTrackConfig);
  const Robot robot = LoadRobot(config.sim.urdf_path);
  const std::unique_ptr<leglab::Plant> plant = MakePlant(config, robot);
  const std::vector<LegAngles> requests = RequestTable(config, robot, kRunTicks);
  // Plant.run's outputs: the three angle rows, the contact force and the four instruments.
  std::vector<LegAngles> measured(kRunTicks), truth(kRunTicks), applied(kRunTicks),
      force(kRunTicks);
  std::vector<double> carriage(kRunTicks), slip(kRunTicks), sled_x(kRunTicks), sled_y(kRunTicks);
  for (auto _ : state) {
    plant->Reset(requests[0]);
    for (int t = 0; t < kRunTicks; ++t) {
      const leglab::PlantReading& r = plant->Tick(requests[t]);
      measured[t] = r.measured_deg;
      truth[t] = r.true_deg;
      applied[t] = r.applied_deg;
      force[t] = r.telemetry.contact_force_n;
      carriage[t] = r.telemetry.carriage_z_mm;
      slip[t] = r.telemetry.slip_mm;
      sled_x[t] = r.telemetry.sled_x_mm;
      sled_y[t] = r.telemetry.sled_y_mm;
    }
    benchmark::DoNotOptimize(measured.data());
    benchmark::DoNotOptimize(truth.data());
    benchmark::DoNotOptimize(applied.data());
    benchmark::DoNotOptimize(force.data());
    benchmark::DoNotOptimize(carriage.data());
    benchmark::DoNotOptimize(slip.data());
    benchmark::DoNotOptimize(sled_x.data());
    benchmark::DoNotOptimize(sled_y.data());
    benchmark::ClobberMemory();
  }
  state.counters["ticks"] = kRunTicks;
}
BENCHMARK(BM_PlantRun1760)->Unit(benchmark::kMillisecond);

void BM_ModelPlantTick(benchmark::State& state) {
  const ExperimentConfig config = LoadExperimentConfig(kTrackConfig, {"plant=model"});
  const Robot robot = LoadRobot(config.sim.urdf_path);
  const std::unique_ptr<leglab::Plant> plant = MakePlant(config, robot);
  const std::vector<LegAngles> requests = RequestTable(config, robot, kRunTicks);
  plant->Reset(requests[0]);
  size_t t = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(plant->Tick(requests[t]).measured_deg);
    t = t + 1 == requests.size() ? 0 : t + 1;
  }
}
BENCHMARK(BM_ModelPlantTick)->Unit(benchmark::kNanosecond);

}  // namespace

BENCHMARK_MAIN();
