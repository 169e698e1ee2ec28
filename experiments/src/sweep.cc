#include "leglab/experiments/sweep.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "leglab/experiments/output.h"
#include "leglab/experiments/parallel.h"
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
  for (std::string_view joint : kLegJointNames) {
    for (const char* field : {"v_max_deg_per_tick", "theta0_deg", "lag_ticks", "accel_ticks"}) {
      columns.push_back("model_" + std::string(joint) + "_" + field);
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
  ok = status == "ok";
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

MergeResult MergeShards(const std::vector<fs::path>& dirs) {
  static const std::regex kShardName(R"(sweep\.shard-(\d+)-of-(\d+)\.csv)");
  std::map<int, fs::path> found;
  MergeResult result;
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
      if (result.shard_count != 0 && *count != result.shard_count) {
        MergeFail("shards of different counts: '" + entry.path().string() + "' is of " +
                  std::to_string(*count) + ", others of " + std::to_string(result.shard_count));
      }
      result.shard_count = static_cast<int>(*count);
      const auto [at, inserted] = found.emplace(static_cast<int>(*index), entry.path());
      if (!inserted) {
        MergeFail("shard " + m[1].str() + " found twice: '" + at->second.string() + "' and '" +
                  entry.path().string() + "'");
      }
    }
  }
  if (found.empty()) MergeFail("no sweep.shard-I-of-N.csv files in the folders given");
  for (int i = 0; i < result.shard_count; ++i) {
    if (!found.count(i)) result.missing.push_back(i);
  }
  if (!result.missing.empty()) return result;

  std::map<long, std::string> rows;
  for (const auto& [shard, path] : found) {
    std::ifstream in(path, std::ios::binary);
    std::string header;
    if (!std::getline(in, header)) MergeFail("'" + path.string() + "' is empty");
    if (result.table.header.empty()) result.table.header = header;
    if (header != result.table.header) {
      MergeFail("'" + path.string() + "' has another header than the other shards");
    }
    long expected = shard;
    for (std::string line; std::getline(in, line); expected += result.shard_count) {
      const auto index = ParseCount(std::string_view(line).substr(0, line.find(',')));
      if (!index || *index != expected) {
        MergeFail("'" + path.string() + "': row " + std::to_string(expected) + " of shard " +
                  std::to_string(shard) + " is missing or out of order");
      }
      rows.emplace(*index, line);
    }
  }
  // Complete shards hold every index below the total exactly once: check it.
  long expected = 0;
  for (auto& [index, line] : rows) {
    if (index != expected++) MergeFail("point " + std::to_string(expected - 1) + " is missing");
    result.table.rows.push_back(std::move(line));
  }
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
  return "sbatch --array=" + ranges + " scripts/sweep-slurm.sh " + sweep_file + " " + out_dir +
         " " + std::to_string(shard_count);
}

}  // namespace leglab::experiments
