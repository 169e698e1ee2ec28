#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/app/input_error.h"
#include "leglab/controller/registry.h"
#include "leglab/core/config_keys.h"
#include "leglab/core/plant.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/paper.h"
#include "leglab/model/trajectories.h"
#include "leglab/servo/log_fit.h"
#include "leglab/sim/sim_config.h"

namespace leglab::experiments {

/// The largest desired.csv read, bytes (1 MiB: track.t_step_ticks' 1000 rows at most, of up to
/// about 1 KiB each); a larger one is refused before it is read.
inline constexpr std::uintmax_t kMaxDesiredCsvBytes = std::uintmax_t{1} << 20;

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
  /// true: each recording's cycles are averaged into one before the fit (StepTestsForFit);
  /// false: the fit scores every recorded tick, as the paper's procedure reads.
  bool average_cycles = true;
};

/// `desired.locus.*`: the half-elliptical foot locus (its shape, the model's HalfEllipseLocus
/// with the cited walk's defaults) and where it sits relative to the leg's shoulder. These
/// are the only defaults of the locus, equal to the shipped track.yaml.
struct LocusConfig {
  /// length_mm, height_mm, ground_fraction, skew (outward mm per mm forward of the locus's
  /// centre), swing_end_speed_fraction (the foot's backward speed at lift-off and touch-down
  /// over the stance's; 0, the half-ellipse); centre and period unused
  HalfEllipseLocus shape;
  double forward_mm = 49.0;                 ///< centre of the flat bottom ahead of the shoulder
  double outward_mm = 28.0;                 ///< ... outward of the shoulder (away from the body)
  double ground_below_shoulder_mm = 100.0;  ///< ... below the shoulder
  /// `body_pitch_deg`: the body's pitch, positive nose down (the cited walk's front and rear
  /// body heights, 77 and 112 mm at shoulders 119 mm apart: asin(35 / 119) = 17.1 deg). The
  /// three offsets above are then
  /// measured in the level ground frame at the shoulder (forward along the ground, below
  /// perpendicular to it) and the placed locus is turned into the body frame about the
  /// shoulder (PitchFootPath). 0 (the default): the body is level.
  double body_pitch_deg = 0.0;
};

/// `track.search_shift`: how a searched mode (time_shift) finds its best candidate.
enum class ShiftSearch {
  kNone,  ///< `false`: no search; the mode runs with its configured options
  /// `true` (the default): a mode whose candidates differ only by how far ahead they request
  /// (RequestLeadTicks) is scored from one run of its lead-0 candidate, one step longer: the
  /// plant is time-invariant, so in steady state candidate k's response is that run's response
  /// k ticks later. Other searched modes, and every mode when plant_changes make the plant
  /// change mid-run, run every candidate.
  kShiftedRun,
  kExhaustive,  ///< `exhaustive`: every candidate run on its own plant (the paper's procedure)
};

/// ShiftSearch's values as the config names them, in the enum's order.
inline constexpr std::array<std::string_view, 3> kShiftSearchNames = {"false", "true",
                                                                      "exhaustive"};

/// `desired.*` and `track.*`: what to follow and for how long.
struct TrackConfig {
  std::string desired_csv;        ///< `desired.csv`: a cycle of joint angles; empty = the locus
  LocusConfig locus;              ///< `desired.locus`
  int t_step_ticks = kStepTicks;  ///< `track.t_step_ticks`: ticks per step (a CSV's rows)
  int warmup_steps = 5;           ///< `warmup_steps`: steps run before measuring
  int steps = 20;                 ///< `steps`: measured steps (the paper: 20)
  ShiftSearch search_shift = ShiftSearch::kShiftedRun;  ///< `track.search_shift`
};

/// Which plant the experiments drive (`plant:`).
enum class PlantKind {
  kSim,    ///< `sim`: the simulated leg (sim::LegSim), the default
  kModel,  ///< `model`: the joint model itself as an ideal plant (JointModelPlant)
};

/// PlantKind's values as the config names them, in the enum's order.
inline constexpr std::array<std::string_view, 2> kPlantNames = {"sim", "model"};

/// `plant_changes[i]`: settings of the running plant changed at the start of measured step
/// `at_step` (0 = the first step after the warm-up) through Plant::ChangeSettings, without
/// restarting it. Keys as in robot.yaml (servo.*, sensor.*; plant_model.* for plant: model).
struct PlantChange {
  int at_step = 0;
  std::vector<PlantSetting> set;  ///< in the order written
};

/// The declared ranges of track.steps and of a change's at_step (in a run of N steps, at most
/// N - 1).
inline constexpr KeyDoc kStepsDoc{
    .min = 1, .max = 1'000'000, .description = "measured steps (the paper: 20)"};
inline constexpr KeyDoc kAtStepDoc{.min = 0, .max = kStepsDoc.max - 1, .unit = "steps"};

/// A whole experiment's configuration: the robot's robot.yaml merged under the experiment's
/// YAML file, then the --set overrides.
struct ExperimentConfig {
  std::string robot_yaml;  ///< the robot description file that was merged in
  /// The keys as the loader read them, YAML text: the config file over the files it extends and
  /// the robot file, with the `--set` overrides applied (what a run writes as
  /// <program>_config.yaml).
  std::string merged_yaml;
  PlantKind plant = PlantKind::kSim;
  /// `plant_model.*`: the ideal plant's joint model (plant: model), the same for every joint;
  /// default the paper's Table 1.
  JointModelParams plant_model = paper::kTable1;
  sim::SimConfig sim;  ///< urdf, sim.physics_dt_ms, servo.*, sensor.*, stand.*, seed
  /// `plant_changes`: changes of the running plant during tracking runs, by increasing
  /// at_step (each validated against the plant as the earlier ones left it).
  std::vector<PlantChange> plant_changes;
  /// The modes track runs with their options, in order: controller.modes, or [controller.mode]
  /// when only that key is given, else every registered mode.
  std::vector<ControllerSpec> controllers;
  int pwl_segments = 8;  ///< `controller.pwl_segments`: segments of each joint's approximation
  std::optional<JointModelParams> model;  ///< model.* when given (all four keys)
  IdentifyConfig identify;
  LogFitConfig logs;  ///< `logs.*`: when given, identify fits these logs instead of step tests
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

/// What identify reads: the plant's keys and its own (a track key given to it is an error).
inline const ConfigScope kIdentifyScope{"identify",
                                        {"extends", "robot", "urdf", "plant", "plant_model", "sim",
                                         "servo", "sensor", "seed", "identify", "stand", "logs"}};

/// Whether top-level key `section` ("servo", "steps") is in `scope`.
bool InScope(const ConfigScope& scope, const std::string& section);

/// Every key an experiment config may set (the robot file's, the experiment's, each registered
/// mode's), each declared once beside the code that owns it, in the reference's order; only
/// the keys of `scope`'s sections when it names any. What `--list-keys` prints and
/// docs/configuration.md holds.
std::vector<KeyRow> ExperimentKeys(const ConfigScope& scope);

/// The experiment key `key` as the user writes it ("servo.delay_ms"), or null.
const KeyRow* FindKey(std::string_view key);

/// The sweep file's own keys (`sweep --list-keys`); its other keys are experiment keys.
std::vector<KeyRow> SweepKeys();

/// `rows` as a Markdown table with the columns key | type | default | range | unit |
/// description.
std::string KeyTableMarkdown(const std::vector<KeyRow>& rows);

/// Loads `config_path` (with the file its `extends:` key names, relative to it, merged beneath
/// it, recursively), merges the robot it names (`robot:` a name under robots/ or a path to
/// a robot.yaml, default ers210a; a robot file may `extends:` another) beneath it, applies
/// `overrides` ("key.path=value", value in YAML syntax) last and in order, and converts the result
/// into structs with defaults. Throws InputError naming the file or key for a missing or malformed
/// file, a duplicate key, an unknown key, a key outside `scope`, a value of the wrong type or
/// out of its declared range (ExperimentKeys), a run larger than kMaxTicksPerRun, kMaxTotalTicks or
/// kMaxIdentificationWork, or a missing URDF.
ExperimentConfig LoadExperimentConfig(const std::string& config_path,
                                      const std::vector<std::string>& overrides = {},
                                      const ConfigScope& scope = {});

/// `config` with the first `count` of its plant_changes applied to its plant settings (sim or
/// plant_model) and none left to apply: the plant as it is after those changes, e.g. to
/// identify it. `count` at most plant_changes.size().
ExperimentConfig ConfigAfterChanges(const ExperimentConfig& config, size_t count);

/// One point of a sweep.
struct SweepPoint {
  long index = 0;                   ///< 0-based, in the sweep's order (a shard's selector)
  std::vector<std::string> values;  ///< each swept key's value as YAML text, in key order
};

/// A sweep file (`sweep --config`): a base experiment and the points at which to run it.
struct SweepConfig {
  std::string path;       ///< the sweep file
  std::string base_path;  ///< `base:`, relative to the sweep file
  /// The sweep file's other keys, merged over the base as `extends:` would: one key=value
  /// override per leaf (maps merge key by key, anything else replaces).
  std::vector<std::string> overrides;
  std::vector<std::string> keys;  ///< the swept keys (dotted config paths), in the file's order
  std::vector<SweepPoint> points;

  /// The overrides that make point `p`'s experiment: `overrides`, then key=value of each
  /// swept key.
  std::vector<std::string> PointOverrides(const SweepPoint& p) const;
};

/// Most points a sweep may have (a grid's product, a sample's count): 10^6.
inline constexpr long kMaxSweepPoints = 1'000'000;

/// Loads a sweep file: `base:` (required) and either `grid: {<key>: [values...], ...}` (the
/// cartesian product, the first key varying slowest) or `sample: {count: K, seed: S, keys:
/// {<key>: {min: a, max: b}, ...}}` (K points, each key uniform in [a, b]; integers when a
/// and b are both written as integers; the same seed gives the same points on any machine).
/// Every other key is an experiment config key merged over the base. Throws InputError naming
/// the file and key for a missing or malformed file, a missing base, neither or both of grid
/// and sample, an empty grid or value list, a bad count, seed or range, or more than
/// kMaxSweepPoints points. Whether the swept keys exist is checked by loading the base
/// (LoadExperimentConfig), not here.
SweepConfig LoadSweepConfig(const std::string& path);

}  // namespace leglab::experiments
