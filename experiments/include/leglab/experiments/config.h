#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/trajectories.h"
#include "leglab/sim/sim_config.h"

namespace leglab::experiments {

/// Bad input from the user (config, robot, URDF, CSV): the message names the item.
/// Programs print it on one line and exit with status 2, having written nothing.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `identify.*`: the step test of eq. 1 on each joint in turn.
struct IdentifyConfig {
  std::vector<double> theta_test_deg{40.0, 110.0};  ///< step heights, one recording each
  int t_step_ticks = kStepTicks;                    ///< period of the square wave
  int settle_cycles = 5;  ///< cycles run before recording, to reach equilibrium
  int record_cycles = 8;  ///< cycles recorded and fitted (fewer lets noise pick among near-ties)
  LegAngles hold_deg{0.0, 0.0, 0.0};  ///< where the joints not under test are held
  IdentificationOptions search;       ///< lag_range_ticks, accel_range_ticks
};

/// `desired.locus.*`: the half-elliptical foot locus, relative to the shoulder.
struct LocusConfig {
  double length_mm = 48.93;                 ///< flat bottom, fore-aft
  double height_mm = 42.0;                  ///< arc height
  double ground_fraction = 0.5;             ///< fraction of the step on the ground
  double forward_mm = 49.0;                 ///< centre of the flat bottom ahead of the shoulder
  double outward_mm = 28.0;                 ///< ... outward of the shoulder (+y for a left leg)
  double ground_below_shoulder_mm = 115.0;  ///< ... below the shoulder
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

/// A whole experiment's configuration: the robot's robot.yaml merged under the experiment's
/// YAML file, then the --set overrides.
struct ExperimentConfig {
  std::string robot_yaml;     ///< the robot description file that was merged in
  sim::SimConfig sim;         ///< urdf, sim.physics_dt_ms, servo.*, sensor.*, seed
  ControllerSpec controller;  ///< controller.mode, shift_ticks, cm, pwl_segments
  /// controller.modes: the modes track runs; all three by default, or [controller.mode] when
  /// only that key is given.
  std::vector<std::string> modes;
  std::optional<JointModelParams> model;  ///< model.* when given (all four keys)
  IdentifyConfig identify;
  TrackConfig track;
};

/// Loads `config_path` (with the file its `extends:` key names, relative to it, merged beneath
/// it, recursively), merges the robot it names (`robot:` a name under robots/ or a path to
/// a robot.yaml, default ers210a) beneath it, applies `overrides` ("key.path=value", value in
/// YAML syntax) last and in order, and converts the result into structs with defaults.
/// Throws InputError naming the file or key for a missing or malformed file, an unknown key,
/// a value of the wrong type or out of range, or a missing URDF.
ExperimentConfig LoadExperimentConfig(const std::string& config_path,
                                      const std::vector<std::string>& overrides = {});

}  // namespace leglab::experiments
