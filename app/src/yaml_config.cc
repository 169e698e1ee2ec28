#include "leglab/app/yaml_config.h"

#include <algorithm>

namespace leglab {

namespace fs = std::filesystem;

void FailConfig(const std::string& what) { throw InputError("config: " + what); }

bool PathExists(const fs::path& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool IsRegularFile(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string FlowYaml(const YAML::Node& node) {
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

std::string KeyText(const YAML::Node& key) { return key.IsScalar() ? key.Scalar() : FlowYaml(key); }

namespace {

// The value of `name` in `map`, or a fresh undefined-as-null node when `map` is not a map or has
// no such key (never yaml-cpp's invalid node, which throws when asked anything else).
YAML::Node ChildOf(const YAML::Node& map, std::string_view name) {
  if (!map.IsDefined() || !map.IsMap()) return YAML::Node();
  const YAML::Node child = map[std::string(name)];
  return child.IsDefined() ? child : YAML::Node();
}

// Whether `map` is a map holding key `name` with an explicit null (`key: null`, `key:`,
// `--set key=`), as opposed to not holding it.
bool HoldsNull(const YAML::Node& map, std::string_view name) {
  if (!map.IsDefined() || !map.IsMap()) return false;
  const YAML::Node child = map[std::string(name)];
  return child.IsDefined() && child.IsNull();
}

// `budget` and `depth` bound the walk: aliases may repeat a subtree exponentially often (an
// alias bomb) or make it a cycle, and no config of ours has 100000 nodes or 64 levels.
void CheckNoDuplicateKeys(const YAML::Node& node, const std::string& where,
                          const std::string& prefix, int& budget, int depth) {
  if (--budget < 0) {
    FailConfig(where + " is too large (over 100000 nodes, or aliases nested too deep)");
  }
  // An alias inside its own anchor makes the tree a cycle.
  if (depth > 64) {
    FailConfig(where + " nests deeper than 64 levels (an alias inside its own anchor?)");
  }
  if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& item : node) {
      const std::string key = prefix + KeyText(item.first);
      if (!seen.insert(key).second) FailConfig(where + ": key '" + key + "' is given twice");
      CheckNoDuplicateKeys(item.second, where, key + ".", budget, depth + 1);
    }
  } else if (node.IsSequence()) {
    for (const auto& element : node) {
      CheckNoDuplicateKeys(element, where, prefix, budget, depth + 1);
    }
  }
}

YAML::Node LoadWithBase(const fs::path& path, int depth, const std::string& what) {
  YAML::Node node = LoadYamlFile(path, depth == 0 ? what : "extended " + what);
  const YAML::Node base_name = node["extends"];
  if (!base_name) return node;
  if (depth >= 8) FailConfig("extends: more than 8 levels from '" + path.string() + "' (a cycle?)");
  std::string base;
  try {
    base = base_name.as<std::string>();
  } catch (const YAML::Exception&) {
    FailConfig("extends: expected a file name in '" + path.string() + "'");
  }
  YAML::Node merged = LoadWithBase(
      fs::path(base).is_absolute() ? fs::path(base) : path.parent_path() / base, depth + 1, what);
  node.remove("extends");
  MergeInto(merged, node);
  return merged;
}

// "a or b", "a, b or c".
std::string OneOf(std::span<const std::string_view> names) {
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i > 0) text += i + 1 == names.size() ? " or " : ", ";
    text += names[i];
  }
  return text;
}

template <typename T>
std::string TypeName() {
  if constexpr (std::is_same_v<T, bool>)
    return "true or false";
  else if constexpr (std::is_integral_v<T>)
    return "an integer";
  else if constexpr (std::is_floating_point_v<T>)
    return "a number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "a string";
  else if constexpr (std::is_same_v<T, std::vector<long long>>)
    return "a list of integers";
  else
    return "a list";
}

}  // namespace

void CheckNoDuplicateKeys(const YAML::Node& node, const std::string& where,
                          const std::string& prefix) {
  int budget = 100000;
  CheckNoDuplicateKeys(node, where, prefix, budget, 0);
}

void CheckFileSize(const std::string& path, std::uintmax_t limit_bytes, const std::string& what) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size <= limit_bytes) return;
  throw InputError(what + " '" + path + "' is " + std::to_string(size) + " bytes, over the " +
                   std::to_string(limit_bytes) + "-byte limit");
}

YAML::Node LoadYamlFile(const fs::path& path, const std::string& what) {
  if (!IsRegularFile(path)) {
    std::error_code ec;
    const bool folder = fs::is_directory(path, ec);
    FailConfig(what + " '" + path.string() + "' " +
               (folder ? "is a folder, not a file" : "does not exist"));
  }
  CheckFileSize(path.string(), kMaxConfigFileBytes, "config: " + what);
  try {
    YAML::Node node = YAML::LoadFile(path.string());
    if (node.IsNull()) return YAML::Node(YAML::NodeType::Map);
    if (!node.IsMap()) FailConfig(what + " '" + path.string() + "' is not a YAML map");
    CheckNoDuplicateKeys(node, what + " '" + path.string() + "'");
    return node;
  } catch (const YAML::Exception& e) {
    FailConfig(what + " '" + path.string() + "' is malformed: " + e.what());
  }
}

YAML::Node LoadWithBase(const fs::path& path, const std::string& what) {
  return LoadWithBase(path, 0, what);
}

void MergeInto(YAML::Node base,  // NOLINT(performance-unnecessary-value-param): a handle
               const YAML::Node& over) {
  for (const auto& item : over) {
    const std::string key = item.first.as<std::string>();
    if (item.second.IsMap() && base[key] && base[key].IsMap()) {
      MergeInto(base[key], item.second);
    } else {
      base[key] = YAML::Clone(item.second);
    }
  }
}

// A YAML::Node is a handle: taken by value, it still edits the caller's tree.
void ApplyOverride(YAML::Node root,  // NOLINT(performance-unnecessary-value-param)
                   const std::string& assignment) {
  const auto equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    FailConfig("--set '" + assignment + "' is not of the form key=value");
  }
  const std::string path = assignment.substr(0, equals);
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(equals + 1));
  } catch (const YAML::Exception& e) {
    FailConfig("--set " + path + ": the value is not valid YAML: " + e.what());
  }
  CheckNoDuplicateKeys(value, "--set " + path, path + ".");
  std::vector<std::string> keys;
  for (size_t start = 0;;) {
    const size_t dot = path.find('.', start);
    keys.push_back(path.substr(start, dot - start));
    if (keys.back().empty()) FailConfig("--set '" + assignment + "' has an empty key");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  // yaml-cpp nodes are handles: walk with fresh handles, never reassign one.
  std::vector<YAML::Node> chain{root};
  for (size_t i = 0; i + 1 < keys.size(); ++i) {
    YAML::Node next = chain.back()[keys[i]];
    if (next.IsDefined() && !next.IsNull() && !next.IsMap()) {
      FailConfig("--set " + path + ": '" + keys[i] + "' is not a map");
    }
    if (!next.IsDefined() || next.IsNull()) chain.back()[keys[i]] = YAML::Node(YAML::NodeType::Map);
    chain.push_back(chain.back()[keys[i]]);
  }
  chain.back()[keys.back()] = value;
}

// ---- YamlKeyReader ----

const char* const kNullIsNoSetting =
    "a value, not null or empty (leave the key out for its default)";

template <typename T>
T YamlKeyReader::As(const YAML::Node& child, std::string_view name) const {
  try {
    return child.as<T>();
  } catch (const YAML::Exception&) {
    FailConfig(FullName(name) + ": expected " + TypeName<T>() + ", got '" + FlowYaml(child) + "'");
  }
}

YamlKeyReader::YamlKeyReader(const YAML::Node& root) {
  if (root.IsDefined() && !root.IsNull() && !root.IsMap()) FailConfig("the config must be a map");
  levels_.push_back({root, ""});
  sections_.insert("");
}

std::string YamlKeyReader::FullName(std::string_view name) const {
  return levels_.back().prefix + std::string(name);
}

void YamlKeyReader::Fail(std::string_view name, const std::string& expectation) {
  FailConfig(FullName(name) + " must be " + expectation);
}

bool YamlKeyReader::Given(std::string_view name) const {
  return !ChildOf(levels_.back().node, name).IsNull();
}

YAML::Node YamlKeyReader::Raw(std::string_view name) {
  // `key: null`, `key:` or `--set key=` would otherwise run with the default and record `~`.
  if (HoldsNull(levels_.back().node, name)) Fail(name, kNullIsNoSetting);
  read_.insert(FullName(name));
  return ChildOf(levels_.back().node, name);
}

YAML::Node YamlKeyReader::Value(std::string_view name) {
  YAML::Node child = Raw(name);
  return child.IsNull() ? YAML::Node(YAML::NodeType::Undefined) : child;
}

void YamlKeyReader::CheckValue(std::string_view name, double value, const KeyDoc& doc) {
  // Every numeric key has a range: one declared without is a bug of ours, not bad input.
  if (!(std::isfinite(doc.min) && std::isfinite(doc.max))) {
    throw std::logic_error("config key '" + FullName(name) + "' is declared without a range");
  }
  if (const std::string problem = KeyValueProblem(value, doc); !problem.empty()) {
    Fail(name, problem + ", got " + FormatNumber(value, NumberStyle::kReadable));
  }
}

std::optional<long long> YamlKeyReader::Integer(std::string_view name, const KeyDoc& doc) {
  const YAML::Node child = Value(name);
  if (!child) return std::nullopt;
  // Read wide, so that a value beyond the field's type is reported as out of range, as the
  // integer written (a double would round 2^63 - 1 up to 9223372036854775808).
  const auto wide = As<long long>(child, name);
  if (const std::string problem = KeyValueProblem(static_cast<double>(wide), doc);
      !problem.empty()) {
    Fail(name, problem + ", got " + std::to_string(wide));
  }
  return wide;
}

void YamlKeyReader::Key(std::string_view name, int& value, const KeyDoc& doc) {
  if (const auto wide = Integer(name, doc)) value = static_cast<int>(*wide);
  CheckValue(name, value, doc);
}

void YamlKeyReader::Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) {
  if (const auto wide = Integer(name, doc)) {
    if (*wide < 0) Fail(name, "a non-negative integer");
    value = static_cast<std::uint64_t>(*wide);
  }
  CheckValue(name, static_cast<double>(value), doc);
}

void YamlKeyReader::Key(std::string_view name, double& value, const KeyDoc& doc) {
  if (const YAML::Node child = Value(name)) value = As<double>(child, name);
  CheckValue(name, value, doc);
}

void YamlKeyReader::Key(std::string_view name, bool& value, const KeyDoc& /*doc*/) {
  if (const YAML::Node child = Value(name)) value = As<bool>(child, name);
}

void YamlKeyReader::Key(std::string_view name, std::string& value, const KeyDoc& /*doc*/) {
  if (const YAML::Node child = Value(name)) value = As<std::string>(child, name);
}

void YamlKeyReader::Key(std::string_view name, std::vector<double>& value, const KeyDoc& doc) {
  if (const YAML::Node child = Value(name)) value = As<std::vector<double>>(child, name);
  for (const double v : value) CheckValue(name, v, doc);
}

void YamlKeyReader::Key(std::string_view name, std::vector<int>& value, const KeyDoc& doc) {
  if (const YAML::Node child = Value(name)) {
    // Read wide, so that a value beyond int's range is reported as out of range.
    const auto wide = As<std::vector<long long>>(child, name);
    value.clear();
    for (const long long v : wide) {
      CheckValue(name, static_cast<double>(v), doc);
      value.push_back(static_cast<int>(v));
    }
  }
  for (const int v : value) CheckValue(name, v, doc);
}

void YamlKeyReader::Structured(std::string_view name, std::string_view /*type*/,
                               std::string_view /*default_text*/, const KeyDoc& /*doc*/) {
  read_.insert(FullName(name));
}

void YamlKeyReader::Choice(std::string_view name, int& index,
                           std::span<const std::string_view> names, const KeyDoc& /*doc*/) {
  const YAML::Node child = Value(name);
  if (!child) return;
  std::string text;
  try {
    text = child.as<std::string>();
  } catch (const YAML::Exception&) {
    Fail(name, OneOf(names) + ", got '" + FlowYaml(child) + "'");
  }
  // YAML's other spellings of a boolean (yes, on, True, ...) name the value true or false.
  bool flag = false;
  if (YAML::convert<bool>::decode(child, flag)) text = flag ? "true" : "false";
  const auto it = std::find(names.begin(), names.end(), text);
  if (it == names.end()) Fail(name, OneOf(names) + ", got '" + text + "'");
  index = static_cast<int>(it - names.begin());
}

void YamlKeyReader::Enter(std::string_view name) {
  const std::string full = FullName(name);
  read_.insert(full);
  sections_.insert(full);
  YAML::Node child = ChildOf(levels_.back().node, name);
  if (!child.IsNull() && !child.IsMap()) FailConfig(full + " must be a map");
  levels_.push_back({child, full + "."});
}

void YamlKeyReader::Leave() { levels_.pop_back(); }

void YamlKeyReader::CheckUnknown(const YAML::Node& map, const std::string& prefix) const {
  if (!map.IsMap()) return;
  for (const auto& item : map) {
    const std::string key = prefix + KeyText(item.first);
    if (!read_.count(key)) throw UnknownKeyError("config: unknown key '" + key + "'");
    if (sections_.count(key)) CheckUnknown(item.second, key + ".");
  }
}

void YamlKeyReader::Finish() const { CheckUnknown(levels_.front().node, ""); }

}  // namespace leglab
