#include "leglab/servo/servo_log_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string_view>
#include <utility>
#include <vector>

#include "leglab/app/input_error.h"
#include "leglab/core/format.h"
#include "leglab/core/units.h"
#include "leglab/servo/servo_plan.h"

namespace leglab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Echoed cells and fields are cut to this many characters, a path to kShownPathChars (its
// end kept, where the file's name is), so that a message stays one short line.
constexpr size_t kShownCellChars = 40;
constexpr size_t kShownPathChars = 120;

constexpr const auto& kCsvColumns = kServoLogColumnList;

// The CSV log's header of its first `columns` columns (3, or 4 with torque_enabled).
std::string CsvHeader(size_t columns) {
  std::string header;
  for (size_t c = 0; c < columns; ++c) {
    if (c > 0) header += ',';
    header += kCsvColumns[c];
  }
  return header;
}

// The code point of the UTF-8 sequence at text[i] and its length in bytes (0: not UTF-8).
std::pair<char32_t, size_t> DecodeUtf8(std::string_view text, size_t i) {
  const auto lead = static_cast<unsigned char>(text[i]);
  const size_t bytes = lead >= 0xF8   ? 0
                       : lead >= 0xF0 ? 4
                       : lead >= 0xE0 ? 3
                       : lead >= 0xC0 ? 2
                                      : 0;
  if (bytes == 0 || i + bytes > text.size()) return {0, 0};
  auto code = static_cast<char32_t>(lead & (0x7F >> bytes));
  for (size_t k = 1; k < bytes; ++k) {
    const auto c = static_cast<unsigned char>(text[i + k]);
    if ((c & 0xC0) != 0x80) return {0, 0};
    code = (code << 6) | (c & 0x3F);
  }
  return {code, bytes};
}

// The character or UTF-8 sequence at text[i] as it is shown, and the bytes it takes: printable
// ASCII as itself, anything else escaped (\r, \t, \n, \xNN, \uXXXX).
std::pair<std::string, size_t> ShownChar(std::string_view text, size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  if (c >= 0x20 && c < 0x7F) return {std::string(1, text[i]), 1};
  if (c == '\r') return {"\\r", 1};
  if (c == '\t') return {"\\t", 1};
  if (c == '\n') return {"\\n", 1};
  std::array<char, 16> buffer{};
  const auto [code, bytes] = c >= 0x80 ? DecodeUtf8(text, i) : std::pair<char32_t, size_t>{0, 0};
  if (bytes == 0) {
    std::snprintf(buffer.data(), buffer.size(), "\\x%02x", static_cast<unsigned>(c));
    return {buffer.data(), 1};
  }
  std::snprintf(buffer.data(), buffer.size(), "\\u%04x", static_cast<unsigned>(code));
  return {buffer.data(), bytes};
}

// `text` on one line, invisible characters escaped, cut to about `max_chars` ("..." added).
std::string Shown(std::string_view text, size_t max_chars = kShownCellChars) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    auto [shown, bytes] = ShownChar(text, i);
    if (out.size() + shown.size() > max_chars) return out + "...";
    out += shown;
    i += bytes;
  }
  return out;
}

std::string ShownPath(std::string_view path) {
  if (path.size() <= kShownPathChars) return Shown(path, 2 * kShownPathChars);
  return "..." + Shown(path.substr(path.size() - kShownPathChars), 2 * kShownPathChars);
}

// Throws the InputError of a bad log: "servo log '<path>': <what>".
[[noreturn]] void Fail(const std::string& path, const std::string& what) {
  throw InputError("servo log '" + ShownPath(path) + "': " + what);
}

// A motor or trajectory name: at most kMaxServoNameBytes, no control character.
void CheckName(const std::string& path, const char* field, const std::string& name) {
  if (name.size() > kMaxServoNameBytes) {
    Fail(path, std::string(field) + " is " + std::to_string(name.size()) +
                   " bytes long, over the limit of " + std::to_string(kMaxServoNameBytes));
  }
  for (const char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      Fail(path, std::string(field) + " '" + Shown(name, kShownCellChars) +
                     "' holds a control character");
    }
  }
}

// A number as it is shown: the shortest form that reads back the same.
std::string Number(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

// The bytes of the file at `path`, refused when it is missing, not a regular file, empty or
// larger than kMaxServoLogBytes (by its size, before reading it).
std::string ReadWholeFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) Fail(path, "no such file");
  if (fs::is_directory(status)) Fail(path, "is a folder, not a file");
  if (!fs::is_regular_file(status)) Fail(path, "is not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) Fail(path, "cannot be read: " + ec.message());
  if (size > kMaxServoLogBytes) {
    Fail(path, "is " + std::to_string(size) + " bytes, over the limit of 64 MiB (" +
                   std::to_string(kMaxServoLogBytes) + " bytes)");
  }
  if (size == 0) Fail(path, "is empty");
  std::ifstream in(path, std::ios::binary);
  std::string bytes(size, '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (!in || static_cast<std::uintmax_t>(in.gcount()) != size) Fail(path, "cannot be read");
  return bytes;
}

ServoLogFormat FormatOf(const std::string& path, ServoLogFormat format) {
  if (format != ServoLogFormat::kAuto) return format;
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".json") return ServoLogFormat::kBamJson;
  if (extension == ".csv") return ServoLogFormat::kCsv;
  Fail(path, "its format cannot be told from its extension '" + Shown(extension) +
                 "' (expected .csv or .json)");
}

// A setting (kp, mass, length) keeps its declaration (a log's kp may be 0: not given).
void CheckSetting(const std::string& path, const std::string& name, double value,
                  const KeyDoc& doc) {
  if (const std::string problem = KeyValueProblem(value, doc); !problem.empty()) {
    Fail(path, name + " must be " + problem + ", got " + Number(value));
  }
}

// A request or measured angle (deg) is physically possible: within kServoAngleDoc.
void CheckAngle(const std::string& path, const std::string& where, double angle_deg) {
  if (const std::string problem = KeyValueProblem(angle_deg, kServoAngleDoc); !problem.empty()) {
    Fail(path, where + " must be " + problem + ", got " + Number(angle_deg));
  }
}

void CheckNotBefore(const std::string& path, double before, double time, const std::string& at,
                    const std::string& previous) {
  if (!(time > before)) {
    Fail(path, at + " = " + Number(time) + " is not after " + previous + "'s " + Number(before) +
                   " (time stamps must strictly increase)");
  }
}

void CheckSamples(const std::string& path, const std::vector<ServoLogSample>& samples) {
  if (samples.size() < 2) {
    Fail(path, "has " + std::to_string(samples.size()) + " samples, at least 2 are needed");
  }
  if (std::none_of(samples.begin(), samples.end(),
                   [](const ServoLogSample& s) { return s.torque_enabled; })) {
    Fail(path, "torque is off in every sample");
  }
}

// ---- CSV ----

std::string RowName(long row) { return "row " + std::to_string(row); }

// The cells of one line, split at every comma (a trailing comma makes an empty last cell).
std::vector<std::string_view> SplitCells(std::string_view line) {
  std::vector<std::string_view> cells;
  for (size_t start = 0;;) {
    const size_t comma = line.find(',', start);
    cells.push_back(line.substr(start, comma - start));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

// One cell as a number: plain decimal as from_chars reads it, the whole cell used, finite.
double ParseNumber(const std::string& path, long row, size_t column, std::string_view cell) {
  double value = 0.0;
  const char* end = cell.data() + cell.size();
  const auto parsed = std::from_chars(cell.data(), end, value);
  const std::string where = RowName(row) + ", " + std::string(kCsvColumns[column]);
  if (cell.empty() || parsed.ec != std::errc() || parsed.ptr != end) {
    Fail(path, where + ": '" + Shown(cell) + "' is not a decimal number");
  }
  if (!std::isfinite(value)) Fail(path, where + ": '" + Shown(cell) + "' is not finite");
  return value;
}

bool ParseTorque(const std::string& path, long row, std::string_view cell) {
  if (cell == "1") return true;
  if (cell == "0") return false;
  Fail(path, RowName(row) + ", torque_enabled: '" + Shown(cell) + "' is not 0 or 1");
}

ServoLogSample ParseCsvRow(const std::string& path, std::string_view line, long row,
                           size_t columns) {
  const std::vector<std::string_view> cells = SplitCells(line);
  if (cells.size() != columns) {
    Fail(path, RowName(row) + " has " + std::to_string(cells.size()) + " columns, expected " +
                   std::to_string(columns));
  }
  ServoLogSample sample;
  sample.time_s = ParseNumber(path, row, 0, cells[0]);
  sample.request_deg = ParseNumber(path, row, 1, cells[1]);
  sample.measured_deg = ParseNumber(path, row, 2, cells[2]);
  CheckAngle(path, RowName(row) + ", request_deg", sample.request_deg);
  CheckAngle(path, RowName(row) + ", measured_deg", sample.measured_deg);
  if (columns == 4) sample.torque_enabled = ParseTorque(path, row, cells[3]);
  return sample;
}

// The next line of `text` from `pos` (moved past it), without its '\n' and trailing '\r'.
std::string_view NextLine(std::string_view text, size_t& pos) {
  const size_t newline = std::min(text.find('\n', pos), text.size());
  std::string_view line = text.substr(pos, newline - pos);
  pos = newline + 1;
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

// The number of columns the header announces (3 or 4).
size_t ParseCsvHeader(const std::string& path, std::string_view header) {
  if (header == CsvHeader(3)) return 3;
  if (header == CsvHeader(4)) return 4;
  Fail(path, "header must be '" + CsvHeader(3) + "' or with '," + std::string(kCsvColumns[3]) +
                 "', got '" + Shown(header, 2 * kShownCellChars) + "'");
}

std::vector<ServoLogSample> ParseCsvSamples(const std::string& path, std::string_view text) {
  size_t pos = 0;
  const size_t columns = ParseCsvHeader(path, NextLine(text, pos));
  std::vector<ServoLogSample> samples;
  long previous_row = 0;
  for (long row = 1; pos < text.size(); ++row) {
    const std::string_view line = NextLine(text, pos);
    if (line.empty()) continue;
    if (samples.size() == kMaxServoLogSamples) {
      Fail(path, RowName(row) + ": more than " + std::to_string(kMaxServoLogSamples) +
                     " samples (the limit)");
    }
    const ServoLogSample sample = ParseCsvRow(path, line, row, columns);
    if (!samples.empty()) {
      CheckNotBefore(path, samples.back().time_s, sample.time_s, RowName(row) + ", time_s",
                     RowName(previous_row));
    }
    samples.push_back(sample);
    previous_row = row;
  }
  return samples;
}

ServoLog ReadCsv(const std::string& path, const std::string& text,
                 const ServoLogDefaults& defaults) {
  CheckSetting(path, "kp (given for a CSV log)", defaults.kp, kLogKpDoc);
  CheckSetting(path, "mass_kg (given for a CSV log)", defaults.mass_kg, kServoMassDoc);
  CheckSetting(path, "length_m (given for a CSV log)", defaults.length_m, kServoLengthDoc);
  ServoLog log{.file = path,
               .motor = defaults.motor,
               .trajectory = fs::path(path).stem().string(),
               .kp = defaults.kp,
               .mass_kg = defaults.mass_kg,
               .length_m = defaults.length_m};
  log.samples = ParseCsvSamples(path, text);
  return log;
}

// ---- BAM JSON ----

// `entries[i]`, or the top-level object when `entry` is negative, for messages.
std::string EntryName(long entry) {
  return entry < 0 ? std::string() : "entries[" + std::to_string(entry) + "]";
}

const Json& Field(const std::string& path, const Json& object, const char* name, long entry) {
  const auto it = object.find(name);
  if (it == object.end()) {
    Fail(path, (entry < 0 ? std::string("the object") : EntryName(entry)) + " has no field '" +
                   name + "'");
  }
  return *it;
}

void FailType(const std::string& path, const Json& value, const char* name, long entry,
              const char* expected) {
  const std::string field = entry < 0 ? name : EntryName(entry) + "." + name;
  Fail(path, field + ": expected " + expected + ", got " + value.type_name());
}

// Field `name`, a number, times `scale`; finite.
double NumberField(const std::string& path, const Json& object, const char* name, long entry,
                   double scale = 1.0) {
  const Json& value = Field(path, object, name, entry);
  if (!value.is_number()) FailType(path, value, name, entry, "a number");
  const double number = value.get<double>() * scale;
  if (!std::isfinite(number)) {
    Fail(path, (entry < 0 ? name : EntryName(entry) + "." + name) + std::string(" is not finite"));
  }
  return number;
}

std::string StringField(const std::string& path, const Json& object, const char* name) {
  const Json& value = Field(path, object, name, -1);
  if (!value.is_string()) FailType(path, value, name, -1, "a string");
  return value.get<std::string>();
}

ServoLogSample JsonSample(const std::string& path, const Json& entry, long i) {
  if (!entry.is_object()) {
    Fail(path, EntryName(i) + ": expected an object, got " + entry.type_name());
  }
  const Json& torque = Field(path, entry, "torque_enable", i);
  if (!torque.is_boolean()) FailType(path, torque, "torque_enable", i, "true or false");
  const ServoLogSample sample{
      .time_s = NumberField(path, entry, "timestamp", i),
      .request_deg = NumberField(path, entry, "goal_position", i, RadToDeg(1.0)),
      .measured_deg = NumberField(path, entry, "position", i, RadToDeg(1.0)),
      .torque_enabled = torque.get<bool>()};
  CheckAngle(path, EntryName(i) + ".goal_position", sample.request_deg);
  CheckAngle(path, EntryName(i) + ".position", sample.measured_deg);
  return sample;
}

std::vector<ServoLogSample> JsonSamples(const std::string& path, const Json& entries) {
  if (!entries.is_array()) FailType(path, entries, "entries", -1, "an array");
  if (entries.size() > kMaxServoLogSamples) {
    Fail(path, "entries: " + std::to_string(entries.size()) + " samples, more than the limit of " +
                   std::to_string(kMaxServoLogSamples));
  }
  std::vector<ServoLogSample> samples;
  samples.reserve(entries.size());
  for (const Json& entry : entries) {
    const long i = static_cast<long>(samples.size());
    const ServoLogSample sample = JsonSample(path, entry, i);
    if (i > 0) {
      CheckNotBefore(path, samples.back().time_s, sample.time_s, EntryName(i) + ".timestamp",
                     EntryName(i - 1));
    }
    samples.push_back(sample);
  }
  return samples;
}

Json ParseJson(const std::string& path, const std::string& text) {
  // Only the fields read are kept: a long log's other fields (speed, load, ...) take no memory.
  static constexpr std::array<std::string_view, 10> kRead = {
      "mass",    "length",    "kp",       "motor",         "trajectory",
      "entries", "timestamp", "position", "goal_position", "torque_enable"};
  const auto keep = [](int, Json::parse_event_t event, Json& parsed) {
    return event != Json::parse_event_t::key ||
           std::find(kRead.begin(), kRead.end(), parsed.get_ref<const std::string&>()) !=
               kRead.end();
  };
  try {
    return Json::parse(text, keep);
  } catch (const Json::parse_error& e) {
    Fail(path, "is not valid JSON (byte " + std::to_string(e.byte) + "): " + Shown(e.what(), 120));
  } catch (const Json::exception& e) {  // a number too large for a double
    Fail(path, "is not valid JSON: " + Shown(e.what(), 120));
  }
}

ServoLog ReadBamJson(const std::string& path, const std::string& text) {
  const Json doc = ParseJson(path, text);
  if (!doc.is_object()) Fail(path, std::string("expected one JSON object, got ") + doc.type_name());
  ServoLog log{.file = path,
               .motor = StringField(path, doc, "motor"),
               .trajectory = StringField(path, doc, "trajectory"),
               .kp = NumberField(path, doc, "kp", -1),
               .mass_kg = NumberField(path, doc, "mass", -1),
               .length_m = NumberField(path, doc, "length", -1)};
  CheckSetting(path, "kp", log.kp, kLogKpDoc);
  CheckSetting(path, "mass", log.mass_kg, kServoMassDoc);
  CheckSetting(path, "length", log.length_m, kServoLengthDoc);
  log.samples = JsonSamples(path, Field(path, doc, "entries", -1));
  return log;
}

}  // namespace

ServoLog ReadServoLog(const std::string& path, ServoLogFormat format,
                      const ServoLogDefaults& csv_defaults) {
  const std::string text = ReadWholeFile(path);
  ServoLog log = FormatOf(path, format) == ServoLogFormat::kCsv ? ReadCsv(path, text, csv_defaults)
                                                                : ReadBamJson(path, text);
  CheckName(path, "motor", log.motor);
  CheckName(path, "trajectory", log.trajectory);
  CheckSamples(path, log.samples);
  return log;
}

void CheckServoLog(const ServoLog& log) {
  const std::string& path = log.file;
  if (log.motor.empty()) Fail(path, "motor is empty (a model is fitted per motor)");
  CheckName(path, "motor", log.motor);
  CheckName(path, "trajectory", log.trajectory);
  CheckSetting(path, "kp", log.kp, kLogKpDoc);
  CheckSetting(path, "mass", log.mass_kg, kServoMassDoc);
  CheckSetting(path, "length", log.length_m, kServoLengthDoc);
  if (log.samples.size() > kMaxServoLogSamples) {
    Fail(path, std::to_string(log.samples.size()) + " samples, more than the limit of " +
                   std::to_string(kMaxServoLogSamples));
  }
  const auto column = [](size_t i, std::string_view name) {
    return "sample " + std::to_string(i) + ", " + std::string(name);
  };
  for (size_t i = 0; i < log.samples.size(); ++i) {
    const ServoLogSample& s = log.samples[i];
    const double values[] = {s.time_s, s.request_deg, s.measured_deg};
    for (size_t c = 0; c < 3; ++c) {
      if (!std::isfinite(values[c])) {
        Fail(path, column(i, kCsvColumns[c]) + ": " + Number(values[c]) + " is not finite");
      }
    }
    CheckAngle(path, column(i, kServoLogColumns.request_deg), s.request_deg);
    CheckAngle(path, column(i, kServoLogColumns.measured_deg), s.measured_deg);
    if (i > 0) {
      CheckNotBefore(path, log.samples[i - 1].time_s, s.time_s, column(i, kServoLogColumns.time_s),
                     "sample " + std::to_string(i - 1));
    }
  }
  CheckSamples(path, log.samples);
}

std::string ServoLogCsvText(const ServoLog& log) {
  CheckServoLog(log);
  std::string text = CsvHeader(4);
  text += '\n';
  for (const ServoLogSample& s : log.samples) {
    AppendNumber(text, s.time_s);
    text += ',';
    AppendNumber(text, s.request_deg);
    text += ',';
    AppendNumber(text, s.measured_deg);
    text += s.torque_enabled ? ",1\n" : ",0\n";
  }
  return text;
}

}  // namespace leglab
