// The experiment's config keys, each declared once (VisitExperimentKeys), and the loader that
// reads them: robot.yaml beneath the experiment file, the overrides last, then the checks that
// involve several keys.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "leglab/app/data_dir.h"
#include "leglab/app/yaml_config.h"
#include "leglab/experiments/config.h"
#include "leglab/model/joint_model_plant.h"
#include "leglab/servo/log_fit_config.h"
#include "run_budget.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

// The robot an experiment drives unless it names another.
constexpr std::string_view kDefaultRobot = "ers210a";

// The step test's keys and their checks.
void VisitKeys(KeyVisitor& v, IdentifyConfig& c) {
  v.Key("theta_test_deg", c.theta_test_deg,
        {.min = -180,
         .max = 180,
         .unit = "deg",
         .description = "step heights, one recording each: 1 to 8, non-zero and distinct (each "
                        "names its step_<joint>_<theta>.csv)"});
  v.Key("t_step_ticks", c.t_step_ticks,
        WithDescription(kStepTicksDoc, "period of the step test's square wave (32 ms to 8 s)"));
  v.Key(
      "settle_cycles", c.settle_cycles,
      {.min = 1, .max = 1000, .description = "cycles run before recording, to reach equilibrium"});
  v.Key("record_cycles", c.record_cycles,
        {.min = 1,
         .max = 1000,
         .description = "cycles recorded and fitted; more ticks than lag + accel"});
  v.Key(
      "average_cycles", c.average_cycles,
      {.description = "true: the fit takes each recording's cycles averaged into one (fit_rms_deg "
                      "is still over every tick); false: it scores every recorded tick, as the "
                      "paper's procedure reads (slower)"});
  std::vector<double> hold(c.hold_deg.begin(), c.hold_deg.end());
  v.Key("hold_deg", hold,
        {.min = -180,
         .max = 180,
         .unit = "deg",
         .description = "where the joints not under test are held: three angles, rotator, "
                        "abductor, knee"});
  if (hold.size() != kLegJoints) v.Fail("hold_deg", "a list of 3 angles (rotator, abductor, knee)");
  std::copy(hold.begin(), hold.end(), c.hold_deg.begin());
  std::vector<int> lag{c.search.lag_min_ticks, c.search.lag_max_ticks};
  std::vector<int> accel{c.search.accel_min_ticks, c.search.accel_max_ticks};
  // Each end within the model's own range of l and a (joint_model.h).
  v.Key("lag_range_ticks", lag,
        WithDescription(kJointModelKeys.lag_ticks, "[min, max] of the lag l the fit searches"));
  v.Key("accel_range_ticks", accel,
        WithDescription(kJointModelKeys.accel_ticks,
                        "[min, max] of the acceleration time a the fit searches"));
  if (c.theta_test_deg.empty() || c.theta_test_deg.size() > 8) {
    v.Fail("theta_test_deg", "a list of 1 to 8 step heights");
  }
  for (size_t i = 0; i < c.theta_test_deg.size(); ++i) {
    const double theta = c.theta_test_deg[i];
    if (theta == 0.0) v.Fail("theta_test_deg", "a list of non-zero step heights");
    if (std::find(c.theta_test_deg.begin(), c.theta_test_deg.begin() + static_cast<long>(i),
                  theta) != c.theta_test_deg.begin() + static_cast<long>(i)) {
      v.Fail("theta_test_deg", "a list of distinct step heights, got " +
                                   FormatNumber(theta, NumberStyle::kReadable) + " twice");
    }
  }
  if (lag.size() != 2 || lag[1] < lag[0]) {
    v.Fail("lag_range_ticks",
           "[min, max] with min <= max, each in " + RangeText(kJointModelKeys.lag_ticks));
  }
  if (accel.size() != 2 || accel[1] < accel[0]) {
    v.Fail("accel_range_ticks",
           "[min, max] with min <= max, each in " + RangeText(kJointModelKeys.accel_ticks));
  }
  c.search = {lag[0], lag[1], accel[0], accel[1]};
  if (c.record_cycles * c.t_step_ticks <= lag[1] + accel[1]) {
    v.Fail("record_cycles",
           "long enough to cover the identification's warm-up of lag + accel ticks");
  }
}

// The half-elliptical foot locus: its shape and where it sits.
void VisitKeys(KeyVisitor& v, LocusConfig& c) {
  HalfEllipseLocus& shape = c.shape;
  VisitKeys(v, shape);
  v.Key("forward_mm", c.forward_mm,
        {.min = -1000,
         .max = 1000,
         .unit = "mm",
         .description = "centre of the flat bottom ahead of the shoulder"});
  v.Key("outward_mm", c.outward_mm,
        {.min = -1000,
         .max = 1000,
         .unit = "mm",
         .description = "centre of the flat bottom outward of the shoulder"});
  v.Key("ground_below_shoulder_mm", c.ground_below_shoulder_mm,
        {.min = -1000,
         .max = 1000,
         .unit = "mm",
         .description = "the ground below the shoulder (on the stand, where the floor lies)"});
  v.Key("body_pitch_deg", c.body_pitch_deg, kBodyPitchDoc);
  // The slow lift-off is checked with the walk's step (and so its flight) in CheckWalk.
  HalfEllipseLocus without_ramp = shape;
  without_ramp.liftoff_ramp_mm = 0.0;
  if (const std::string problem = HalfEllipseLocusProblem(without_ramp); !problem.empty()) {
    FailConfig(v.FullName(problem));
  }
}

void VisitKeys(KeyVisitor& v, TrackConfig& t) {
  v.Section("desired", [&] {
    v.Key("csv", t.desired_csv,
          {.description = "a cycle of joint angles to follow instead of the locus "
                          "(tick,rotator_deg,abductor_deg,knee_deg; relative to the config file "
                          "when not found from the working directory; at most 1 MiB)"});
    v.Section("locus", [&] { VisitKeys(v, t.locus); });
  });
  v.Section("track", [&] {
    v.Key("t_step_ticks", t.t_step_ticks,
          WithDescription(kStepTicksDoc, "ticks per step (a desired.csv's rows)"));
    v.Key("search_shift", t.search_shift, kShiftSearchNames,
          {.description = "how time_shift finds its k: true, every k scored from one run one step "
                          "longer; exhaustive, every k run on its own (the paper's procedure); "
                          "false, controller.shift_ticks"});
  });
  v.Key("warmup_steps", t.warmup_steps,
        {.min = 0, .max = 1'000'000, .description = "steps run before measuring"});
  v.Key("steps", t.steps, kStepsDoc);
}

// What the loader keeps besides the config while it reads: every mode's options (the modes to
// run are chosen from them), and the plant changes' YAML.
struct ReadState {
  std::vector<ControllerSpec> all_modes;
  std::string mode;          // controller.mode
  YAML::Node modes;          // controller.modes
  YAML::Node plant_changes;  // plant_changes
  bool model_given = false;  // a `model` section
  JointModelParams model = paper::kTable1;
};

// Every key of an experiment, in the order the reference lists them. `reader` is the
// YamlKeyReader when loading (null when listing), for the structured keys' YAML.
void VisitExperimentKeys(KeyVisitor& v, ExperimentConfig& c, ReadState& state,
                         YamlKeyReader* reader) {
  v.Structured("extends", "file name", "(none)",
               {.description = "a config (or robot file) merged beneath this one, relative to it"});
  std::string robot(kDefaultRobot);
  v.Key("robot", robot,
        {.description = "a robot under robots/ (ers210a, the left front leg; ers210a_hind; "
                        "ers210a_stand, on the test stand) or a path to a robot.yaml"});
  VisitKeys(v, c.sim);
  v.Key("plant", c.plant, kPlantNames,
        {.description = "sim, the simulated leg; or model, the joint model as an ideal, "
                        "noise-free plant"});
  v.Section("plant_model", [&] { VisitKeys(v, c.plant_model); });
  v.Structured("plant_changes", "list of {at_step, set}", "[]",
               {.description = "changes of the running plant: {at_step: N, set: {key: value}} "
                               "applied at the start of measured step N (servo.*, sensor.*; "
                               "plant_model.* for plant: model), each checked as the key itself"});
  if (reader != nullptr) state.plant_changes = reader->Raw("plant_changes");
  v.Section("controller", [&] {
    v.Key("mode", state.mode,
          {.description = "the one mode to run, one of controller.modes' (controller.modes, when "
                          "given, wins)"});
    v.Structured("modes", "list of modes", "[" + ControllerModeNames() + "]",
                 {.description = "the modes track runs, in order, each at most once"});
    if (reader != nullptr) state.modes = reader->Raw("modes");
    v.Key("pwl_segments", c.pwl_segments, kPwlSegmentsDoc);
  });
  // Each mode's keys, in its own section (`controller` unless it says otherwise).
  for (const ControllerModeInfo& m : ControllerModes()) {
    v.Section(m.config_section, [&] { state.all_modes.push_back(ReadControllerSpec(m.name, v)); });
  }
  state.model_given = v.Given("model");
  v.Section("model", [&] {
    // All four keys or none: without them the model is identified on the plant.
    if (state.model_given) {
      for (const KeyRow& row :
           ListKeys(state.model, [](KeyVisitor&l, JointModelParams&p) { VisitKeys(l, p); })) {
        if (!v.Given(row.key)) v.Fail(row.key, "given (model.* needs all four keys, or none)");
      }
    }
    VisitKeys(v, state.model);
  });
  v.Section("identify", [&] { VisitKeys(v, c.identify); });
  c.logs.given = v.Given("logs");
  v.Section("logs", [&] {
    VisitKeys(v, c.logs);
    if (reader != nullptr) ReadLogFitStructured(*reader, c.logs);
  });
  VisitKeys(v, c.track);
}

// The robot file `robot` names: a path (relative to the config file), or robots/<name>/robot.yaml
// in the working directory, else leglab's own (DataDir(): the installed share/leglab, or the
// build tree's link to the source folder).
fs::path ResolveRobot(const std::string& robot, const fs::path& config_dir) {
  if (robot.find('/') != std::string::npos || fs::path(robot).extension() == ".yaml") {
    return fs::path(robot).is_absolute() ? fs::path(robot) : config_dir / robot;
  }
  fs::path here = fs::path("robots") / robot / "robot.yaml";
  if (PathExists(here)) return here;
  return DataDir() / "robots" / robot / "robot.yaml";
}

// The experiment file (with its bases and the overrides) merged over the robot file it names;
// sets config.robot_yaml.
YAML::Node MergedConfig(const std::string& config_path, const std::vector<std::string>& overrides,
                        ExperimentConfig& config) {
  YAML::Node experiment = LoadWithBase(config_path, "config file");
  for (const std::string& o : overrides) ApplyOverride(experiment, o);
  // A file names its base; an override cannot (the files are merged by now).
  if (experiment["extends"]) throw UnknownKeyError("config: unknown key 'extends' in --set");
  std::string robot(kDefaultRobot);
  if (experiment["robot"]) {
    try {
      robot = experiment["robot"].as<std::string>();
    } catch (const YAML::Exception&) {
      FailConfig("robot: expected a robot name or a path to a robot.yaml");
    }
    // The error below names it, on one line.
    if (robot.find_first_of("\n\r") != std::string::npos) {
      FailConfig(
          "robot: expected a robot name or a path to a robot.yaml, got text with a line "
          "break");
    }
  }
  const fs::path robot_yaml = ResolveRobot(robot, fs::path(config_path).parent_path());
  if (!PathExists(robot_yaml)) FailConfig("robot '" + robot + "': no " + robot_yaml.string());
  config.robot_yaml = robot_yaml.string();
  YAML::Node merged = LoadWithBase(robot_yaml, "robot file");
  MergeInto(merged, experiment);
  return merged;
}

// The first key path under `node` (a.b.c), as the user would have written it.
std::string FirstKeyPath(const std::string& prefix, const YAML::Node& node) {
  if (!node.IsMap() || node.size() == 0) return prefix;
  const auto first = node.begin();
  return FirstKeyPath(prefix + "." + KeyText(first->first), first->second);
}

const std::vector<KeyRow>& AllExperimentKeys();

// A key some other program uses, given to this one: say so rather than ignore it.
void CheckScope(const YAML::Node& merged, const ConfigScope& scope) {
  const std::vector<KeyRow>& all = AllExperimentKeys();
  for (const auto& item : merged) {
    const std::string key = KeyText(item.first);
    const bool known = std::any_of(all.begin(), all.end(), [&](const KeyRow& row) {
      return row.key == key || row.key.starts_with(key + ".");
    });
    if (known && !InScope(scope, key)) {
      FailConfig(FirstKeyPath(key, item.second) + " is not used by " + scope.program);
    }
  }
}

// The URDF resolved against the robot file, and the plant's own checks.
void ResolvePlant(ExperimentConfig& config) {
  std::string& urdf = config.sim.urdf_path;
  if (urdf.empty()) FailConfig("urdf: no URDF given (robot file " + config.robot_yaml + ")");
  const fs::path urdf_path = fs::path(urdf).is_absolute()
                                 ? fs::path(urdf)
                                 : fs::path(config.robot_yaml).parent_path() / urdf;
  if (!IsRegularFile(urdf_path)) FailConfig("urdf: '" + urdf_path.string() + "' does not exist");
  CheckFileSize(urdf_path.string(), kMaxConfigFileBytes, "config: urdf");
  urdf = urdf_path.string();
  try {
    sim::ValidateSimConfig(config.sim);
    sim::CheckTurnPerPhysicsStep(config.sim);
  } catch (const std::invalid_argument& e) {
    FailConfig(e.what());
  }
}

// plant_changes[i].at_step: a measured step after the previous change's.
int ReadChangeStep(const YAML::Node& item, const std::string& name,
                   const std::vector<PlantChange>& earlier) {
  const YAML::Node at = item.IsMap() ? item["at_step"] : YAML::Node();
  long long step = -1;
  if (at.IsDefined() && !at.IsNull()) {
    try {
      step = at.as<long long>();
    } catch (const YAML::Exception&) {
      FailConfig(name + ".at_step: expected an integer");
    }
    if (const std::string problem = KeyValueProblem(static_cast<double>(step), kAtStepDoc);
        !problem.empty()) {
      FailConfig(name + ".at_step must be a measured step " + problem + ", got " +
                 std::to_string(step));
    }
  }
  if (step < 0) FailConfig(name + ".at_step must be given, a measured step");
  if (!earlier.empty() && step <= earlier.back().at_step) {
    FailConfig(name + ".at_step must be after the previous change's (" +
               std::to_string(earlier.back().at_step) + ")");
  }
  return static_cast<int>(step);
}

// plant_changes[i].set, dotted (servo.delay_ms: 56) or nested (servo: {delay_ms: 56}); each
// value checked against the key it sets.
std::vector<PlantSetting> ReadChangeSettings(const YAML::Node& set, const std::string& name) {
  if (!set.IsMap() || set.size() == 0)
    FailConfig(name + ".set must be a non-empty map of key: value");
  std::vector<std::pair<std::string, YAML::Node>> pending;
  for (const auto& entry : set) pending.emplace_back(entry.first.as<std::string>(), entry.second);
  std::vector<PlantSetting> settings;
  for (size_t k = 0; k < pending.size(); ++k) {
    const auto [key, value] = pending[k];
    if (value.IsMap()) {
      for (const auto& entry : value) {
        pending.emplace_back(key + "." + entry.first.as<std::string>(), entry.second);
      }
      continue;
    }
    PlantSetting setting{key, 0.0};
    try {
      setting.value = value.as<double>();
    } catch (const YAML::Exception&) {
      FailConfig(name + ".set." + key + ": expected a number");
    }
    if (const KeyRow* row = FindKey(key)) {
      if (const std::string problem = KeyValueProblem(setting.value, row->doc); !problem.empty()) {
        FailConfig(name + ".set." + key + " must be " + problem + ", got " +
                   FormatNumber(setting.value, NumberStyle::kReadable));
      }
    }
    // servo: {delay_ms: 56} and servo.delay_ms: 48 in one change are one setting given twice.
    for (const PlantSetting& earlier : settings) {
      if (earlier.key == setting.key) FailConfig(name + ".set." + key + " is given twice");
    }
    settings.push_back(setting);
  }
  return settings;
}

// Changes of the running plant: each checked against the plant the earlier ones left, with the
// plant's own rules (sim::ValidateSimConfig and CheckTurnPerPhysicsStep, the model plant's
// SetPlantModelSetting).
void ReadPlantChanges(const YAML::Node& list, ExperimentConfig& config) {
  if (list.IsDefined() && !list.IsNull() && !list.IsSequence()) {
    FailConfig("plant_changes must be a list of {at_step: N, set: {key: value, ...}}");
  }
  ExperimentConfig changed = config;
  for (size_t i = 0; list.IsSequence() && i < list.size(); ++i) {
    const std::string name = "plant_changes[" + std::to_string(i) + "]";
    const YAML::Node item = list[i];
    if (item.IsDefined() && !item.IsNull() && !item.IsMap()) FailConfig(name + " must be a map");
    PlantChange change;
    change.at_step = ReadChangeStep(item, name, config.plant_changes);
    for (const auto& entry : item) {
      const std::string key = entry.first.as<std::string>();
      if (key != "at_step" && key != "set") {
        throw UnknownKeyError("config: unknown key '" + name + "." + key + "'");
      }
    }
    change.set = ReadChangeSettings(item["set"], name);
    config.plant_changes.push_back(change);
    try {
      changed.plant_changes = {change};
      changed = ConfigAfterChanges(changed, 1);
    } catch (const std::invalid_argument& e) {
      FailConfig(name + ".set." + e.what());
    }
  }
}

bool IsMode(const std::string& name) {
  const auto modes = ControllerModes();
  return std::any_of(modes.begin(), modes.end(),
                     [&](const ControllerModeInfo& m) { return m.name == name; });
}

// The modes to run with their options: controller.modes, or [controller.mode] when only that
// is given, else every registered mode.
void ChooseModes(const ReadState& state, ExperimentConfig& config) {
  if (!state.mode.empty() && !IsMode(state.mode)) {
    FailConfig("controller.mode must be one of " + ControllerModeNames() + ", got '" + state.mode +
               "'");
  }
  std::vector<std::string> modes;
  if (!state.mode.empty()) modes = {state.mode};
  if (state.modes.IsDefined() && !state.modes.IsNull()) {
    try {
      modes = state.modes.as<std::vector<std::string>>();
    } catch (const YAML::Exception&) {
      FailConfig("controller.modes: expected a list, got '" + FlowYaml(state.modes) + "'");
    }
    if (modes.empty()) FailConfig("controller.modes must be a non-empty list");
  }
  if (modes.empty()) {
    for (const ControllerModeInfo& m : ControllerModes()) modes.emplace_back(m.name);
  }
  for (size_t i = 0; i < modes.size(); ++i) {
    if (!IsMode(modes[i])) {
      FailConfig("controller.modes must be a list of " + ControllerModeNames() + ", got '" +
                 modes[i] + "'");
    }
    // Each mode names its own output files.
    if (std::find(modes.begin(), modes.begin() + static_cast<long>(i), modes[i]) !=
        modes.begin() + static_cast<long>(i)) {
      FailConfig("controller.modes must be a list of distinct modes, got '" + modes[i] + "' twice");
    }
  }
  for (const std::string& m : modes) {
    for (const ControllerSpec& spec : state.all_modes) {
      if (ModeOf(spec).name == m) config.controllers.push_back(spec);
    }
  }
}

// The walk as a whole: the locus with the walk's step, the stand's floor and belt, and the
// keys bounded by others.
void CheckWalk(ExperimentConfig& config, const std::string& config_path) {
  TrackConfig& t = config.track;
  if (!t.desired_csv.empty() && fs::path(t.desired_csv).is_relative() &&
      !PathExists(t.desired_csv)) {
    // Relative to the config file when not found from the working directory.
    t.desired_csv = (fs::path(config_path).parent_path() / t.desired_csv).string();
  }
  for (const double v :
       {t.locus.forward_mm, t.locus.outward_mm, t.locus.ground_below_shoulder_mm}) {
    if (!std::isfinite(v)) FailConfig("desired.locus must be finite in every placement key");
  }
  // The stand's floor lies at the walk's ground.
  sim::StandConfig& stand = config.sim.stand;
  stand.ground_below_shoulder_mm = t.locus.ground_below_shoulder_mm;
  if (stand.enabled && !(t.locus.ground_below_shoulder_mm > stand.foot_radius_mm)) {
    FailConfig(
        "desired.locus.ground_below_shoulder_mm must be more than stand.foot_radius_mm on "
        "the stand (the floor lies below the shoulder)");
  }
  // The whole locus, the slow lift-off's ticks against the walk's own flight.
  HalfEllipseLocus shape = t.locus.shape;
  shape.t_step_ticks = t.t_step_ticks;
  if (const std::string problem = HalfEllipseLocusProblem(shape); !problem.empty()) {
    FailConfig("desired.locus." + problem);
  }
  // The treadmill moves with the walk's stance unless told otherwise: the locus's flat bottom,
  // length_mm, swept in ground_fraction of the step.
  if (stand.enabled && stand.belt_follows_walk) {
    stand.belt_speed_mm_per_s = t.locus.shape.length_mm /
                                (t.locus.shape.ground_fraction * t.t_step_ticks * kTickMs / 1000.0);
  }
  if (const std::string problem =
          KeyValueProblem(config.pwl_segments, WithRange(kPwlSegmentsDoc, 1, t.t_step_ticks));
      !problem.empty()) {
    FailConfig("controller.pwl_segments must be " + problem +
               ", at most track.t_step_ticks (a segment spans at least one tick), got " +
               std::to_string(config.pwl_segments));
  }
  for (size_t i = 0; i < config.plant_changes.size(); ++i) {
    const int at_step = config.plant_changes[i].at_step;
    if (const std::string problem = KeyValueProblem(at_step, WithRange(kAtStepDoc, 0, t.steps - 1));
        !problem.empty()) {
      FailConfig("plant_changes[" + std::to_string(i) + "].at_step must be a measured step " +
                 problem + ", below steps, got " + std::to_string(at_step));
    }
  }
}

ExperimentConfig LoadExperimentConfigUnguarded(const std::string& config_path,
                                               const std::vector<std::string>& overrides,
                                               const ConfigScope& scope) {
  ExperimentConfig config;
  const YAML::Node merged = MergedConfig(config_path, overrides, config);
  CheckScope(merged, scope);
  YAML::Emitter emitter;
  emitter << merged;
  config.merged_yaml = std::string(emitter.c_str()) + "\n";
  YamlKeyReader reader(merged);
  ReadState state;
  VisitExperimentKeys(reader, config, state, &reader);
  reader.Finish();
  ResolvePlant(config);
  ReadPlantChanges(state.plant_changes, config);
  ChooseModes(state, config);
  if (state.model_given) config.model = state.model;
  CheckWalk(config, config_path);
  // A log fit plans its work once it has read the logs (ReplanProgress).
  config.planned_ticks = config.logs.given ? 0 : PlannedTicks(config, InScope(scope, "steps"));
  return config;
}

}  // namespace

bool InScope(const ConfigScope& scope, const std::string& section) {
  return scope.sections.empty() ||
         std::find(scope.sections.begin(), scope.sections.end(), section) != scope.sections.end();
}

namespace {

// Every experiment key, listed once with the code's defaults.
const std::vector<KeyRow>& AllExperimentKeys() {
  static const std::vector<KeyRow> all = [] {
    KeyLister lister;
    ExperimentConfig config;
    ReadState state;
    VisitExperimentKeys(lister, config, state, nullptr);
    std::vector<KeyRow> rows = lister.rows();
    for (KeyRow& row : rows) {
      if (row.key.starts_with("model.")) row.default_text = "(identified)";
    }
    return rows;
  }();
  return all;
}

}  // namespace

std::vector<KeyRow> ExperimentKeys(const ConfigScope& scope) {
  std::vector<KeyRow> rows;
  for (const KeyRow& row : AllExperimentKeys()) {
    if (InScope(scope, row.key.substr(0, row.key.find('.')))) rows.push_back(row);
  }
  return rows;
}

const KeyRow* FindKey(std::string_view key) {
  for (const KeyRow& row : AllExperimentKeys()) {
    if (row.key == key) return &row;
  }
  return nullptr;
}

ExperimentConfig ConfigAfterChanges(const ExperimentConfig& config, size_t count) {
  ExperimentConfig after = config;
  for (size_t i = 0; i < count && i < config.plant_changes.size(); ++i) {
    for (const PlantSetting& setting : config.plant_changes[i].set) {
      if (config.plant == PlantKind::kModel) {
        SetPlantModelSetting(after.plant_model, setting.key, setting.value);
      } else {
        sim::SetSimSetting(after.sim, setting.key, setting.value);
        sim::ValidateSimConfig(after.sim);
        sim::CheckTurnPerPhysicsStep(after.sim);
      }
    }
  }
  after.plant_changes.clear();
  return after;
}

ExperimentConfig LoadExperimentConfig(const std::string& config_path,
                                      const std::vector<std::string>& overrides,
                                      const ConfigScope& scope) {
  try {
    return LoadExperimentConfigUnguarded(config_path, overrides, scope);
  } catch (const YAML::Exception& e) {
    // What the conversions did not catch (e.g. a key that is not a scalar).
    FailConfig("'" + config_path + "' is malformed: " + e.what());
  }
}

}  // namespace leglab::experiments
