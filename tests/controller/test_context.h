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

/// Options from a map of key -> text; every key read is remembered.
class MapOptions final : public OptionReader {
 public:
  explicit MapOptions(std::map<std::string, std::string> values = {})
      : values_(std::move(values)) {}
  void Read(std::string_view key, int& value) override {
    if (const std::string* text = Find(key)) value = std::stoi(*text);
  }
  void Read(std::string_view key, double& value) override {
    if (const std::string* text = Find(key)) value = std::stod(*text);
  }
  void Read(std::string_view key, bool& value) override {
    if (const std::string* text = Find(key)) value = *text == "true";
  }
  void Read(std::string_view key, std::string& value) override {
    if (const std::string* text = Find(key)) value = *text;
  }
  [[noreturn]] void Fail(std::string_view key, const std::string& expectation) override {
    throw OptionError("controller." + std::string(key) + " must be " + expectation);
  }
  const std::map<std::string, int>& read_keys() const { return read_; }

 private:
  const std::string* Find(std::string_view key) {
    ++read_[std::string(key)];
    const auto it = values_.find(std::string(key));
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
