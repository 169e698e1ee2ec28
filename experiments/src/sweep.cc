#include "leglab/experiments/sweep.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "leglab/app/output.h"
#include "leglab/app/parallel.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxShards = 1'000'000;

// A whole non-negative decimal number, or nothing.
std::optional<long> ParseCount(std::string_view text) {
  long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty() || value < 0) {
    return std::nullopt;
  }
  return value;
}

// A CSV cell: quoted (RFC 4180) when it holds a separator, a quote or a line break.
std::string CsvCell(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return quoted + '"';
}

// The columns after a point's status: what every base mode, the floor and the model report.
std::vector<std::string> ResultColumns(const ExperimentConfig& base) {
  std::vector<std::string> columns;
  auto joint_l2 = [&](const std::string& who) {
    for (std::string_view joint : kLegJointNames) {
      columns.push_back(who + "_" + std::string(joint) + "_l2_deg");
    }
    columns.push_back(who + "_foot_l2_cm");
  };
  for (const ControllerSpec& spec : base.controllers) {
    const std::string mode(ModeOf(spec).name);
    joint_l2(mode);
    for (const auto& [name, value] : ModeParameters(spec)) {
      columns.push_back(mode + "_" + std::string(name));
    }
  }
  joint_l2("floor");
  columns.emplace_back("model_source");
  // A joint model's values by their keys' names (VisitKeys).
  const std::vector<KeyValue> model_keys =
      KeyValues(JointModelParams{}, [](KeyVisitor& v, JointModelParams& m) { VisitKeys(v, m); });
  for (std::string_view joint : kLegJointNames) {
    for (const KeyValue& k : model_keys) {
      columns.push_back("model_" + std::string(joint) + "_" + k.key);
    }
  }
  return columns;
}

// The result cells of one point's run, matching ResultColumns(base). A mode the point does not
// run (it changed controller.modes) leaves its cells empty.
std::vector<std::string> ResultCells(const ExperimentConfig& base, const TrackResult& result) {
  const Table2 table = ComputeTable2(result);
  std::vector<std::string> cells;
  auto joint_l2 = [&](const std::string& label, const std::string& foot_key) {
    const Table2Row* row = table.Find("L2(Des," + label + ")");
    const FootRow* foot = table.FindFoot(foot_key);
    for (int j = 0; j < kLegJoints; ++j) {
      cells.push_back(row ? FormatDouble(row->joints[j].mean) : "");
    }
    cells.push_back(foot ? FormatDouble(foot->l2_cm.mean) : "");
  };
  for (const ControllerSpec& spec : base.controllers) {
    const ControllerModeInfo& mode = ModeOf(spec);
    joint_l2(std::string(mode.label), std::string(mode.name));
    const FootRow* foot = table.FindFoot(mode.name);
    for (const auto& [name, unused] : ModeParameters(spec)) {
      std::string cell;
      if (foot) {
        for (const auto& [n, value] : foot->parameters) {
          if (n == name) cell = std::to_string(value);
        }
      }
      cells.push_back(cell);
    }
  }
  joint_l2("Floor", "floor");
  cells.emplace_back(table.models_identified ? "identified" : "given");
  for (const JointModelParams& m : table.models) {
    cells.push_back(FormatDouble(m.v_max_deg_per_tick));
    cells.push_back(FormatDouble(m.theta0_deg));
    cells.push_back(std::to_string(m.lag_ticks));
    cells.push_back(std::to_string(m.accel_ticks));
  }
  return cells;
}

// A whole cell that is a finite number: what the merge requires of a result cell.
bool IsFiniteNumber(const std::string& cell) {
  double value = 0.0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return ec == std::errc() && end == cell.data() + cell.size() && std::isfinite(value);
}

// "ok", or the status of a point whose results hold a NaN or an infinity (a row the merge would
// refuse as an ok row); result cells in ResultColumns' order, model_source the only text.
std::string NonFiniteResult(const ExperimentConfig& base, const std::vector<std::string>& cells) {
  const std::vector<std::string> columns = ResultColumns(base);
  for (size_t c = 0; c < cells.size() && c < columns.size(); ++c) {
    if (columns[c] != "model_source" && !cells[c].empty() && !IsFiniteNumber(cells[c])) {
      return "result " + columns[c] + " is not finite: " + cells[c];
    }
  }
  return "ok";
}

// One point's row: the experiment at the point, or the reason it could not run.
std::string PointRow(const SweepConfig& sweep, const SweepPoint& point,
                     const ExperimentConfig& base, size_t result_columns, bool& ok) {
  std::string status = "ok";
  std::vector<std::string> cells;
  try {
    ExperimentConfig config = LoadExperimentConfig(sweep.base_path, sweep.PointOverrides(point));
    config.threads = 1;  // points run in parallel; one thread each keeps the schedule out of it
    cells = ResultCells(base, RunTrackExperiment(config));
  } catch (const InputError& e) {
    status = e.what();
  } catch (const std::invalid_argument& e) {
    status = e.what();
  } catch (const std::domain_error& e) {
    status = e.what();
  } catch (const std::exception& e) {
    status = std::string("internal error: ") + e.what();
  }
  if (status == "ok") status = NonFiniteResult(base, cells);
  ok = status == "ok";
  if (!ok) cells.clear();
  cells.resize(result_columns);  // a failed point: empty result cells
  std::string row = std::to_string(point.index);
  for (const std::string& value : point.values) row += "," + CsvCell(value);
  row += "," + CsvCell(status);
  for (const std::string& cell : cells) row += "," + cell;
  return row;
}

// A swept key that no config reader knows is the sweep file's mistake: found by loading the
// base with that key alone at its first value (a bad value is a point's status, not this).
void CheckSweptKeys(const SweepConfig& sweep) {
  if (sweep.points.empty()) return;
  for (size_t k = 0; k < sweep.keys.size(); ++k) {
    std::vector<std::string> overrides = sweep.overrides;
    overrides.push_back(sweep.keys[k] + "=" + sweep.points[0].values[k]);
    try {
      LoadExperimentConfig(sweep.base_path, overrides);
    } catch (const UnknownKeyError& e) {
      throw InputError("sweep '" + sweep.path + "': swept key '" + sweep.keys[k] +
                       "': " + e.what());
    } catch (const std::exception&) {
      // A bad value: each point reports its own.
    }
  }
}

[[noreturn]] void MergeFail(const std::string& what) { throw InputError("merge: " + what); }

// FNV-1a 64: small and the same on every machine; it tells sweeps apart, it is no signature.
class Fnv1a64 {
 public:
  void Add(std::string_view text) {
    for (const unsigned char c : text) {
      hash_ ^= c;
      hash_ *= 0x100000001b3ULL;
    }
  }
  std::string Hex() const {
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash_));
    return hex;
  }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

// What a shard file's stamp (ShardStamp) says.
struct StampFields {
  std::string id;
  long index = 0, count = 1, points = 0;
};

std::optional<StampFields> ParseStamp(const std::string& line) {
  static const std::regex kStamp(R"(# sweep ([0-9a-f]{16}) shard (\d+) of (\d+), (\d+) points)");
  std::smatch m;
  if (!std::regex_match(line, m, kStamp)) return std::nullopt;
  const auto index = ParseCount(m[2].str()), count = ParseCount(m[3].str()),
             points = ParseCount(m[4].str());
  if (!index || !count || !points) return std::nullopt;
  return StampFields{m[1].str(), *index, *count, *points};
}

// How many of the sweep's points are the stamp's shard's: indices I, I + N, ... below P.
long ShardPoints(const StampFields& s) {
  return s.points > s.index ? (s.points - 1 - s.index) / s.count + 1 : 0;
}

// The cells of a CSV line (RFC 4180 quotes, as CsvCell writes them); empty for an unclosed
// quote or text after a closing quote.
std::optional<std::vector<std::string>> SplitCsv(std::string_view line) {
  std::vector<std::string> cells(1);
  bool quoted = false, closed = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
      cells.back() += '"';
      ++i;
    } else if (c == '"' && (quoted || cells.back().empty()) && !closed) {
      closed = quoted;
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      cells.emplace_back();
      closed = false;
    } else if (closed) {
      return std::nullopt;
    } else {
      cells.back() += c;
    }
  }
  if (quoted) return std::nullopt;
  return cells;
}

// A shard file as read: its stamp, header (and its columns) and rows.
struct ShardFile {
  fs::path path;
  StampFields stamp;
  std::string header;
  std::vector<std::string> columns;
  std::vector<std::string> rows;
};

// Reads the shard file `path`, named as `shard`: its stamp must name that shard, its header
// an index and a status column.
ShardFile ReadShard(const fs::path& path, const Shard& shard) {
  const std::string where = "'" + path.string() + "'";
  std::ifstream in(path, std::ios::binary);
  std::string stamp;
  if (!std::getline(in, stamp)) MergeFail(where + " is empty");
  const std::optional<StampFields> fields = ParseStamp(stamp);
  if (!fields) {
    MergeFail(where + " line 1: expected the stamp '# sweep <id> shard I of N, P points', got '" +
              stamp.substr(0, 60) + "'");
  }
  if (fields->index != shard.index || fields->count != shard.count) {
    MergeFail(where + " line 1: the stamp says shard " + std::to_string(fields->index) + " of " +
              std::to_string(fields->count) + ", the file's name shard " +
              std::to_string(shard.index) + " of " + std::to_string(shard.count));
  }
  ShardFile file{path, *fields, "", {}, {}};
  if (!std::getline(in, file.header)) MergeFail(where + ": no header (line 2)");
  file.columns = SplitCsv(file.header).value_or(std::vector<std::string>{});
  if (file.columns.empty() || file.columns[0] != "index" ||
      std::find(file.columns.begin(), file.columns.end(), "status") == file.columns.end()) {
    MergeFail(where + " line 2: expected a header 'index,<keys>,status,...'");
  }
  for (std::string line; std::getline(in, line);) file.rows.push_back(std::move(line));
  return file;
}

// `file` is of the same sweep as `first` (the first shard read, when there is one) and as
// `expected` (the --config sweep's id and point count, when given), with the same header.
void CheckSameSweep(const ShardFile& file, const ShardFile* first,
                    const std::optional<StampFields>& expected, const std::string& sweep_path) {
  const std::string where = "'" + file.path.string() + "'";
  const auto of = [](const StampFields& s) {
    return "sweep " + s.id + " (" + std::to_string(s.points) + " points)";
  };
  if (expected && (file.stamp.id != expected->id || file.stamp.points != expected->points)) {
    MergeFail(where + " line 1: a shard of " + of(file.stamp) + ", but '" + sweep_path + "' is " +
              of(*expected));
  }
  if (!first) return;
  if (file.stamp.id != first->stamp.id || file.stamp.points != first->stamp.points) {
    MergeFail(where + " line 1: a shard of " + of(file.stamp) + ", but '" + first->path.string() +
              "' of " + of(first->stamp));
  }
  if (file.header != first->header) {
    MergeFail(where + " line 2: another header than '" + first->path.string() + "'");
  }
}

// Checks one row (`where`: its file and line) against the header's `columns`: as many cells,
// the index `index`, and after the status either finite numbers (or empty: a mode the point
// did not run) and a model_source when ok, or no results when the point failed. Returns
// whether the point is ok.
bool CheckRow(const std::string& where, const std::vector<std::string>& columns,
              const std::string& line, long index) {
  const auto cells = SplitCsv(line);
  const std::string at = where + " (point " + std::to_string(index) + ")";
  if (!cells) MergeFail(at + ": a quote is not closed");
  if (cells->size() != columns.size()) {
    MergeFail(at + ": " + std::to_string(cells->size()) + " cells, the header has " +
              std::to_string(columns.size()) + " columns");
  }
  const auto fail = [&](size_t c, const std::string& what) {
    MergeFail(at + ", column " + std::to_string(c + 1) + " '" + columns[c] + "': " + what +
              ", got '" + (*cells)[c].substr(0, 40) + "'");
  };
  if (ParseCount((*cells)[0]) != index) fail(0, "expected " + std::to_string(index));
  const size_t status = std::find(columns.begin(), columns.end(), "status") - columns.begin();
  const bool ok = (*cells)[status] == "ok";
  if ((*cells)[status].empty()) fail(status, "expected ok or why the point failed");
  for (size_t c = status + 1; c < columns.size(); ++c) {
    const std::string& cell = (*cells)[c];
    if (!ok && !cell.empty()) {
      fail(c, "expected no result: the point's status is not ok");
    } else if (ok && columns[c] == "model_source") {
      if (cell != "identified" && cell != "given") fail(c, "expected identified or given");
    } else if (ok && !cell.empty() && !IsFiniteNumber(cell)) {
      fail(c, "expected a finite number");
    }
  }
  return ok;
}

// Every sweep.shard-I-of-N.csv in `dirs` by I; sets `shard_count` to their N.
std::map<int, fs::path> FindShards(const std::vector<fs::path>& dirs, int& shard_count) {
  static const std::regex kShardName(R"(sweep\.shard-(\d+)-of-(\d+)\.csv)");
  std::map<int, fs::path> found;
  for (const fs::path& dir : dirs) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) MergeFail("'" + dir.string() + "' is not a folder");
    for (const auto& entry : fs::directory_iterator(dir)) {
      std::smatch m;
      const std::string name = entry.path().filename().string();
      if (!std::regex_match(name, m, kShardName)) continue;
      const auto index = ParseCount(m[1].str()), count = ParseCount(m[2].str());
      if (!index || !count || *count < 1 || *count > kMaxShards || *index >= *count) {
        MergeFail("'" + entry.path().string() + "' is not a shard's name");
      }
      if (shard_count != 0 && *count != shard_count) {
        MergeFail("shards of different counts: '" + entry.path().string() + "' is of " +
                  std::to_string(*count) + ", others of " + std::to_string(shard_count));
      }
      shard_count = static_cast<int>(*count);
      const auto [at, inserted] = found.emplace(static_cast<int>(*index), entry.path());
      if (!inserted) {
        MergeFail("shard " + m[1].str() + " found twice: '" + at->second.string() + "' and '" +
                  entry.path().string() + "'");
      }
    }
  }
  if (found.empty()) MergeFail("no sweep.shard-I-of-N.csv files in the folders given");
  return found;
}

}  // namespace

Shard ParseShard(std::string_view text) {
  const auto fail = [&]() -> Shard {
    throw InputError("--shard '" + std::string(text) +
                     "': expected I/N with 0 <= I < N <= " + std::to_string(kMaxShards));
  };
  const size_t slash = text.find('/');
  if (slash == std::string_view::npos) return fail();
  const auto index = ParseCount(text.substr(0, slash));
  const auto count = ParseCount(text.substr(slash + 1));
  if (!index || !count || *count < 1 || *count > kMaxShards || *index >= *count) return fail();
  return {static_cast<int>(*index), static_cast<int>(*count)};
}

std::optional<Shard> ShardFromEnvironment(const std::function<const char*(const char*)>& getenv,
                                          std::optional<int> shards) {
  auto number = [&](const char* name) -> std::optional<long> {
    const char* value = getenv(name);
    if (value == nullptr) return std::nullopt;
    const auto parsed = ParseCount(value);
    if (!parsed || *parsed > kMaxShards) {
      throw InputError(std::string(name) + "='" + value + "' is not a shard number");
    }
    return parsed;
  };
  auto shard = [&](const char* index_name, long index, long count) {
    if (count < 1 || index >= count) {
      throw InputError(std::string(index_name) + "=" + std::to_string(index) +
                       " is not below the shard count " + std::to_string(count) +
                       " (shards are numbered from 0: e.g. sbatch --array=0-" +
                       std::to_string(std::max(0L, count - 1)) + ")");
    }
    return Shard{static_cast<int>(index), static_cast<int>(count)};
  };
  if (const auto task = number("SLURM_ARRAY_TASK_ID")) {
    const auto count = shards ? std::optional<long>(*shards) : number("SLURM_ARRAY_TASK_COUNT");
    if (!count) throw InputError("SLURM_ARRAY_TASK_ID is set without SLURM_ARRAY_TASK_COUNT");
    return shard("SLURM_ARRAY_TASK_ID", *task, *count);
  }
  if (const auto index = number("JOB_COMPLETION_INDEX")) {
    if (!shards) {
      throw InputError(
          "JOB_COMPLETION_INDEX is set: give the shard count (the Job's completions) with "
          "--shards N");
    }
    return shard("JOB_COMPLETION_INDEX", *index, *shards);
  }
  return std::nullopt;
}

std::string SweepId(const SweepConfig& sweep) {
  // Separators no key or YAML value holds keep "a,b" + "c" apart from "a" + "b,c".
  Fnv1a64 hash;
  for (const std::string& key : sweep.keys) {
    hash.Add(key);
    hash.Add("\x1f");
  }
  for (const SweepPoint& p : sweep.points) {
    hash.Add("\x1e");
    hash.Add(std::to_string(p.index));
    for (const std::string& value : p.values) {
      hash.Add("\x1f");
      hash.Add(value);
    }
  }
  hash.Add("\x1d");
  hash.Add(LoadExperimentConfig(sweep.base_path, sweep.overrides).merged_yaml);
  return hash.Hex();
}

std::string ShardStamp(const SweepConfig& sweep, const Shard& shard) {
  return "# sweep " + SweepId(sweep) + " shard " + std::to_string(shard.index) + " of " +
         std::to_string(shard.count) + ", " + std::to_string(sweep.points.size()) + " points";
}

std::string ShardFileName(const Shard& shard) {
  return "sweep.shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) +
         ".csv";
}

SweepTable RunSweep(const SweepConfig& sweep, const Shard& shard, int threads,
                    const std::function<void(long, long)>& on_point_done) {
  const ExperimentConfig base = LoadExperimentConfig(sweep.base_path, sweep.overrides);
  CheckSweptKeys(sweep);
  const std::vector<std::string> results = ResultColumns(base);
  SweepTable table;
  table.header = "index";
  for (const std::string& key : sweep.keys) table.header += "," + CsvCell(key);
  table.header += ",status";
  for (const std::string& column : results) table.header += "," + column;

  std::vector<const SweepPoint*> mine;
  for (const SweepPoint& p : sweep.points) {
    if (p.index % shard.count == shard.index) mine.push_back(&p);
  }
  table.rows.resize(mine.size());
  std::vector<char> ok(mine.size());
  std::mutex progress;
  long done = 0;
  ParallelFor(static_cast<int>(mine.size()), threads, [&](int i) {
    bool point_ok = false;
    table.rows[i] = PointRow(sweep, *mine[i], base, results.size(), point_ok);
    ok[i] = point_ok;
    if (on_point_done) {
      const std::lock_guard lock(progress);
      on_point_done(++done, static_cast<long>(mine.size()));
    }
  });
  table.not_ok = static_cast<long>(std::count(ok.begin(), ok.end(), 0));
  return table;
}

void WriteSweepTable(const SweepTable& table, const fs::path& path) {
  const fs::path temporary =
      path.parent_path() / ("." + path.filename().string() + ".tmp-" + std::to_string(::getpid()));
  {
    std::ofstream out(temporary, std::ios::binary);
    if (!table.stamp.empty()) out << table.stamp << '\n';
    out << table.header << '\n';
    for (const std::string& row : table.rows) out << row << '\n';
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(temporary, ec);
      throw std::runtime_error("cannot write " + path.string());
    }
  }
  std::error_code ec;
  fs::rename(temporary, path, ec);
  if (ec) {
    fs::remove(temporary, ec);
    throw std::runtime_error("cannot write " + path.string() + ": " + ec.message());
  }
}

MergeResult MergeShards(const std::vector<fs::path>& dirs, const SweepConfig* sweep) {
  MergeResult result;
  const std::map<int, fs::path> found = FindShards(dirs, result.shard_count);
  for (int i = 0; i < result.shard_count; ++i) {
    if (!found.count(i)) result.missing.push_back(i);
  }
  if (!result.missing.empty()) return result;

  std::optional<StampFields> expected;
  if (sweep) expected = StampFields{SweepId(*sweep), 0, 1, static_cast<long>(sweep->points.size())};
  std::optional<ShardFile> first;
  std::map<long, std::string> rows;
  for (const auto& [shard, path] : found) {
    ShardFile file = ReadShard(path, Shard{shard, result.shard_count});
    CheckSameSweep(file, first ? &*first : nullptr, expected, sweep ? sweep->path : "");
    const std::string where = "'" + path.string() + "'";
    long index = shard;
    for (size_t r = 0; r < file.rows.size(); ++r, index += result.shard_count) {
      if (index >= file.stamp.points) {
        MergeFail(where + " line " + std::to_string(r + 3) + ": a row beyond shard " +
                  std::to_string(shard) + "'s " + std::to_string(ShardPoints(file.stamp)) +
                  " points");
      }
      const bool ok =
          CheckRow(where + " line " + std::to_string(r + 3), file.columns, file.rows[r], index);
      result.table.not_ok += ok ? 0 : 1;
      rows.emplace(index, std::move(file.rows[r]));
    }
    if (index < file.stamp.points) {
      MergeFail(where + ": point " + std::to_string(index) + " is missing (after line " +
                std::to_string(file.rows.size() + 2) + "; shard " + std::to_string(shard) +
                " has " + std::to_string(ShardPoints(file.stamp)) + " points)");
    }
    if (!first) {
      result.table.header = file.header;
      first = std::move(file);
    }
  }
  // Whole shards of one sweep hold every index below its point count once: rows is complete.
  for (auto& [index, line] : rows) result.table.rows.push_back(std::move(line));
  return result;
}

std::string SlurmRerunCommand(const std::vector<int>& missing, int shard_count,
                              const std::string& sweep_file, const std::string& out_dir) {
  std::string ranges;
  for (size_t i = 0; i < missing.size();) {
    size_t j = i;
    while (j + 1 < missing.size() && missing[j + 1] == missing[j] + 1) ++j;
    if (!ranges.empty()) ranges += ',';
    ranges += std::to_string(missing[i]);
    if (j > i) ranges += "-" + std::to_string(missing[j]);
    i = j + 1;
  }
  return "sbatch --array=" + ranges + " scripts/sweep_slurm.sh " + sweep_file + " " + out_dir +
         " " + std::to_string(shard_count);
}

std::span<const OutputDoc> SweepOutputs() {
  static const OutputDoc outputs[] = {
      {"sweep.csv",
       "track at every point of the sweep, a row each (with --shard I/N: "
       "sweep.shard-I-of-N.csv, its points only, after a line that stamps the sweep and shard; "
       "sweep merge joins them into sweep.csv byte for byte).",
       kSweepColumns},
  };
  return outputs;
}

}  // namespace leglab::experiments
