#pragma once

#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/controller/registry.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/paper.h"
#include "leglab/model/trajectories.h"
#include "leglab/sim/sim_config.h"

namespace leglab::experiments {

/// Bad input from the user (config, robot, URDF, CSV): the message names the item.
/// Programs print it on one line and exit with status 2, having written nothing.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The documented range of a numeric config key (the README's config reference lists the same):
/// a value must lie in [min, max], an end excluded when `min_open` / `max_open`. A list key's range
/// holds for each element. Keys are named as the user writes them ("servo.delay_ms", "steps").
struct NumericRange {
  std::string_view key;
  double min;
  double max;
  bool min_open;
  bool max_open;
  std::string_view unit;  ///< "ms", "deg", "" for a count
};

/// Every numeric key's range. LoadExperimentConfig checks each value read against it, before
/// anything runs; a numeric key read without a range here is a bug (std::logic_error).
std::span<const NumericRange> NumericKeyRanges();

/// The most ticks one tracking run (warmup_steps + steps, times track.t_step_ticks) may
/// simulate: its recorded trace is what track writes, so this also bounds memory and output.
inline constexpr long long kMaxTicksPerRun = 100'000'000;
/// The most ticks a whole program run may simulate (every run of every mode and candidate,
/// and the identification): 2e9 ticks of 8 ms are 185 days of walking.
inline constexpr long long kMaxTotalTicks = 2'000'000'000;
/// The most work one joint's identification may do: recorded ticks times the (l, a)
/// candidates searched, summed over the step tests.
inline constexpr long long kMaxIdentificationWork = 1'000'000;

/// `identify.*`: the step test of eq. 1 on each joint in turn.
struct IdentifyConfig {
  std::vector<double> theta_test_deg{40.0, 110.0};  ///< step heights, one recording each
  int t_step_ticks = kStepTicks;                    ///< period of the square wave
  int settle_cycles = 5;  ///< cycles run before recording, to reach equilibrium
  int record_cycles = 8;  ///< cycles recorded and fitted (fewer lets noise pick among near-ties)
  LegAngles hold_deg{0.0, 0.0, 0.0};  ///< where the joints not under test are held
  IdentificationOptions search;       ///< lag_range_ticks, accel_range_ticks
};

/// `desired.locus.*`: the half-elliptical foot locus (its shape, the model's HalfEllipseLocus
/// with the cited walk's defaults) and where it sits relative to the leg's shoulder. These
/// are the only defaults of the locus, equal to the shipped track.yaml.
struct LocusConfig {
  HalfEllipseLocus shape;    ///< length_mm, height_mm, ground_fraction (centre and period unused)
  double forward_mm = 49.0;  ///< centre of the flat bottom ahead of the shoulder
  double outward_mm = 28.0;  ///< ... outward of the shoulder (away from the body)
  double ground_below_shoulder_mm = 100.0;  ///< ... below the shoulder
};

/// `desired.*` and `track.*`: what to follow and for how long.
struct TrackConfig {
  std::string desired_csv;        ///< `desired.csv`: a cycle of joint angles; empty = the locus
  LocusConfig locus;              ///< `desired.locus`
  int t_step_ticks = kStepTicks;  ///< `track.t_step_ticks`: ticks per step (a CSV's rows)
  int warmup_steps = 5;           ///< `warmup_steps`: steps run before measuring
  int steps = 20;                 ///< `steps`: measured steps (the paper: 20)
  bool search_shift = true;       ///< `track.search_shift`: time_shift searches every k by foot L2
};

/// Which plant the experiments drive (`plant:`).
enum class PlantKind {
  kSim,    ///< `sim`: the simulated leg (sim::LegSim), the default
  kModel,  ///< `model`: the joint model itself as an ideal plant (JointModelPlant)
};

/// A whole experiment's configuration: the robot's robot.yaml merged under the experiment's
/// YAML file, then the --set overrides.
struct ExperimentConfig {
  std::string robot_yaml;  ///< the robot description file that was merged in
  PlantKind plant = PlantKind::kSim;
  /// `plant_model.*`: the ideal plant's joint model (plant: model), the same for every joint;
  /// default the paper's Table 1.
  JointModelParams plant_model = paper::kTable1;
  sim::SimConfig sim;  ///< urdf, sim.physics_dt_ms, servo.*, sensor.*, seed
  /// The modes track runs with their options, in order: controller.modes, or [controller.mode]
  /// when only that key is given, else every registered mode.
  std::vector<ControllerSpec> controllers;
  int pwl_segments = 8;  ///< `controller.pwl_segments`: segments of each joint's approximation
  std::optional<JointModelParams> model;  ///< model.* when given (all four keys)
  IdentifyConfig identify;
  TrackConfig track;
  /// Worker threads (`--threads`, not a config key); 0 means one per core. Results do not
  /// depend on it.
  int threads = 0;
  /// The ticks the run simulates at most (every step test, mode and searched candidate), as
  /// checked against kMaxTotalTicks; the progress display's 100 %.
  long long planned_ticks = 0;
};

/// Which top-level config sections a program uses. A key the loader knows but the program
/// does not use is bad input ("steps is not used by identify"), so that nobody believes a key
/// took effect that did not. Empty `sections` means every key.
struct ConfigScope {
  std::string program;                ///< for messages, e.g. "identify"
  std::vector<std::string> sections;  ///< top-level keys, e.g. "servo", "identify", "seed"
};

/// Loads `config_path` (with the file its `extends:` key names, relative to it, merged beneath
/// it, recursively), merges the robot it names (`robot:` a name under robots/ or a path to
/// a robot.yaml, default ers210a; a robot file may `extends:` another) beneath it, applies
/// `overrides` ("key.path=value", value in YAML syntax) last and in order, and converts the result
/// into structs with defaults. Throws InputError naming the file or key for a missing or malformed
/// file, a duplicate key, an unknown key, a key outside `scope`, a value of the wrong type or
/// out of its range (NumericKeyRanges), a run larger than kMaxTicksPerRun, kMaxTotalTicks or
/// kMaxIdentificationWork, or a missing URDF.
ExperimentConfig LoadExperimentConfig(const std::string& config_path,
                                      const std::vector<std::string>& overrides = {},
                                      const ConfigScope& scope = {});

}  // namespace leglab::experiments
