// Sweep files (`sweep --config`): their keys, declared for --list-keys, and their loader.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "leglab/app/output.h"
#include "leglab/app/yaml_config.h"
#include "leglab/experiments/config.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

// The ranges of a sample's count and seed and of a sampled key's step, which the listing and
// the loader share.
constexpr KeyDoc kCountDoc{
    .min = 1, .max = static_cast<double>(kMaxSweepPoints), .description = "points drawn at random"};
constexpr KeyDoc kSeedDoc{
    .min = 0,
    .max = 9.2e18,
    .description = "seed of the draw: the same seed gives the same points on any machine"};
constexpr KeyDoc kStepDoc{
    .min = 0, .max = std::numeric_limits<double>::infinity(), .min_open = true, .max_open = true};

// The sweep file's own keys; every other key is an experiment key merged over the base.
void VisitSweepKeys(KeyVisitor& v) {
  std::string base;
  v.Key("base", base,
        {.description = "the experiment config every point runs (required), relative to the "
                        "sweep file"});
  v.Structured("grid", "map of key: [values]", "(none)",
               {.description = "the cartesian product of each key's values, the first key "
                               "varying slowest (give grid or sample)"});
  v.Section("sample", [&] {
    int count = 1;
    v.Key("count", count, kCountDoc);
    std::uint64_t seed = 0;
    v.Key("seed", seed, kSeedDoc);
    v.Structured("keys", "map of key: {min, max[, step]}", "(none)",
                 {.description = "each key uniform in [min, max] (integers when min and max are "
                                 "written so); with step, only min + k step"});
  });
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

// Throws InputError "sweep '<path>': <what>".
class SweepError {
 public:
  explicit SweepError(const std::string& path) : where_("sweep '" + path + "'") {}
  [[noreturn]] void operator()(const std::string& what) const {
    throw InputError(where_ + ": " + what);
  }

 private:
  std::string where_;
};

// `grid:`'s points: the cartesian product in odometer order, the last key varying fastest.
void LoadGrid(const YAML::Node& grid, const SweepError& fail, SweepConfig& sweep) {
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
}

// One sampled key's range.
struct SampleRange {
  double min, max;
  bool integer;
  double step = 0.0;  // > 0: only min + k step, k = 0..steps
  long long steps = 0;
};

// `sample.keys.<key>`: {min: a, max: b[, step: s]}.
SampleRange ReadSampleRange(const YAML::Node& r, const std::string& name, const SweepError& fail) {
  const bool stepped = r.IsMap() && r["step"];
  if (!r.IsMap() || r.size() != (stepped ? 3U : 2U) || !r["min"] || !r["max"]) {
    fail(name + ": expected {min: a, max: b[, step: s]}");
  }
  SampleRange range{};
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
    if (const std::string problem = KeyValueProblem(range.step, kStepDoc); !problem.empty()) {
      fail(name + ".step must be " + problem + ", got " +
           FormatNumber(range.step, NumberStyle::kReadable));
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
  return range;
}

// A value of `r` from one uniform draw `u` in [0, 1), as YAML text.
std::string SampleValue(const SampleRange& r, double u) {
  if (r.step > 0.0) {
    const long long k =
        std::min(r.steps, static_cast<long long>(std::floor(u * static_cast<double>(r.steps + 1))));
    if (r.integer) {
      return std::to_string(static_cast<long long>(r.min) + k * static_cast<long long>(r.step));
    }
    // The lattice as written: 0.1 + 2 * 0.1 is 0.3, not 0.30000000000000004.
    return FormatNumber(r.min + static_cast<double>(k) * r.step, 15);
  }
  if (r.integer) {
    const double n = r.max - r.min + 1.0;
    return std::to_string(static_cast<long long>(r.min + std::floor(u * n)));
  }
  return FormatNumber(r.min + u * (r.max - r.min));
}

// `sample:`'s points: count draws, each key in turn, from one seeded generator.
void LoadSample(const YAML::Node& sample, const SweepError& fail, SweepConfig& sweep) {
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
  if (const std::string problem = KeyValueProblem(static_cast<double>(count), kCountDoc);
      !problem.empty()) {
    fail("sample.count must be " + problem + ", got " + std::to_string(count));
  }
  try {
    seed = sample["seed"].as<long long>();
  } catch (const YAML::Exception&) {
    fail("sample.seed: expected a non-negative integer");
  }
  if (const std::string problem = KeyValueProblem(static_cast<double>(seed), kSeedDoc);
      !problem.empty()) {
    fail("sample.seed must be " + problem + ", got " + std::to_string(seed));
  }
  const YAML::Node keys = sample["keys"];
  if (!keys.IsMap() || keys.size() == 0) {
    fail("sample.keys: expected {<key>: {min: a, max: b[, step: s]}}");
  }
  std::vector<SampleRange> ranges;
  for (const auto& item : keys) {
    const std::string key = item.first.as<std::string>();
    ranges.push_back(ReadSampleRange(item.second, "sample.keys." + key, fail));
    sweep.keys.push_back(key);
  }
  std::mt19937_64 random(static_cast<std::uint64_t>(seed));
  for (long index = 0; index < count; ++index) {
    SweepPoint p{index, {}};
    for (const SampleRange& r : ranges) p.values.push_back(SampleValue(r, Uniform01(random)));
    sweep.points.push_back(std::move(p));
  }
}

SweepConfig LoadSweepConfigUnguarded(const std::string& path) {
  const SweepError fail(path);
  const YAML::Node file = LoadYamlFile(path, "sweep file");
  SweepConfig sweep;
  sweep.path = path;
  if (!file["base"] || !file["base"].IsScalar()) fail("base: expected the base config's file name");
  const fs::path base(file["base"].Scalar());
  sweep.base_path = (base.is_absolute() ? base : fs::path(path).parent_path() / base).string();
  if (!IsRegularFile(sweep.base_path)) fail("base: '" + sweep.base_path + "' does not exist");
  const bool has_grid = file["grid"].IsDefined(), has_sample = file["sample"].IsDefined();
  if (has_grid == has_sample) fail("give either grid: or sample: (exactly one)");
  for (const auto& item : file) {
    const std::string key = item.first.as<std::string>();
    if (key == "base" || key == "grid" || key == "sample") continue;
    if (key == "extends") fail("extends: a sweep names its base config with base:");
    FlattenInto(item.second, key, sweep.overrides);
  }
  if (has_grid) {
    LoadGrid(file["grid"], fail, sweep);
  } else {
    LoadSample(file["sample"], fail, sweep);
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
    FailConfig("sweep '" + path + "' is malformed: " + e.what());
  }
}

std::vector<KeyRow> SweepKeys() {
  KeyLister lister;
  VisitSweepKeys(lister);
  std::vector<KeyRow> rows = lister.rows();
  // A sweep file has no defaults: base is required, and so are a sample's count, seed and keys.
  for (KeyRow& row : rows) {
    if (row.key != "grid") row.default_text = "(required)";
  }
  return rows;
}

}  // namespace leglab::experiments
