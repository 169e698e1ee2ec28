#pragma once

// Contexts and option readers for the controller tests.
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

#include "leglab/controller/registry.h"
#include "leglab/core/units.h"
#include "leglab/model/paper.h"

namespace leglab::testing {

/// The ERS-210A's software limits (../shared/ers210a.md), rad.
inline std::array<JointLimits, kLegJoints> Ers210aLimits() {
  return {{{DegToRad(-117.0), DegToRad(117.0)},
           {DegToRad(-11.0), DegToRad(89.0)},
           {DegToRad(-27.0), DegToRad(147.0)}}};
}

/// A smooth cycle within the limits, slower than v_max on every joint.
inline DesiredCycle Walkish(int period = 88) {
  DesiredCycle d(period);
  for (int t = 0; t < period; ++t) {
    const double phase = 2.0 * std::numbers::pi * t / period;
    d[t] = {10.0 + 30.0 * std::sin(phase), 15.0 + 8.0 * std::cos(phase),
            60.0 + 25.0 * std::sin(phase + 1.0)};
  }
  return d;
}

/// A context with the paper's model on every joint and 8 segments.
inline ControllerContext PaperContext(const DesiredCycle& desired) {
  const std::array<JointModelParams, kLegJoints> models = {paper::kTable1, paper::kTable1,
                                                           paper::kTable1};
  return MakeControllerContext(desired, models, Ers210aLimits(), 8);
}

/// The error a test reader throws: the key and what it must be.
struct OptionError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Options from a map of key -> text (a dotted key for a nested section's, as
/// "initial_model.lag_ticks"); every key visited is remembered. Values are range-checked as the
/// loader checks them (KeyValueProblem), so a test sees the declaration's rules.
class MapOptions final : public SectionedKeyVisitor {
 public:
  explicit MapOptions(std::map<std::string, std::string> values = {})
      : values_(std::move(values)) {}
  void Key(std::string_view key, int& value, const KeyDoc& doc) override {
    if (const std::string* text = Find(key)) value = std::stoi(*text);
    Check(key, value, doc);
  }
  void Key(std::string_view key, std::uint64_t& value, const KeyDoc& doc) override {
    if (const std::string* text = Find(key)) value = std::stoull(*text);
    Check(key, static_cast<double>(value), doc);
  }
  void Key(std::string_view key, double& value, const KeyDoc& doc) override {
    if (const std::string* text = Find(key)) value = std::stod(*text);
    Check(key, value, doc);
  }
  void Key(std::string_view key, bool& value, const KeyDoc& /*doc*/) override {
    if (const std::string* text = Find(key)) value = *text == "true";
  }
  void Key(std::string_view key, std::string& value, const KeyDoc& /*doc*/) override {
    if (const std::string* text = Find(key)) value = *text;
  }
  void Key(std::string_view key, std::vector<double>& /*value*/, const KeyDoc& /*doc*/) override {
    Find(key);
  }
  void Key(std::string_view key, std::vector<int>& /*value*/, const KeyDoc& /*doc*/) override {
    Find(key);
  }
  void Structured(std::string_view key, std::string_view /*type*/,
                  std::string_view /*default_text*/, const KeyDoc& /*doc*/) override {
    Find(key);
  }
  bool Given(std::string_view key) const override { return values_.count(FullName(key)) > 0; }
  [[noreturn]] void Fail(std::string_view key, const std::string& expectation) override {
    throw OptionError("controller." + FullName(key) + " must be " + expectation);
  }
  const std::map<std::string, int>& read_keys() const { return read_; }

 protected:
  void Choice(std::string_view key, int& index, std::span<const std::string_view> names,
              const KeyDoc& /*doc*/) override {
    const std::string* text = Find(key);
    if (text == nullptr) return;
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == *text) {
        index = static_cast<int>(i);
        return;
      }
    }
    Fail(key, "one of its names, got '" + *text + "'");
  }

 private:
  void Check(std::string_view key, double value, const KeyDoc& doc) {
    if (const std::string problem = KeyValueProblem(value, doc); !problem.empty()) {
      Fail(key, problem);
    }
  }
  const std::string* Find(std::string_view key) {
    const std::string name = FullName(key);
    ++read_[name];
    const auto it = values_.find(name);
    return it == values_.end() ? nullptr : &it->second;
  }
  std::map<std::string, std::string> values_;
  std::map<std::string, int> read_;
};

/// Mode `name` with its default options.
inline ControllerSpec SpecOf(std::string_view name,
                             std::map<std::string, std::string> options = {}) {
  MapOptions reader(std::move(options));
  return ReadControllerSpec(name, reader);
}

}  // namespace leglab::testing
