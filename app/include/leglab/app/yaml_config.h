#pragma once

// YAML reading for the config loaders (the experiments' config, the real servo's logs
// section). Knows no config key: the keys are declared beside the structs that own them and
// read through YamlKeyReader.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/app/input_error.h"
#include "leglab/core/config_keys.h"

namespace leglab {

/// The largest config file, sweep file or URDF read, bytes (4 MiB: the shipped ones are a few
/// KiB); a larger one is refused before it is read.
inline constexpr std::uintmax_t kMaxConfigFileBytes = std::uintmax_t{4} << 20;

/// Throws InputError "config: <what>".
[[noreturn]] void FailConfig(const std::string& what);

/// Whether `path` names something, or a regular file. A path the file system cannot even look
/// up (a name too long, a component not a folder) does not exist: the user's input, never a
/// filesystem_error escaping as an internal error.
bool PathExists(const std::filesystem::path& path);
bool IsRegularFile(const std::filesystem::path& path);

/// What a key given as null or empty must be instead, for "<key> must be " messages.
extern const char* const kNullIsNoSetting;

/// `node` as one line of YAML flow text, as the user could write it.
std::string FlowYaml(const YAML::Node& node);

/// A map key as the user wrote it: its text, or its flow YAML when it is not a scalar.
std::string KeyText(const YAML::Node& key);

/// The YAML map in file `path` (an empty file is an empty map); `what` names it in messages
/// ("config file"). Throws InputError for a missing, malformed or non-map file, or a key given
/// twice in one of its maps.
YAML::Node LoadYamlFile(const std::filesystem::path& path, const std::string& what);

/// The file at `path` with the file its `extends:` key names (relative to it) merged beneath,
/// recursively (at most 8 levels); `extends` itself removed.
YAML::Node LoadWithBase(const std::filesystem::path& path, const std::string& what);

/// Deep copy of `over` onto `base`: maps merge key by key, anything else replaces.
void MergeInto(YAML::Node base, const YAML::Node& over);

/// Applies "a.b.c=value" (value in YAML syntax) to `root`, creating maps on the way.
void ApplyOverride(YAML::Node root, const std::string& assignment);

/// Throws InputError naming the first key given twice in one map of `node`, or a tree too
/// large or deep to be a config (an alias bomb or cycle).
void CheckNoDuplicateKeys(const YAML::Node& node, const std::string& where,
                          const std::string& prefix = "");

/// Reads the keys that declarations visit (KeyVisitor) from a YAML tree: each value given is
/// converted and checked against its declared range and rule, and a default that breaks its
/// range is reported too. Every key and section visited is remembered, so that Finish() names
/// the keys no declaration asked for. A section may be visited more than once (the modes that
/// keep their keys in `controller`).
class YamlKeyReader final : public KeyVisitor {
 public:
  explicit YamlKeyReader(const YAML::Node& root);

  void Key(std::string_view name, int& value, const KeyDoc& doc) override;
  void Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) override;
  void Key(std::string_view name, double& value, const KeyDoc& doc) override;
  void Key(std::string_view name, bool& value, const KeyDoc& doc) override;
  void Key(std::string_view name, std::string& value, const KeyDoc& doc) override;
  void Key(std::string_view name, std::vector<double>& value, const KeyDoc& doc) override;
  void Key(std::string_view name, std::vector<int>& value, const KeyDoc& doc) override;
  void Structured(std::string_view name, std::string_view type, std::string_view default_text,
                  const KeyDoc& doc) override;
  bool Given(std::string_view name) const override;
  [[noreturn]] void Fail(std::string_view name, const std::string& expectation) override;
  std::string FullName(std::string_view name) const override;

  /// The node of key `name` in the current map (undefined when absent), marked as read: the
  /// value of a Structured key. An explicit null (`key: null`, `key:`, `--set key=`) fails
  /// naming the key: it would otherwise run as the default and be recorded as `~`.
  YAML::Node Raw(std::string_view name);

  /// Throws UnknownKeyError "config: unknown key '<key>'" for the first key, in a map that was
  /// visited as a section (or the root), that no declaration visited.
  void Finish() const;

 protected:
  void Choice(std::string_view name, int& index, std::span<const std::string_view> names,
              const KeyDoc& doc) override;
  void Enter(std::string_view name) override;
  void Leave() override;

 private:
  // The value of `name` in the current map, marked as read (Raw); undefined when absent.
  YAML::Node Value(std::string_view name);
  void CheckValue(std::string_view name, double value, const KeyDoc& doc);
  // `child`, the value of key `name`, as a T; fails naming the key and the type expected.
  template <typename T>
  T As(const YAML::Node& child, std::string_view name) const;
  // An integer key's given value, range-checked; empty when absent.
  std::optional<long long> Integer(std::string_view name, const KeyDoc& doc);
  void CheckUnknown(const YAML::Node& map, const std::string& prefix) const;

  struct Level {
    YAML::Node node;  // the current map (undefined when the config has no such section)
    std::string prefix;
  };
  std::vector<Level> levels_;
  std::set<std::string> read_;      // full names of the keys and sections visited
  std::set<std::string> sections_;  // full names of the sections visited, with "" the root
};

}  // namespace leglab
