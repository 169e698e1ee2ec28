#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "leglab/core/format.h"

namespace leglab {

/// What a config key's declaration says besides its name, type and default (the default is the
/// value the visited struct holds): its range (numeric keys; a list key's range holds for each
/// element), unit and one line of description. Written with designated initializers in this
/// order, e.g. `{.min = 0, .max = 400, .unit = "ms", .description = "..."}`.
struct KeyDoc {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false;  ///< the range excludes min
  bool max_open = false;  ///< the range excludes max
  std::string_view unit;  ///< "ms", "deg", "deg/tick", ...; empty for a count or a ratio
  std::string_view description;
  /// A rule beyond the range: returns "" when `value` keeps it, else what a value must be
  /// ("a multiple of 8 ms"). nullptr: none.
  std::string_view (*rule)(double value) = nullptr;
};

/// `doc` with another description: a key that takes the values another declaration
/// allows (identify's search range of l takes a model's l), its range written once.
constexpr KeyDoc WithDescription(KeyDoc doc, std::string_view description) {
  doc.description = description;
  return doc;
}

/// `doc` with another range (`min_open`: min excluded): the same key where another user
/// takes other values.
constexpr KeyDoc WithRange(KeyDoc doc, double min, double max, bool min_open = false) {
  doc.min = min;
  doc.max = max;
  doc.min_open = min_open;
  doc.max_open = false;
  return doc;
}

/// The range of `doc` as people write it: "[0, 400] ms", "(0, 1]" (without the unit when
/// `with_unit` is false); empty for an unbounded one.
inline std::string RangeText(const KeyDoc& doc, bool with_unit = true) {
  if (doc.min == -std::numeric_limits<double>::infinity() &&
      doc.max == std::numeric_limits<double>::infinity()) {
    return "";
  }
  std::string text(doc.min_open ? "(" : "[");
  text += FormatNumber(doc.min, NumberStyle::kReadable);
  text += ", ";
  text += FormatNumber(doc.max, NumberStyle::kReadable);
  text += doc.max_open ? ")" : "]";
  if (with_unit && !doc.unit.empty()) {
    text += ' ';
    text += doc.unit;
  }
  return text;
}

/// What `value` must be to keep `doc` ("in [0, 400] ms", or the rule's text), or "" when it
/// does. NaN is outside every range.
inline std::string KeyValueProblem(double value, const KeyDoc& doc) {
  const bool above_min = doc.min_open ? value > doc.min : value >= doc.min;
  const bool below_max = doc.max_open ? value < doc.max : value <= doc.max;
  if (!(above_min && below_max)) return "in " + RangeText(doc);
  if (doc.rule != nullptr) return std::string(doc.rule(value));
  return "";
}

/// Visits the config keys of a struct: each struct that is configured declares its keys once,
/// in a function `void VisitKeys(KeyVisitor&, Struct&)` beside it, calling Key() once per key
/// (name, the field, its KeyDoc) and Section() for a nested map. The same declaration serves
/// every job: the YAML loader (reads, range-checks and names unknown keys), `--list-keys` and
/// docs/configuration.md (lists them with the struct's defaults), and tests. Checks that
/// involve several keys follow the keys in the same function and report through Fail(). (The
/// pattern of Drake's Serialize(Archive*) and ros2_controllers' parameter library.)
class KeyVisitor {
 public:
  virtual ~KeyVisitor() = default;

  virtual void Key(std::string_view name, int& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, double& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, bool& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, std::string& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, std::vector<double>& value, const KeyDoc& doc) = 0;
  virtual void Key(std::string_view name, std::vector<int>& value, const KeyDoc& doc) = 0;

  /// An enum key: `value` is one of `names`, the enumerators' names in their order (0, 1, ...).
  template <typename Enum, size_t N>
  requires std::is_enum_v<Enum>
  void Key(std::string_view name, Enum& value, const std::array<std::string_view, N>& names,
           const KeyDoc& doc) {
    int index = static_cast<int>(value);
    Choice(name, index, names, doc);
    value = static_cast<Enum>(index);
  }

  /// A key whose value is not a scalar, list of scalars or enum (a list of maps, a list of
  /// modes): declared here to be listed and accepted, read by its owner from the YAML itself.
  /// `type` and `default_text` are as the key reference shows them.
  virtual void Structured(std::string_view name, std::string_view type,
                          std::string_view default_text, const KeyDoc& doc) = 0;

  /// The keys `body` visits live in the map `name` (nested in the current one).
  template <typename Body>
  void Section(std::string_view name, Body&& body) {
    Enter(name);
    std::forward<Body>(body)();
    Leave();
  }

  /// Whether the config gives key `name` of the current map (false when only listing).
  virtual bool Given(std::string_view name) const = 0;

  /// Bad input: "<key as the user wrote it> must be <expectation>".
  [[noreturn]] virtual void Fail(std::string_view name, const std::string& expectation) = 0;

  /// `name` as the user writes it: the current sections' names, dotted, then `name`.
  virtual std::string FullName(std::string_view name) const = 0;

 protected:
  virtual void Choice(std::string_view name, int& index, std::span<const std::string_view> names,
                      const KeyDoc& doc) = 0;
  virtual void Enter(std::string_view name) = 0;
  virtual void Leave() = 0;
};

/// A KeyVisitor that names keys by the sections it is in: FullName(name) is the sections'
/// names, dotted, then `name` ("servo.delay_ms"), after a fixed `prefix`.
class SectionedKeyVisitor : public KeyVisitor {
 public:
  std::string FullName(std::string_view name) const override { return prefix_ + std::string(name); }

 protected:
  explicit SectionedKeyVisitor(std::string prefix = "") : prefix_(std::move(prefix)) {}
  void Enter(std::string_view name) override {
    sections_.push_back(prefix_.size());
    prefix_ += std::string(name) + ".";
  }
  void Leave() override {
    prefix_.resize(sections_.back());
    sections_.pop_back();
  }

 private:
  std::string prefix_;
  std::vector<size_t> sections_;  // prefix_'s length before each section entered
};

/// One row of a key reference: what --list-keys prints and docs/configuration.md holds.
struct KeyRow {
  std::string key;           ///< dotted, as the user writes it: "servo.delay_ms"
  std::string type;          ///< "number", "integer", "bool", "string", "list of numbers", ...
  std::string default_text;  ///< the declaring struct's default
  std::string range;         ///< "[0, 400]" (numeric), the names of an enum's values, or ""
  std::string unit;
  std::string description;
  KeyDoc doc;  ///< the declaration itself (its range, unit and rule)
};

/// Lists every key a declaration visits, with the visited struct's values as the defaults.
class KeyLister final : public SectionedKeyVisitor {
 public:
  /// The keys listed so far, in declaration order.
  const std::vector<KeyRow>& rows() const { return rows_; }

  void Key(std::string_view name, int& value, const KeyDoc& doc) override {
    Add(name, "integer", FormatNumber(value, NumberStyle::kReadable), doc);
  }
  void Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) override {
    Add(name, "integer", std::to_string(value), doc);
  }
  void Key(std::string_view name, double& value, const KeyDoc& doc) override {
    Add(name, "number", FormatNumber(value, NumberStyle::kReadable), doc);
  }
  void Key(std::string_view name, bool& value, const KeyDoc& doc) override {
    Add(name, "bool", value ? "true" : "false", doc);
  }
  void Key(std::string_view name, std::string& value, const KeyDoc& doc) override {
    Add(name, "string", value.empty() ? "(none)" : value, doc);
  }
  void Key(std::string_view name, std::vector<double>& value, const KeyDoc& doc) override {
    Add(name, "list of numbers", ListText(value), doc);
  }
  void Key(std::string_view name, std::vector<int>& value, const KeyDoc& doc) override {
    Add(name, "list of integers", ListText(value), doc);
  }
  void Structured(std::string_view name, std::string_view type, std::string_view default_text,
                  const KeyDoc& doc) override {
    Add(name, std::string(type), std::string(default_text), doc);
  }
  bool Given(std::string_view /*name*/) const override { return false; }
  [[noreturn]] void Fail(std::string_view name, const std::string& expectation) override {
    // The declarations' own defaults break a rule: a bug of the declaration, not bad input.
    throw std::logic_error("the default of " + FullName(name) + " is not " + expectation);
  }

 protected:
  void Choice(std::string_view name, int& index, std::span<const std::string_view> names,
              const KeyDoc& doc) override {
    std::string choices;
    for (std::string_view n : names) choices += (choices.empty() ? "" : ", ") + std::string(n);
    Add(name, "enum", std::string(names[static_cast<size_t>(index)]), doc);
    rows_.back().range = choices;
  }

 private:
  template <typename T>
  static std::string ListText(const std::vector<T>& values) {
    std::string text = "[";
    for (const T& v : values) {
      text += (text.size() > 1 ? ", " : "") + FormatNumber(v, NumberStyle::kReadable);
    }
    return text + "]";
  }
  void Add(std::string_view name, std::string type, std::string default_text, const KeyDoc& doc) {
    rows_.push_back({FullName(name), std::move(type), std::move(default_text),
                     RangeText(doc, /*with_unit=*/false), std::string(doc.unit),
                     std::string(doc.description), doc});
  }

  std::vector<KeyRow> rows_;
};

/// A KeyVisitor that sees only a declaration's numeric keys (int, unsigned, double): every other
/// key is passed over, and a rule of several keys that fails throws std::invalid_argument
/// "<key> must be <expectation>". What KeyValueLister and KeyAssigner are built on.
class NumericKeyVisitor : public SectionedKeyVisitor {
 public:
  using KeyVisitor::Key;
  void Key(std::string_view, bool&, const KeyDoc&) override {}
  void Key(std::string_view, std::string&, const KeyDoc&) override {}
  void Key(std::string_view, std::vector<double>&, const KeyDoc&) override {}
  void Key(std::string_view, std::vector<int>&, const KeyDoc&) override {}
  void Structured(std::string_view, std::string_view, std::string_view, const KeyDoc&) override {}
  bool Given(std::string_view /*name*/) const override { return false; }
  [[noreturn]] void Fail(std::string_view name, const std::string& expectation) override {
    throw std::invalid_argument(FullName(name) + " must be " + expectation);
  }

 protected:
  void Choice(std::string_view, int&, std::span<const std::string_view>, const KeyDoc&) override {}
};

/// One numeric key as a declaration visits it, with the visited struct's value (KeyValues).
struct KeyValue {
  std::string key;  ///< dotted, as the config writes it
  double value = 0.0;
  bool integer = false;  ///< an integer key (int or unsigned): write it without a fraction
  KeyDoc doc;
};

/// Lists the numeric keys a declaration visits with the visited struct's values: what writes a
/// struct's values under its keys' names (a JSON object, a dict) and reads them back.
class KeyValueLister final : public NumericKeyVisitor {
 public:
  using NumericKeyVisitor::Key;
  const std::vector<KeyValue>& values() const { return values_; }

  void Key(std::string_view name, int& value, const KeyDoc& doc) override {
    values_.push_back({FullName(name), static_cast<double>(value), true, doc});
  }
  void Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) override {
    values_.push_back({FullName(name), static_cast<double>(value), true, doc});
  }
  void Key(std::string_view name, double& value, const KeyDoc& doc) override {
    values_.push_back({FullName(name), value, false, doc});
  }

 private:
  std::vector<KeyValue> values_;
};

/// The numeric keys `visit(visitor, value)` declares, in order, with `value`'s values. Throws
/// std::invalid_argument as KeyChecker where `value` breaks a rule of several keys.
template <typename T, typename Visit>
std::vector<KeyValue> KeyValues(T value, Visit&& visit) {
  KeyValueLister lister;
  std::forward<Visit>(visit)(lister, value);
  return lister.values();
}

/// Checks the values a declaration visits as they are (a struct built in code, not loaded):
/// each against its range and rule, an enum against its names, and the declaration's checks
/// of several keys. Throws std::invalid_argument "<prefix><key> must be <expectation>, got
/// <value>" for the first that fails.
class KeyChecker final : public SectionedKeyVisitor {
 public:
  /// `prefix` names the struct's keys in messages: "ilc." gives "ilc.gain must be ...".
  explicit KeyChecker(std::string prefix = "") : SectionedKeyVisitor(std::move(prefix)) {}

  void Key(std::string_view name, int& value, const KeyDoc& doc) override {
    Check(name, value, doc);
  }
  void Key(std::string_view name, std::uint64_t& value, const KeyDoc& doc) override {
    Check(name, static_cast<double>(value), doc);
  }
  void Key(std::string_view name, double& value, const KeyDoc& doc) override {
    Check(name, value, doc);
  }
  void Key(std::string_view /*name*/, bool& /*value*/, const KeyDoc& /*doc*/) override {}
  void Key(std::string_view /*name*/, std::string& /*value*/, const KeyDoc& /*doc*/) override {}
  void Key(std::string_view name, std::vector<double>& value, const KeyDoc& doc) override {
    for (const double v : value) Check(name, v, doc);
  }
  void Key(std::string_view name, std::vector<int>& value, const KeyDoc& doc) override {
    for (const int v : value) Check(name, v, doc);
  }
  void Structured(std::string_view /*name*/, std::string_view /*type*/,
                  std::string_view /*default_text*/, const KeyDoc& /*doc*/) override {}
  bool Given(std::string_view /*name*/) const override { return false; }
  [[noreturn]] void Fail(std::string_view name, const std::string& expectation) override {
    throw std::invalid_argument(FullName(name) + " must be " + expectation);
  }

 protected:
  void Choice(std::string_view name, int& index, std::span<const std::string_view> names,
              const KeyDoc& /*doc*/) override {
    if (index < 0 || index >= static_cast<int>(names.size())) {
      throw std::invalid_argument(FullName(name) + " must be one of its names, got value " +
                                  std::to_string(index));
    }
  }

 private:
  void Check(std::string_view name, double value, const KeyDoc& doc) {
    if (const std::string problem = KeyValueProblem(value, doc); !problem.empty()) {
      Fail(name, problem + ", got " + FormatNumber(value, NumberStyle::kReadable));
    }
  }
};

/// Sets one numeric key of a struct, found through its declaration: a running plant's
/// settings named as the config names them ("servo.delay_ms"), unchecked beyond the type (the
/// owner validates the result). assigned() tells whether the declaration has such a key.
class KeyAssigner final : public NumericKeyVisitor {
 public:
  using NumericKeyVisitor::Key;
  /// `name` is dotted from the visited struct's own keys, `value` in the key's unit.
  KeyAssigner(std::string name, double value) : target_(std::move(name)), value_(value) {}
  bool assigned() const { return assigned_; }

  void Key(std::string_view name, int& value, const KeyDoc& /*doc*/) override {
    if (Matches(name)) value = static_cast<int>(Whole(name));
  }
  void Key(std::string_view name, std::uint64_t& value, const KeyDoc& /*doc*/) override {
    if (Matches(name)) value = static_cast<std::uint64_t>(Whole(name));
  }
  void Key(std::string_view name, double& value, const KeyDoc& /*doc*/) override {
    if (Matches(name)) value = value_;
  }

 private:
  bool Matches(std::string_view name) {
    if (FullName(name) != target_) return false;
    assigned_ = true;
    return true;
  }
  // The value of an integer key: a whole number within an int's range.
  double Whole(std::string_view name) {
    if (!(std::isfinite(value_) && value_ == std::round(value_) && std::abs(value_) <= 2e9)) {
      Fail(name, "a whole number, got " + FormatNumber(value_, NumberStyle::kReadable));
    }
    return value_;
  }
  std::string target_;
  double value_;
  bool assigned_ = false;
};

/// KeyChecker over `value`'s declaration `visit(visitor, value)`; throws as KeyChecker.
template <typename T, typename Visit>
void CheckKeys(std::string prefix, T value, Visit&& visit) {
  KeyChecker checker(std::move(prefix));
  std::forward<Visit>(visit)(checker, value);
}

/// What CheckKeys would throw for `value`, or "" when it keeps its declaration: a
/// precondition checked through the declaration, for a caller that reports it its own way.
template <typename T, typename Visit>
std::string KeysProblem(T value, Visit&& visit, std::string prefix = "") {
  try {
    CheckKeys(std::move(prefix), std::move(value), std::forward<Visit>(visit));
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

/// The keys `visit(visitor, value)` declares, with `value`'s fields as the defaults.
template <typename T, typename Visit>
std::vector<KeyRow> ListKeys(T value, Visit&& visit) {
  KeyLister lister;
  std::forward<Visit>(visit)(lister, value);
  return lister.rows();
}

}  // namespace leglab
