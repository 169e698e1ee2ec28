#include "leglab/experiments/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <string_view>

#include "leglab/experiments/data_dir.h"
#include "leglab/experiments/output.h"
#include "leglab/experiments/track.h"
#include "leglab/model/joint_model_plant.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Fail(const std::string& what) { throw InputError("config: " + what); }

// Whether a path names something, or a regular file. A path the file system cannot even look
// up (a name too long, a component not a folder) is a path that does not exist: the user's
// input, so never a filesystem_error escaping as an internal error.
bool Exists(const fs::path& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}
bool IsFile(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// Shortest text that reads back as `value`.
std::string Text(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (value == std::round(value) && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string RangeText(const NumericRange& r) {
  std::string text = std::string(r.min_open ? "(" : "[") + Text(r.min) + ", " + Text(r.max) +
                     (r.max_open ? ")" : "]");
  if (!r.unit.empty()) text += " " + std::string(r.unit);
  return text;
}

const NumericRange* FindRange(const std::string& key) {
  for (const NumericRange& r : NumericKeyRanges()) {
    if (r.key == key) return &r;
  }
  return nullptr;
}

// Checks `value` of `key` (as the user wrote it) against its documented range, the range of
// `range_key` when given (a plant change's value has the range of the key it sets).
void CheckRange(const std::string& key, double value, const std::string& range_key = "") {
  const NumericRange* range = FindRange(range_key.empty() ? key : range_key);
  // Every numeric key has a range: reading one without is a bug of ours, not bad input.
  if (range == nullptr) throw std::logic_error("config key '" + key + "' has no documented range");
  const bool above_min = range->min_open ? value > range->min : value >= range->min;
  const bool below_max = range->max_open ? value < range->max : value <= range->max;
  if (!(above_min && below_max)) {
    Fail(key + " must be in " + RangeText(*range) + ", got " + Text(value));
  }
}

std::string KeyText(const YAML::Node& key) {
  if (key.IsScalar()) return key.Scalar();
  YAML::Emitter out;
  out << YAML::Flow << key;
  return out.c_str();
}

// Fails naming the first key given twice in one map of `node` (yaml-cpp keeps both, and a
// lookup would silently take one). `budget` and `depth` bound the walk: aliases may repeat a
// subtree exponentially often (an alias bomb) or make it a cycle, and no config of ours has
// 100000 nodes or 64 levels.
void CheckNoDuplicateKeys(const YAML::Node& node, const std::string& where,
                          const std::string& prefix, int& budget, int depth = 0) {
  if (--budget < 0) Fail(where + " is too large (over 100000 nodes, or aliases nested too deep)");
  // An alias inside its own anchor makes the tree a cycle (found by tests/.../fuzz_test.cc).
  if (depth > 64) Fail(where + " nests deeper than 64 levels (an alias inside its own anchor?)");
  if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& item : node) {
      const std::string key = prefix + KeyText(item.first);
      if (!seen.insert(key).second) Fail(where + ": key '" + key + "' is given twice");
      CheckNoDuplicateKeys(item.second, where, key + ".", budget, depth + 1);
    }
  } else if (node.IsSequence()) {
    for (const auto& element : node) {
      CheckNoDuplicateKeys(element, where, prefix, budget, depth + 1);
    }
  }
}

void CheckNoDuplicateKeys(const YAML::Node& node, const std::string& where,
                          const std::string& prefix = "") {
  int budget = 100000;
  CheckNoDuplicateKeys(node, where, prefix, budget);
}

YAML::Node LoadYamlFile(const fs::path& path, const std::string& what) {
  if (!IsFile(path)) Fail(what + " '" + path.string() + "' does not exist");
  try {
    YAML::Node node = YAML::LoadFile(path.string());
    if (node.IsNull()) return YAML::Node(YAML::NodeType::Map);
    if (!node.IsMap()) Fail(what + " '" + path.string() + "' is not a YAML map");
    CheckNoDuplicateKeys(node, what + " '" + path.string() + "'");
    return node;
  } catch (const YAML::Exception& e) {
    Fail(what + " '" + path.string() + "' is malformed: " + e.what());
  }
}

// Deep copy of `over` onto `base`: maps merge key by key, anything else replaces.
void MergeInto(YAML::Node base, const YAML::Node& over) {
  for (const auto& item : over) {
    const std::string key = item.first.as<std::string>();
    if (item.second.IsMap() && base[key] && base[key].IsMap()) {
      MergeInto(base[key], item.second);
    } else {
      base[key] = YAML::Clone(item.second);
    }
  }
}

// Applies "a.b.c=value" to `root`, creating maps on the way. A YAML::Node is a handle: taken
// by value, it still edits the caller's tree.
void ApplyOverride(YAML::Node root,  // NOLINT(performance-unnecessary-value-param)
                   const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    Fail("--set '" + assignment + "' is not of the form key=value");
  }
  const std::string path = assignment.substr(0, equals);
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(equals + 1));
  } catch (const YAML::Exception& e) {
    Fail("--set " + path + ": the value is not valid YAML: " + e.what());
  }
  CheckNoDuplicateKeys(value, "--set " + path, path + ".");
  std::vector<std::string> keys;
  for (size_t start = 0;;) {
    const size_t dot = path.find('.', start);
    keys.push_back(path.substr(start, dot - start));
    if (keys.back().empty()) Fail("--set '" + assignment + "' has an empty key");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  // yaml-cpp nodes are handles: walk with fresh handles, never reassign one.
  std::vector<YAML::Node> chain{root};
  for (size_t i = 0; i + 1 < keys.size(); ++i) {
    YAML::Node next = chain.back()[keys[i]];
    if (next.IsDefined() && !next.IsNull() && !next.IsMap()) {
      Fail("--set " + path + ": '" + keys[i] + "' is not a map");
    }
    if (!next.IsDefined() || next.IsNull()) chain.back()[keys[i]] = YAML::Node(YAML::NodeType::Map);
    chain.push_back(chain.back()[keys[i]]);
  }
  chain.back()[keys.back()] = value;
}

// Reads one YAML map into structs: every key read is remembered, so Finish() can name the
// keys nobody asked for.
class MapReader {
 public:
  MapReader(const YAML::Node& node, std::string prefix) : node_(node), prefix_(std::move(prefix)) {
    if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
      Fail((prefix_.empty() ? std::string("the config") : prefix_) + " must be a map");
    }
  }

  // Reads `key` into `value` when given. A number (integer or floating point) is checked
  // against its documented range (NumericKeyRanges) whether given or defaulted.
  template <typename T>
  void Read(const std::string& key, T& value) {
    used_.insert(key);
    const YAML::Node child = node_.IsMap() ? node_[key] : YAML::Node();
    if (child.IsDefined() && !child.IsNull()) {
      try {
        if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
          // Read wide, so that a value beyond T's range is reported as out of range.
          const auto wide = child.as<long long>();
          CheckRange(Name(key), static_cast<double>(wide));
          value = static_cast<T>(wide);
        } else {
          value = child.as<T>();
        }
      } catch (const YAML::Exception&) {
        Fail(Name(key) + ": expected " + TypeName<T>() + ", got '" + Dump(child) + "'");
      }
    }
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      CheckRange(Name(key), static_cast<double>(value));
    }
  }

  // Reads a list of numbers, each checked against the range of `key`.
  void ReadList(const std::string& key, std::vector<double>& values) {
    Read(key, values);
    for (const double v : values) CheckRange(Name(key), v);
  }
  void ReadList(const std::string& key, std::vector<int>& values) {
    used_.insert(key);
    const YAML::Node child = node_.IsMap() ? node_[key] : YAML::Node();
    if (child.IsDefined() && !child.IsNull()) {
      std::vector<long long> wide;
      try {
        wide = child.as<std::vector<long long>>();
      } catch (const YAML::Exception&) {
        Fail(Name(key) + ": expected a list of integers, got '" + Dump(child) + "'");
      }
      values.clear();
      for (const long long v : wide) {
        CheckRange(Name(key), static_cast<double>(v));
        values.push_back(static_cast<int>(v));
      }
    }
    for (const int v : values) CheckRange(Name(key), v);
  }

  // The node under `key` (undefined when absent), for values that are not a plain scalar, map
  // or list of scalars.
  YAML::Node Raw(const std::string& key) {
    used_.insert(key);
    return node_.IsMap() ? node_[key] : YAML::Node();
  }

  bool Has(const std::string& key) const {
    return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
  }

  MapReader Child(const std::string& key) {
    used_.insert(key);
    return MapReader(node_.IsMap() ? node_[key] : YAML::Node(), Name(key));
  }

  std::string Name(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }

  void Finish() const {
    if (!node_.IsMap()) return;
    for (const auto& item : node_) {
      const std::string key = item.first.as<std::string>();
      if (!used_.count(key)) throw UnknownKeyError("config: unknown key '" + Name(key) + "'");
    }
  }

 private:
  static std::string Dump(const YAML::Node& node) {
    YAML::Emitter out;
    out << YAML::Flow << node;
    return out.c_str();
  }
  template <typename T>
  static std::string TypeName() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "a number";
    else if constexpr (std::is_same_v<T, std::string>)
      return "a string";
    else
      return "a list";
  }

  YAML::Node node_;
  std::string prefix_;
  std::set<std::string> used_;
};

// The registry's view of the `controller` map: each mode reads its own keys through it.
// A dotted key ("initial_model.theta0_deg") is read from the nested map it names.
class ControllerOptions final : public OptionReader {
 public:
  explicit ControllerOptions(MapReader& map) : map_(map) {}
  void Read(std::string_view key, int& value) override { ReadAt(key, value); }
  void Read(std::string_view key, double& value) override { ReadAt(key, value); }
  void Read(std::string_view key, bool& value) override { ReadAt(key, value); }
  void Read(std::string_view key, std::string& value) override { ReadAt(key, value); }
  [[noreturn]] void Fail(std::string_view key, const std::string& expectation) override {
    leglab::experiments::Fail(map_.Name(std::string(key)) + " must be " + expectation);
  }
  // Names the unknown keys of the nested maps read.
  void Finish() const {
    for (const auto& [name, child] : children_) child.Finish();
  }

 private:
  template <typename T>
  void ReadAt(std::string_view key, T& value) {
    const size_t dot = key.rfind('.');
    if (dot == std::string_view::npos) return map_.Read(std::string(key), value);
    const std::string path(key.substr(0, dot));
    auto it = children_.find(path);
    if (it == children_.end()) {
      // Each level of the path is a child of the one before.
      MapReader* parent = &map_;
      std::string walked;
      for (size_t start = 0; start <= path.size();) {
        const size_t next = std::min(path.find('.', start), path.size());
        const std::string part = path.substr(start, next - start);
        walked += (walked.empty() ? "" : ".") + part;
        if (!children_.count(walked)) children_.emplace(walked, parent->Child(part));
        parent = &children_.at(walked);
        start = next + 1;
      }
      it = children_.find(path);
    }
    it->second.Read(std::string(key.substr(dot + 1)), value);
  }

  MapReader& map_;
  std::map<std::string, MapReader> children_;
};

void Require(bool ok, const std::string& key, const std::string& expectation) {
  if (!ok) Fail(key + " must be " + expectation);
}

bool IsMode(const std::string& name) {
  for (const ControllerModeInfo& m : ControllerModes()) {
    if (m.name == name) return true;
  }
  return false;
}

// The four keys of a joint model in `m` over `params`, validated by the model's own rules.
void ReadJointModel(MapReader& m, JointModelParams& params) {
  m.Read("v_max_deg_per_tick", params.v_max_deg_per_tick);
  m.Read("theta0_deg", params.theta0_deg);
  m.Read("lag_ticks", params.lag_ticks);
  m.Read("accel_ticks", params.accel_ticks);
  if (const std::string problem = JointModelParamsProblem(params); !problem.empty()) {
    Fail(m.Name(problem));
  }
}

fs::path ResolveRobot(const std::string& robot, const fs::path& config_dir) {
  if (robot.find('/') != std::string::npos || fs::path(robot).extension() == ".yaml") {
    return fs::path(robot).is_absolute() ? fs::path(robot) : config_dir / robot;
  }
  // A robot name: robots/<name>/robot.yaml in the working directory, else leglab's own
  // (DataDir(): the installed share/leglab, or the build tree's link to the source folder).
  fs::path here = fs::path("robots") / robot / "robot.yaml";
  if (Exists(here)) return here;
  return DataDir() / "robots" / robot / "robot.yaml";
}

// An experiment file with the file named by its `extends:` key (relative to it) merged beneath,
// recursively.
YAML::Node LoadWithBase(const fs::path& path, int depth, const std::string& what = "config file") {
  YAML::Node node = LoadYamlFile(path, depth == 0 ? what : "extended " + what);
  const YAML::Node base_name = node["extends"];
  if (!base_name) return node;
  if (depth >= 8) Fail("extends: more than 8 levels from '" + path.string() + "' (a cycle?)");
  std::string base;
  try {
    base = base_name.as<std::string>();
  } catch (const YAML::Exception&) {
    Fail("extends: expected a file name in '" + path.string() + "'");
  }
  YAML::Node merged = LoadWithBase(
      fs::path(base).is_absolute() ? fs::path(base) : path.parent_path() / base, depth + 1, what);
  node.remove("extends");
  MergeInto(merged, node);
  return merged;
}

// The top-level keys some program reads.
bool IsKnownTopLevelKey(const std::string& key) {
  static constexpr std::string_view kKeys[] = {
      "robot",      "urdf",  "plant",    "plant_model", "sim",   "servo",        "sensor", "seed",
      "controller", "model", "identify", "desired",     "track", "warmup_steps", "steps",  "stand"};
  for (std::string_view k : kKeys) {
    if (k == key) return true;
  }
  for (const ControllerModeInfo& m : ControllerModes()) {
    if (m.config_section == key) return true;
  }
  return false;
}

// The first key path under `node` (a.b.c), as the user would have written it.
std::string FirstKeyPath(const std::string& prefix, const YAML::Node& node) {
  if (!node.IsMap() || node.size() == 0) return prefix;
  const auto first = node.begin();
  return FirstKeyPath(prefix + "." + KeyText(first->first), first->second);
}

bool InScope(const ConfigScope& scope, const std::string& key) {
  return scope.sections.empty() ||
         std::find(scope.sections.begin(), scope.sections.end(), key) != scope.sections.end();
}

// A key some other program uses, given to this one: say so rather than ignore it.
void CheckScope(const YAML::Node& merged, const ConfigScope& scope) {
  for (const auto& item : merged) {
    const std::string key = KeyText(item.first);
    if (IsKnownTopLevelKey(key) && !InScope(scope, key)) {
      Fail(FirstKeyPath(key, item.second) + " is not used by " + scope.program);
    }
  }
}

ExperimentConfig LoadExperimentConfigUnguarded(const std::string& config_path,
                                               const std::vector<std::string>& overrides,
                                               const ConfigScope& scope) {
  YAML::Node experiment = LoadWithBase(config_path, 0);
  for (const std::string& o : overrides) ApplyOverride(experiment, o);

  ExperimentConfig config;
  std::string robot = "ers210a";
  if (experiment["robot"]) {
    try {
      robot = experiment["robot"].as<std::string>();
    } catch (const YAML::Exception&) {
      Fail("robot: expected a robot name or a path to a robot.yaml");
    }
    // The error below names it, on one line.
    if (robot.find_first_of("\n\r") != std::string::npos) {
      Fail("robot: expected a robot name or a path to a robot.yaml, got text with a line break");
    }
  }
  const fs::path robot_yaml = ResolveRobot(robot, fs::path(config_path).parent_path());
  if (!Exists(robot_yaml)) Fail("robot '" + robot + "': no " + robot_yaml.string());
  config.robot_yaml = robot_yaml.string();
  YAML::Node merged = LoadWithBase(robot_yaml, 0, "robot file");
  MergeInto(merged, experiment);
  CheckScope(merged, scope);

  MapReader root(merged, "");
  root.Read("robot", robot);

  // The plant (robot.yaml).
  bool belt_given = false;  // stand.belt_speed_mm_per_s, else the walk's stance speed
  std::string urdf;
  root.Read("urdf", urdf);
  if (urdf.empty()) Fail("urdf: no URDF given (robot file " + robot_yaml.string() + ")");
  const fs::path urdf_path =
      fs::path(urdf).is_absolute() ? fs::path(urdf) : robot_yaml.parent_path() / urdf;
  if (!IsFile(urdf_path)) Fail("urdf: '" + urdf_path.string() + "' does not exist");
  config.sim.urdf_path = urdf_path.string();
  {
    MapReader sim = root.Child("sim");
    sim.Read("physics_dt_ms", config.sim.physics_dt_ms);
    sim.Finish();
    MapReader servo = root.Child("servo");
    servo.Read("delay_ms", config.sim.servo.delay_ms);
    servo.Read("max_speed_deg_s", config.sim.servo.max_speed_deg_s);
    servo.Read("gain_per_s", config.sim.servo.gain_per_s);
    servo.Read("damping", config.sim.servo.damping);
    servo.Read("smoothing_ms", config.sim.servo.smoothing_ms);
    servo.Read("max_torque_nm", config.sim.servo.max_torque_nm);
    servo.Finish();
    MapReader sensor = root.Child("sensor");
    sensor.Read("noise_deg", config.sim.sensor.noise_deg);
    sensor.Finish();
    // The single-leg test stand: built when a `stand:` section is given (robots/ers210a_stand).
    sim::StandConfig& stand_config = config.sim.stand;
    stand_config.enabled = root.Has("stand");
    MapReader stand = root.Child("stand");
    stand.Read("load_kg", stand_config.load_kg);
    stand.Read("stop_below_shoulder_mm", stand_config.stop_below_shoulder_mm);
    stand.Read("friction", stand_config.friction);
    stand.Read("contact_stiffness_n_per_m", stand_config.contact_stiffness_n_per_m);
    stand.Read("contact_damping_n_s_per_m", stand_config.contact_damping_n_s_per_m);
    stand.Read("foot_radius_mm", stand_config.foot_radius_mm);
    belt_given = stand.Has("belt_speed_mm_per_s");
    stand.Read("belt_speed_mm_per_s", stand_config.belt_speed_mm_per_s);
    stand.Read("sled_stiffness_n_per_m", stand_config.sled_stiffness_n_per_m);
    stand.Read("sled_damping_n_s_per_m", stand_config.sled_damping_n_s_per_m);
    stand.Finish();
    long long seed = static_cast<long long>(config.sim.seed);
    root.Read("seed", seed);
    Require(seed >= 0, "seed", "a non-negative integer");
    config.sim.seed = static_cast<std::uint64_t>(seed);
    try {
      sim::ValidateSimConfig(config.sim);
    } catch (const std::invalid_argument& e) {
      Fail(e.what());
    }
  }

  // The plant: the simulated leg, or the joint model as an ideal plant.
  {
    std::string plant = "sim";
    root.Read("plant", plant);
    Require(plant == "sim" || plant == "model", "plant", "sim or model, got '" + plant + "'");
    config.plant = plant == "model" ? PlantKind::kModel : PlantKind::kSim;
    MapReader m = root.Child("plant_model");
    ReadJointModel(m, config.plant_model);
    m.Finish();
  }

  // Changes of the running plant: each checked against the plant the earlier ones left, with
  // the plant's own rules (sim::ValidateSimConfig, the model plant's SetPlantModelSetting).
  {
    const YAML::Node list = root.Raw("plant_changes");
    ExperimentConfig changed = config;
    if (list.IsDefined() && !list.IsNull() && !list.IsSequence()) {
      Fail("plant_changes must be a list of {at_step: N, set: {key: value, ...}}");
    }
    for (size_t i = 0; list.IsSequence() && i < list.size(); ++i) {
      const std::string name = "plant_changes[" + std::to_string(i) + "]";
      MapReader item(list[i], name);
      PlantChange change;
      change.at_step = -1;
      // A measured step: its range is [0, steps), checked once steps is read.
      if (const YAML::Node at = item.Raw("at_step"); at.IsDefined() && !at.IsNull()) {
        long long step = -1;
        try {
          step = at.as<long long>();
        } catch (const YAML::Exception&) {
          Fail(name + ".at_step: expected an integer");
        }
        Require(step >= 0 && step <= 1'000'000, name + ".at_step",
                "a measured step in [0, 1000000]");
        change.at_step = static_cast<int>(step);
      }
      Require(change.at_step >= 0, name + ".at_step", "given, a measured step >= 0");
      if (!config.plant_changes.empty()) {
        Require(change.at_step > config.plant_changes.back().at_step, name + ".at_step",
                "after the previous change's (" +
                    std::to_string(config.plant_changes.back().at_step) + ")");
      }
      // `set` may name keys dotted (servo.delay_ms: 56) or nested (servo: {delay_ms: 56}).
      const YAML::Node set = item.Raw("set");
      item.Finish();
      if (!set.IsMap() || set.size() == 0)
        Fail(name + ".set must be a non-empty map of key: value");
      std::vector<std::pair<std::string, YAML::Node>> pending;
      for (const auto& entry : set)
        pending.emplace_back(entry.first.as<std::string>(), entry.second);
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
          Fail(name + ".set." + key + ": expected a number");
        }
        if (FindRange(key) != nullptr) CheckRange(name + ".set." + key, setting.value, key);
        change.set.push_back(setting);
      }
      config.plant_changes.push_back(change);
      try {
        changed.plant_changes = {change};
        changed = ConfigAfterChanges(changed, 1);
      } catch (const std::invalid_argument& e) {
        Fail(name + ".set." + e.what());
      }
    }
  }

  // The controllers: every registered mode reads (and so validates) its own keys; the modes
  // to run keep their options.
  {
    MapReader c = root.Child("controller");
    std::string mode;
    c.Read("mode", mode);
    if (!mode.empty() && !IsMode(mode)) {
      Fail("controller.mode must be one of " + ControllerModeNames() + ", got '" + mode + "'");
    }
    // A lone controller.mode picks the one mode to run; controller.modes, when given, wins.
    std::vector<std::string> modes;
    if (!mode.empty()) modes = {mode};
    if (modes.empty()) {
      for (const ControllerModeInfo& m : ControllerModes()) modes.emplace_back(m.name);
    }
    c.Read("modes", modes);
    Require(!modes.empty(), "controller.modes", "a non-empty list");
    for (size_t i = 0; i < modes.size(); ++i) {
      Require(IsMode(modes[i]), "controller.modes",
              "a list of " + ControllerModeNames() + ", got '" + modes[i] + "'");
      // Each mode names its own output files.
      Require(std::find(modes.begin(), modes.begin() + static_cast<long>(i), modes[i]) ==
                  modes.begin() + static_cast<long>(i),
              "controller.modes", "a list of distinct modes, got '" + modes[i] + "' twice");
    }
    c.Read("pwl_segments", config.pwl_segments);
    // Each mode reads its keys from its own section (`controller` unless it says otherwise).
    std::map<std::string, MapReader> sections;
    sections.emplace("controller", c);
    std::vector<ControllerSpec> all;
    for (const ControllerModeInfo& m : ControllerModes()) {
      const std::string section(m.config_section);
      if (!sections.count(section)) sections.emplace(section, root.Child(section));
      ControllerOptions options(sections.at(section));
      all.push_back(ReadControllerSpec(m.name, options));
      options.Finish();
    }
    for (const std::string& m : modes) {
      for (const ControllerSpec& spec : all) {
        if (ModeOf(spec).name == m) config.controllers.push_back(spec);
      }
    }
    for (const auto& [name, section] : sections) section.Finish();
  }

  // A given model (all four keys), else it is identified on the plant.
  if (root.Has("model")) {
    MapReader m = root.Child("model");
    for (const char* key : {"v_max_deg_per_tick", "theta0_deg", "lag_ticks", "accel_ticks"}) {
      Require(m.Has(key), m.Name(key), "given (model.* needs all four keys, or none)");
    }
    JointModelParams p;
    ReadJointModel(m, p);
    m.Finish();
    config.model = p;
  } else {
    root.Child("model");  // an explicit `model: ~` is the same as none
  }

  // The step test.
  {
    MapReader id = root.Child("identify");
    IdentifyConfig& c = config.identify;
    id.ReadList("theta_test_deg", c.theta_test_deg);
    id.Read("t_step_ticks", c.t_step_ticks);
    id.Read("settle_cycles", c.settle_cycles);
    id.Read("record_cycles", c.record_cycles);
    id.Read("average_cycles", c.average_cycles);
    std::vector<double> hold(c.hold_deg.begin(), c.hold_deg.end());
    id.ReadList("hold_deg", hold);
    std::string joints;
    for (std::string_view name : kLegJointNames)
      joints += (joints.empty() ? "" : ", ") + std::string(name);
    Require(hold.size() == kLegJoints, "identify.hold_deg",
            "a list of " + std::to_string(kLegJoints) + " angles (" + joints + ")");
    std::copy(hold.begin(), hold.end(), c.hold_deg.begin());
    std::vector<int> lag{c.search.lag_min_ticks, c.search.lag_max_ticks};
    std::vector<int> accel{c.search.accel_min_ticks, c.search.accel_max_ticks};
    id.ReadList("lag_range_ticks", lag);
    id.ReadList("accel_range_ticks", accel);
    id.Finish();
    Require(!c.theta_test_deg.empty() && c.theta_test_deg.size() <= 8, "identify.theta_test_deg",
            "a list of 1 to 8 step heights");
    for (size_t i = 0; i < c.theta_test_deg.size(); ++i) {
      const double theta = c.theta_test_deg[i];
      Require(theta != 0.0, "identify.theta_test_deg", "a list of non-zero step heights");
      for (size_t k = 0; k < i; ++k) {
        // Each height names its own output file (step_<joint>_<theta>.csv).
        Require(c.theta_test_deg[k] != theta, "identify.theta_test_deg",
                "a list of distinct step heights, got " + Text(theta) + " twice");
      }
    }
    Require(lag.size() == 2 && lag[1] >= lag[0], "identify.lag_range_ticks",
            "[min, max] with 0 <= min <= max <= 50");
    Require(accel.size() == 2 && accel[1] >= accel[0], "identify.accel_range_ticks",
            "[min, max] with 1 <= min <= max <= 50");
    c.search = {lag[0], lag[1], accel[0], accel[1]};
    Require(c.record_cycles * c.t_step_ticks > lag[1] + accel[1], "identify.record_cycles",
            "long enough to cover the identification's warm-up of lag + accel ticks");
    // The fit scores every (l, a) candidate over every recorded tick.
    const long long candidates =
        static_cast<long long>(lag[1] - lag[0] + 1) * (accel[1] - accel[0] + 1);
    const long long work = candidates * c.record_cycles * c.t_step_ticks *
                           static_cast<long long>(c.theta_test_deg.size());
    if (work > kMaxIdentificationWork) {
      Fail("identify: " + std::to_string(candidates) + " (l, a) candidates (lag_range_ticks x " +
           "accel_range_ticks) times " + std::to_string(c.record_cycles * c.t_step_ticks) +
           " recorded ticks (record_cycles x t_step_ticks) times " +
           std::to_string(c.theta_test_deg.size()) + " step heights is " + std::to_string(work) +
           ", more than the " + std::to_string(kMaxIdentificationWork) +
           " a fit may take; narrow the ranges or record fewer cycles");
    }
  }

  // What to track.
  {
    MapReader desired = root.Child("desired");
    TrackConfig& t = config.track;
    desired.Read("csv", t.desired_csv);
    if (!t.desired_csv.empty() && fs::path(t.desired_csv).is_relative() && !Exists(t.desired_csv)) {
      // Relative to the config file when not found from the working directory.
      t.desired_csv = (fs::path(config_path).parent_path() / t.desired_csv).string();
    }
    MapReader locus = desired.Child("locus");
    locus.Read("length_mm", t.locus.shape.length_mm);
    locus.Read("height_mm", t.locus.shape.height_mm);
    locus.Read("ground_fraction", t.locus.shape.ground_fraction);
    locus.Read("forward_mm", t.locus.forward_mm);
    locus.Read("outward_mm", t.locus.outward_mm);
    locus.Read("ground_below_shoulder_mm", t.locus.ground_below_shoulder_mm);
    locus.Read("skew", t.locus.shape.skew);
    locus.Read("swing_end_speed_fraction", t.locus.shape.swing_end_speed_fraction);
    locus.Read("liftoff_ramp_mm", t.locus.shape.liftoff_ramp_mm);
    locus.Read("liftoff_ramp_ticks", t.locus.shape.liftoff_ramp_ticks);
    locus.Read("body_pitch_deg", t.locus.body_pitch_deg);
    locus.Finish();
    desired.Finish();
    {
      // The slow lift-off is checked below, once the walk's step (and so its flight) is known.
      HalfEllipseLocus shape = t.locus.shape;
      shape.liftoff_ramp_mm = 0.0;
      if (const std::string problem = HalfEllipseLocusProblem(shape); !problem.empty()) {
        Fail(locus.Name(problem));
      }
    }
    for (const double v :
         {t.locus.forward_mm, t.locus.outward_mm, t.locus.ground_below_shoulder_mm}) {
      Require(std::isfinite(v), "desired.locus", "finite in every placement key");
    }
    // The stand's floor lies at the walk's ground.
    config.sim.stand.ground_below_shoulder_mm = t.locus.ground_below_shoulder_mm;
    if (config.sim.stand.enabled) {
      Require(t.locus.ground_below_shoulder_mm > config.sim.stand.foot_radius_mm,
              "desired.locus.ground_below_shoulder_mm",
              "more than stand.foot_radius_mm on the stand (the floor lies below the shoulder)");
    }

    MapReader track = root.Child("track");
    track.Read("t_step_ticks", t.t_step_ticks);
    root.Read("warmup_steps", t.warmup_steps);  // top-level keys, as the track issue names them
    root.Read("steps", t.steps);
    std::string search = "true";
    track.Read("search_shift", search);
    if (search == "exhaustive") {
      t.search_shift = ShiftSearch::kExhaustive;
    } else {
      bool on = true;
      try {
        on = YAML::Load(search).as<bool>();
      } catch (const YAML::Exception&) {
        Fail("track.search_shift must be true, false or exhaustive, got '" + search + "'");
      }
      t.search_shift = on ? ShiftSearch::kShiftedRun : ShiftSearch::kNone;
    }
    track.Finish();
    {
      // The whole locus, the slow lift-off's ticks against the walk's own flight.
      HalfEllipseLocus shape = t.locus.shape;
      shape.t_step_ticks = t.t_step_ticks;
      if (const std::string problem = HalfEllipseLocusProblem(shape); !problem.empty()) {
        Fail(locus.Name(problem));
      }
    }
    // The stand's treadmill moves with the walk's stance unless told otherwise: the locus's
    // flat bottom, length_mm, swept in ground_fraction of the step.
    if (config.sim.stand.enabled && !belt_given) {
      config.sim.stand.belt_speed_mm_per_s =
          t.locus.shape.length_mm /
          (t.locus.shape.ground_fraction * t.t_step_ticks * kTickMs / 1000.0);
    }
    Require(config.pwl_segments <= t.t_step_ticks, "controller.pwl_segments",
            "at most track.t_step_ticks = " + std::to_string(t.t_step_ticks) +
                " (a segment spans at least one tick), got " + std::to_string(config.pwl_segments));
    const long long per_run =
        (static_cast<long long>(t.warmup_steps) + t.steps) * static_cast<long long>(t.t_step_ticks);
    if (per_run > kMaxTicksPerRun) {
      Fail("(warmup_steps + steps) x track.t_step_ticks = (" + std::to_string(t.warmup_steps) +
           " + " + std::to_string(t.steps) + ") x " + std::to_string(t.t_step_ticks) + " = " +
           std::to_string(per_run) + " ticks per run, more than " +
           std::to_string(kMaxTicksPerRun));
    }
    for (size_t i = 0; i < config.plant_changes.size(); ++i) {
      Require(config.plant_changes[i].at_step < t.steps,
              "plant_changes[" + std::to_string(i) + "].at_step",
              "a measured step, below steps = " + std::to_string(t.steps) + ", got " +
                  std::to_string(config.plant_changes[i].at_step));
    }
  }
  root.Finish();

  // What the whole run simulates: the step tests (unless a model is given to track), then
  // one run per mode, and per searched candidate plus the best one's rerun.
  long long total = 0;
  const bool tracks = InScope(scope, "steps");
  if (!tracks || !config.model) {
    const IdentifyConfig& id = config.identify;
    total += static_cast<long long>(kLegJoints) * static_cast<long long>(id.theta_test_deg.size()) *
             (id.settle_cycles + id.record_cycles) * id.t_step_ticks;
  }
  if (tracks) {
    long long runs = 0;
    bool walk_fit = false;
    for (const ControllerSpec& spec : config.controllers) {
      // A searched mode tries at most one candidate per tick of the step (time_shift's k).
      runs += ModeOf(spec).searchable && config.track.search_shift != ShiftSearch::kNone
                  ? config.track.t_step_ticks + 1
                  : 1;
      walk_fit = walk_fit || UsesWalkModels(spec);
    }
    total += runs * (static_cast<long long>(config.track.warmup_steps) + config.track.steps) *
             config.track.t_step_ticks;
    // The walk the walk-fitted models are fitted to, once for all the modes that use them.
    if (walk_fit) {
      total +=
          static_cast<long long>(kWalkFitWarmupSteps + kWalkFitSteps) * config.track.t_step_ticks;
    }
  }
  if (total > kMaxTotalTicks) {
    Fail("the run would simulate " + std::to_string(total) + " ticks (every mode and searched " +
         "candidate, (warmup_steps + steps) x track.t_step_ticks each), more than " +
         std::to_string(kMaxTotalTicks) + "; run fewer steps, fewer modes or " +
         "track.search_shift=false");
  }
  config.planned_ticks = total;
  return config;
}

}  // namespace

ExperimentConfig ConfigAfterChanges(const ExperimentConfig& config, size_t count) {
  ExperimentConfig after = config;
  for (size_t i = 0; i < count && i < config.plant_changes.size(); ++i) {
    for (const PlantSetting& setting : config.plant_changes[i].set) {
      if (config.plant == PlantKind::kModel) {
        SetPlantModelSetting(after.plant_model, setting.key, setting.value);
      } else {
        sim::SetSimSetting(after.sim, setting.key, setting.value);
        sim::ValidateSimConfig(after.sim);
      }
    }
  }
  after.plant_changes.clear();
  return after;
}

namespace {

// Each range says what is physically meaningful for the ERS-210A-sized leg and its 8 ms
// servo frame, wide enough for every experiment in the README, narrow enough that no value
// overflows a tick count or sizes a run beyond kMaxTicksPerRun. The README's config reference
// lists the same ranges.
constexpr NumericRange kRanges[] = {
    {"seed", 0, 9.2e18, false, false, ""},
    {"sim.physics_dt_ms", 0.1, 8, false, false, "ms"},
    {"servo.delay_ms", 0, 400, false, false, "ms"},
    {"servo.max_speed_deg_s", 30, 3600, false, false, "deg/s"},
    {"servo.gain_per_s", 1, 1000, false, false, "1/s"},
    {"servo.damping", 0, 10, false, false, ""},
    {"servo.smoothing_ms", 0, 400, false, false, "ms"},
    {"servo.max_torque_nm", 0.1, 100, false, false, "N m"},
    {"sensor.noise_deg", 0, 2, false, false, "deg"},
    {"stand.load_kg", 0, 10, true, false, "kg"},
    {"stand.stop_below_shoulder_mm", 0, 50, false, false, "mm"},
    {"stand.friction", 0, 5, false, false, ""},
    {"stand.contact_stiffness_n_per_m", 100, 1e6, false, false, "N/m"},
    {"stand.contact_damping_n_s_per_m", 0, 1000, false, false, "N s/m"},
    {"stand.foot_radius_mm", 0, 50, true, false, "mm"},
    {"stand.belt_speed_mm_per_s", -2000, 2000, false, false, "mm/s"},
    {"stand.sled_stiffness_n_per_m", 0, 1e5, false, false, "N/m"},
    {"stand.sled_damping_n_s_per_m", 0, 1000, false, false, "N s/m"},
    {"plant_model.v_max_deg_per_tick", 0.01, 45, false, false, "deg/tick"},
    {"plant_model.theta0_deg", 0.01, 180, false, false, "deg"},
    {"plant_model.lag_ticks", 0, 50, false, false, "ticks"},
    {"plant_model.accel_ticks", 1, 50, false, false, "ticks"},
    {"model.v_max_deg_per_tick", 0.01, 45, false, false, "deg/tick"},
    {"model.theta0_deg", 0.01, 180, false, false, "deg"},
    {"model.lag_ticks", 0, 50, false, false, "ticks"},
    {"model.accel_ticks", 1, 50, false, false, "ticks"},
    {"controller.shift_ticks", 0, 999, false, false, "ticks"},
    {"controller.pwl_segments", 1, 1000, false, false, ""},
    {"optimal.joint_weight", 0, 100, false, false, ""},
    {"optimal.request_smoothing", 0, 1e6, false, false, ""},
    {"ilc.gain", 0, 1, true, false, ""},
    {"ilc.filter_ticks", 1, 999, false, false, "ticks"},
    {"ilc.solver_iterations", 1, 1000, false, false, ""},
    {"ilc.solver_tolerance_deg", 0, 1, false, false, "deg"},
    {"ilc.joint_weight", 0, 100, false, false, ""},
    {"ilc.request_smoothing", 0, 1e6, false, false, ""},
    {"adaptive.initial_model.v_max_deg_per_tick", 0, 45, true, false, "deg/tick"},
    {"adaptive.initial_model.theta0_deg", 0, 180, true, false, "deg"},
    {"adaptive.initial_model.lag_ticks", 0, 12, false, false, "ticks"},
    {"adaptive.initial_model.accel_ticks", 1, 12, false, false, "ticks"},
    {"adaptive.window_steps", 1, 50, false, false, ""},
    {"adaptive.probe_deg", 0, 45, false, false, "deg"},
    {"adaptive.probe_ticks", 0, 64, false, false, "ticks"},
    {"identify.theta_test_deg", -180, 180, false, false, "deg"},
    {"identify.t_step_ticks", 4, 1000, false, false, "ticks"},
    {"identify.settle_cycles", 1, 1000, false, false, ""},
    {"identify.record_cycles", 1, 1000, false, false, ""},
    {"identify.hold_deg", -180, 180, false, false, "deg"},
    {"identify.lag_range_ticks", 0, 50, false, false, "ticks"},
    {"identify.accel_range_ticks", 1, 50, false, false, "ticks"},
    {"desired.locus.length_mm", 0, 1000, false, false, "mm"},
    {"desired.locus.height_mm", 0, 1000, false, false, "mm"},
    {"desired.locus.ground_fraction", 0, 1, true, true, ""},
    {"desired.locus.forward_mm", -1000, 1000, false, false, "mm"},
    {"desired.locus.outward_mm", -1000, 1000, false, false, "mm"},
    {"desired.locus.ground_below_shoulder_mm", -1000, 1000, false, false, "mm"},
    {"desired.locus.skew", -1, 1, false, false, ""},
    {"desired.locus.swing_end_speed_fraction", 0, 2, false, false, ""},
    {"desired.locus.liftoff_ramp_mm", 0, 50, false, false, "mm"},
    {"desired.locus.liftoff_ramp_ticks", 0, 100, false, false, "ticks"},
    {"desired.locus.body_pitch_deg", -45, 45, false, false, "deg"},
    {"track.t_step_ticks", 4, 1000, false, false, "ticks"},
    {"warmup_steps", 0, 1'000'000, false, false, ""},
    {"steps", 1, 1'000'000, false, false, ""},
};

}  // namespace

std::span<const NumericRange> NumericKeyRanges() { return kRanges; }

ExperimentConfig LoadExperimentConfig(const std::string& config_path,
                                      const std::vector<std::string>& overrides,
                                      const ConfigScope& scope) {
  try {
    return LoadExperimentConfigUnguarded(config_path, overrides, scope);
  } catch (const YAML::Exception& e) {
    // What the conversions above did not catch (e.g. a key that is not a scalar).
    Fail("'" + config_path + "' is malformed: " + e.what());
  }
}

// ---- Sweep files ----

namespace {

std::string FlowYaml(const YAML::Node& node) {
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

// One key=value per leaf of `node` under `prefix`: merging them one by one is a deep merge.
void FlattenInto(const YAML::Node& node, const std::string& prefix, std::vector<std::string>& out) {
  if (node.IsMap() && node.size() > 0) {
    for (const auto& item : node) {
      FlattenInto(item.second, prefix + "." + item.first.as<std::string>(), out);
    }
  } else {
    out.push_back(prefix + "=" + FlowYaml(node));
  }
}

// An integer written as one (no point, no exponent), for a sample range's type.
bool WrittenAsInteger(const YAML::Node& node) {
  if (!node.IsScalar()) return false;
  const std::string& text = node.Scalar();
  if (text.empty()) return false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (!(std::isdigit(static_cast<unsigned char>(c)) || (i == 0 && (c == '-' || c == '+')))) {
      return false;
    }
  }
  return true;
}

// Uniform in [0, 1) from 53 random bits: the same on every standard library (unlike
// std::uniform_real_distribution).
double Uniform01(std::mt19937_64& random) {
  return static_cast<double>(random() >> 11) * 0x1.0p-53;
}

SweepConfig LoadSweepConfigUnguarded(const std::string& path) {
  const std::string where = "sweep '" + path + "'";
  auto fail = [&](const std::string& what) -> void { throw InputError(where + ": " + what); };
  const YAML::Node file = LoadYamlFile(path, "sweep file");
  SweepConfig sweep;
  sweep.path = path;
  if (!file["base"] || !file["base"].IsScalar()) fail("base: expected the base config's file name");
  const fs::path base(file["base"].Scalar());
  sweep.base_path = (base.is_absolute() ? base : fs::path(path).parent_path() / base).string();
  if (!IsFile(sweep.base_path)) {
    fail("base: '" + sweep.base_path + "' does not exist");
  }
  const bool has_grid = file["grid"].IsDefined(), has_sample = file["sample"].IsDefined();
  if (has_grid == has_sample) fail("give either grid: or sample: (exactly one)");
  for (const auto& item : file) {
    const std::string key = item.first.as<std::string>();
    if (key == "base" || key == "grid" || key == "sample") continue;
    if (key == "extends") fail("extends: a sweep names its base config with base:");
    FlattenInto(item.second, key, sweep.overrides);
  }

  if (has_grid) {
    const YAML::Node grid = file["grid"];
    if (!grid.IsMap() || grid.size() == 0) fail("grid: expected a map of key: [values...]");
    std::vector<std::vector<std::string>> values;
    long points = 1;
    for (const auto& item : grid) {
      const std::string key = item.first.as<std::string>();
      if (!item.second.IsSequence() || item.second.size() == 0) {
        fail("grid." + key + ": expected a non-empty list of values");
      }
      sweep.keys.push_back(key);
      values.emplace_back();
      for (const YAML::Node& v : item.second) values.back().push_back(FlowYaml(v));
      points *= static_cast<long>(values.back().size());
      if (points > kMaxSweepPoints) {
        fail("grid: more than " + std::to_string(kMaxSweepPoints) + " points");
      }
    }
    // The cartesian product in odometer order: the last key varies fastest.
    for (long index = 0; index < points; ++index) {
      SweepPoint p{index, std::vector<std::string>(values.size())};
      long rest = index;
      for (size_t k = values.size(); k-- > 0;) {
        const long n = static_cast<long>(values[k].size());
        p.values[k] = values[k][rest % n];
        rest /= n;
      }
      sweep.points.push_back(std::move(p));
    }
    return sweep;
  }

  const YAML::Node sample = file["sample"];
  if (!sample.IsMap()) fail("sample: expected {count: K, seed: S, keys: {...}}");
  for (const auto& item : sample) {
    const std::string key = item.first.as<std::string>();
    if (key != "count" && key != "seed" && key != "keys") fail("unknown key 'sample." + key + "'");
  }
  long count = 0;
  long long seed = 0;
  try {
    count = sample["count"].as<long>();
  } catch (const YAML::Exception&) {
    fail("sample.count: expected a whole number of points");
  }
  if (count < 1 || count > kMaxSweepPoints) {
    fail("sample.count must be in [1, " + std::to_string(kMaxSweepPoints) + "], got " +
         std::to_string(count));
  }
  try {
    seed = sample["seed"].as<long long>();
  } catch (const YAML::Exception&) {
    fail("sample.seed: expected a non-negative integer");
  }
  if (seed < 0) fail("sample.seed must be non-negative");
  const YAML::Node keys = sample["keys"];
  if (!keys.IsMap() || keys.size() == 0) {
    fail("sample.keys: expected {<key>: {min: a, max: b[, step: s]}}");
  }
  struct Range {
    double min, max;
    bool integer;
    double step = 0.0;  // > 0: only min + k step, k = 0..steps
    long long steps = 0;
  };
  std::vector<Range> ranges;
  for (const auto& item : keys) {
    const std::string key = item.first.as<std::string>();
    const std::string name = "sample.keys." + key;
    const YAML::Node r = item.second;
    const bool stepped = r.IsMap() && r["step"];
    if (!r.IsMap() || r.size() != (stepped ? 3U : 2U) || !r["min"] || !r["max"]) {
      fail(name + ": expected {min: a, max: b[, step: s]}");
    }
    Range range{};
    try {
      range = {r["min"].as<double>(), r["max"].as<double>(),
               WrittenAsInteger(r["min"]) && WrittenAsInteger(r["max"])};
      if (stepped) {
        range.step = r["step"].as<double>();
        range.integer = WrittenAsInteger(r["min"]) && WrittenAsInteger(r["step"]);
      }
    } catch (const YAML::Exception&) {
      fail(name + ": min, max and step must be numbers");
    }
    if (!std::isfinite(range.min) || !std::isfinite(range.max) || range.min > range.max) {
      fail(name + ": expected finite min <= max");
    }
    if (stepped) {
      if (!(std::isfinite(range.step) && range.step > 0.0)) {
        fail(name + ".step must be positive and finite");
      }
      // max counts when it is min plus a whole number of steps up to rounding (0.1 .. 0.5 by
      // 0.1: (0.5 - 0.1) / 0.1 is 3.9999999999999996).
      const double steps = std::floor((range.max - range.min) / range.step + 1e-9);
      if (steps >= 0x1.0p53 ||
          (range.integer && std::max(std::fabs(range.min), std::fabs(range.max)) >= 0x1.0p53)) {
        fail(name + ": range too wide");
      }
      range.steps = static_cast<long long>(steps);
    } else if (range.integer && range.max - range.min >= 0x1.0p53) {
      fail(name + ": range too wide");
    }
    sweep.keys.push_back(key);
    ranges.push_back(range);
  }
  std::mt19937_64 random(static_cast<std::uint64_t>(seed));
  for (long index = 0; index < count; ++index) {
    SweepPoint p{index, {}};
    for (const Range& r : ranges) {
      const double u = Uniform01(random);
      if (r.step > 0.0) {
        const long long k = std::min(
            r.steps, static_cast<long long>(std::floor(u * static_cast<double>(r.steps + 1))));
        if (r.integer) {
          p.values.push_back(
              std::to_string(static_cast<long long>(r.min) + k * static_cast<long long>(r.step)));
        } else {
          // 15 significant digits: the lattice as written (0.1 + 2 * 0.1 is 0.3, not
          // 0.30000000000000004).
          char text[32];
          const auto end =
              std::to_chars(text, text + sizeof text, r.min + static_cast<double>(k) * r.step,
                            std::chars_format::general, 15);
          p.values.emplace_back(text, end.ptr);
        }
      } else if (r.integer) {
        const double n = r.max - r.min + 1.0;
        p.values.push_back(std::to_string(static_cast<long long>(r.min + std::floor(u * n))));
      } else {
        p.values.push_back(FormatDouble(r.min + u * (r.max - r.min)));
      }
    }
    sweep.points.push_back(std::move(p));
  }
  return sweep;
}

}  // namespace

std::vector<std::string> SweepConfig::PointOverrides(const SweepPoint& p) const {
  std::vector<std::string> out = overrides;
  for (size_t k = 0; k < keys.size(); ++k) out.push_back(keys[k] + "=" + p.values[k]);
  return out;
}

SweepConfig LoadSweepConfig(const std::string& path) {
  try {
    return LoadSweepConfigUnguarded(path);
  } catch (const YAML::Exception& e) {
    Fail("sweep '" + path + "' is malformed: " + e.what());
  }
}

}  // namespace leglab::experiments
