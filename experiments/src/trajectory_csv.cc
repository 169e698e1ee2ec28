#include "leglab/experiments/trajectory_csv.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string_view>
#include <vector>

#include "leglab/core/units.h"
#include "leglab/experiments/config.h"

namespace leglab::experiments {
namespace {

constexpr size_t kColumns = kLegJoints + 1;

// Throws the InputError of a bad file: "desired.csv '<path>': <what>".
using Fail = std::function<void(const std::string&)>;

// Column `c`'s name: tick, then <joint>_deg.
std::string ColumnName(size_t c) {
  return c == 0 ? "tick" : std::string(kLegJointNames[c - 1]) + "_deg";
}

// One cell as a number: plain decimal only, the tick a whole number of digits, an angle as
// from_chars reads it (no hex such as 0x7, no sign '+', no spaces), the whole cell used.
double ParseCell(const std::string& cell, size_t c, int row, const Fail& fail) {
  const char* end = cell.data() + cell.size();
  std::from_chars_result parsed{};
  double value = 0.0;
  if (c == 0) {
    long tick = -1;
    parsed = std::from_chars(cell.data(), end, tick);
    if (cell.empty() || cell.find_first_not_of("0123456789") != std::string::npos) {
      parsed.ec = std::errc::invalid_argument;
    }
    value = static_cast<double>(tick);
  } else {
    parsed = std::from_chars(cell.data(), end, value);
  }
  if (parsed.ec != std::errc() || parsed.ptr != end) {
    fail("row " + std::to_string(row) + ", " + ColumnName(c) + ": '" + cell + "' is not a " +
         (c == 0 ? "tick (digits only)" : "decimal number"));
  }
  if (!std::isfinite(value))
    fail("row " + std::to_string(row) + ", " + ColumnName(c) + " is not finite");
  return value;
}

// One non-blank row, `row` counted from 1 after the header, which must be tick `tick`.
LegAngles ParseRow(const std::string& line, int row, size_t tick,
                   const std::array<JointLimits, kLegJoints>& limits, const Fail& fail) {
  std::vector<std::string> cells;
  std::stringstream s(line);
  for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
  if (cells.size() != kColumns) {
    fail("row " + std::to_string(row) + " has " + std::to_string(cells.size()) +
         " columns, expected " + std::to_string(kColumns));
  }
  std::array<double, kColumns> values{};
  for (size_t c = 0; c < kColumns; ++c) {
    values[c] = ParseCell(cells[c], c, row, fail);
    if (c > 0) {
      const JointLimits& lim = limits[c - 1];
      if (DegToRad(values[c]) < lim.lower_rad - 1e-9 ||
          DegToRad(values[c]) > lim.upper_rad + 1e-9) {
        fail("row " + std::to_string(row) + ", " + ColumnName(c) + " = " + cells[c] +
             " is outside the joint limits");
      }
    }
  }
  if (values[0] != static_cast<double>(tick)) {
    fail("row " + std::to_string(row) + ": tick must be " + std::to_string(tick) + ", got " +
         cells[0]);
  }
  return {values[1], values[2], values[3]};
}

}  // namespace

std::string DesiredCsvHeader() {
  std::string header = "tick";
  for (std::string_view joint : kLegJointNames) {
    header += ',';  // appended piecewise: GCC 12 misfires -Wrestrict on "," + ...
    header += joint;
    header += "_deg";
  }
  return header;
}

DesiredCycle ReadDesiredCsv(const std::string& path, int period,
                            const std::array<JointLimits, kLegJoints>& limits) {
  CheckFileSize(path, kMaxDesiredCsvBytes, "desired.csv");
  std::ifstream in(path);
  if (!in) throw InputError("desired.csv: cannot read '" + path + "'");
  const Fail fail = [&](const std::string& what) {
    throw InputError("desired.csv '" + path + "': " + what);
  };
  const std::string header = DesiredCsvHeader();
  std::string line;
  if (!std::getline(in, line)) fail("is empty");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != header) fail("header must be '" + header + "', got '" + line + "'");
  DesiredCycle cycle;
  for (int row = 1; std::getline(in, line); ++row) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    cycle.push_back(ParseRow(line, row, cycle.size(), limits, fail));
  }
  if (static_cast<int>(cycle.size()) != period) {
    fail("has " + std::to_string(cycle.size()) +
         " rows, expected one cycle of track.t_step_ticks = " + std::to_string(period));
  }
  return cycle;
}

}  // namespace leglab::experiments
