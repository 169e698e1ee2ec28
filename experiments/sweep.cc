// sweep: runs a base experiment (track) at every point of a grid or a seeded random sample of
// config values and writes one row per point to sweep.csv; with --shard I/N (or a Slurm or
// Kubernetes job array) only every N-th point, into sweep.shard-I-of-N.csv. `sweep merge`
// joins the shards into the sweep.csv an unsharded run writes, byte for byte. Exit status: 0,
// 2 for bad input (nothing written), 3 when every point of the sweep failed (sweep.csv
// written), 1 for our failures.
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <optional>
#include <thread>

#include "leglab/app/output.h"
#include "leglab/app/progress.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/sweep.h"

namespace {

using namespace leglab;

using namespace leglab::experiments;
namespace fs = std::filesystem;

// --out checked as every program checks it, before any point runs.
void CheckOutDir(const std::string& out) { CheckOutFolder(out, {"sweep."}); }

// --progress: a line every 2 s while the points run, inside a point too: the points done, the
// ticks simulated so far (every point's, counted as they run) and an estimate of the time
// left from the points done.
class ProgressLines {
 public:
  explicit ProgressLines(long total) : total_(total), start_(Clock::now()) {
    thread_ = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!wake_.wait_for(lock, std::chrono::seconds(2), [this] { return stop_; })) Print();
    });
  }
  ~ProgressLines() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  ProgressLines(const ProgressLines&) = delete;
  ProgressLines& operator=(const ProgressLines&) = delete;

  void PointDone() { done_.fetch_add(1); }

 private:
  using Clock = std::chrono::steady_clock;
  void Print() const {
    const long done = done_.load();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    std::string line = "sweep: " + std::to_string(done) + "/" + std::to_string(total_) +
                       " points, " + std::to_string(CountedProgressTicks()) + " ticks simulated, " +
                       std::to_string(std::lround(elapsed)) + " s";
    if (done > 0) {
      line += ", about " +
              std::to_string(std::lround(elapsed / static_cast<double>(done) *
                                         static_cast<double>(total_ - done))) +
              " s left";
    }
    std::cerr << line + "\n" << std::flush;
  }

  long total_;
  Clock::time_point start_;
  std::atomic<long> done_{0};
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

// Exit status 3 when no point of a whole sweep is ok (its table, written, says why of each);
// else 0.
int AllFailedStatus(const char* program, const SweepTable& table) {
  if (table.rows.empty() || table.not_ok < static_cast<long>(table.rows.size())) return 0;
  std::cerr << program << ": error: every one of the " << table.rows.size()
            << " points failed (each row's status says why)\n";
  return 3;
}

// `sweep merge`: the shards of `dirs` into `out`/sweep.csv, checked against `config_path`'s
// sweep when given.
int Merge(const std::vector<std::string>& merge_dirs, const std::string& out,
          const std::string& config_path) {
  CheckOutDir(out);
  std::optional<SweepConfig> sweep;
  if (!config_path.empty()) sweep = LoadSweepConfig(config_path);
  const std::vector<fs::path> dirs(merge_dirs.begin(), merge_dirs.end());
  const MergeResult merged = MergeShards(dirs, sweep ? &*sweep : nullptr);
  if (!merged.missing.empty()) {
    std::string names;
    for (const int i : merged.missing) {
      names += (names.empty() ? "" : ", ") + ShardFileName({i, merged.shard_count});
    }
    std::cerr << "sweep merge: error: " << merged.missing.size() << " of " << merged.shard_count
              << " shards missing: " << names << "\nrerun them with:\n  "
              << SlurmRerunCommand(merged.missing, merged.shard_count,
                                   config_path.empty() ? "SWEEP.yaml" : config_path,
                                   merge_dirs.front())
              << '\n';
    return 2;
  }
  fs::create_directories(out);
  WriteSweepTable(merged.table, fs::path(out) / "sweep.csv");
  std::cerr << "sweep merge: " << merged.table.rows.size() << " points from " << merged.shard_count
            << " shards into " << out << "/sweep.csv\n";
  return AllFailedStatus("sweep merge", merged.table);
}

int Run(int argc, char** argv) {
  CLI::App app(
      "Sweep: run an experiment at every point of a grid or a random sample of config values, "
      "one CSV row per point; shard it over a cluster and merge the shards",
      "sweep");
  std::string config_path, out_dir, shard_text;
  std::optional<int> shards;
  int threads = 0;
  bool quiet = false;
  bool progress = false;
  app.add_option("--config", config_path, "sweep file (YAML: base, grid or sample)");
  app.add_option("--out", out_dir, "folder for sweep.csv or sweep.shard-I-of-N.csv");
  app.add_option("--shard", shard_text, "run only the points with index % N == I (I/N, 0-based)");
  app.add_option("--shards", shards,
                 "shard count when the index comes from JOB_COMPLETION_INDEX (or overrides "
                 "SLURM_ARRAY_TASK_COUNT)")
      ->check(CLI::PositiveNumber);
  app.add_option("--threads", threads,
                 "points run at once (default: one per core); rows do not depend on it")
      ->check(CLI::PositiveNumber);
  app.add_flag("--quiet", quiet, "no progress lines on stderr");
  app.add_flag("--progress", progress,
               "a progress line every 2 s, inside a point too (points done, ticks simulated)")
      ->excludes("--quiet");
  AddListOutputsFlag(app, SweepOutputs());
  AddListKeysFlag(app, [] {
    return KeyTableMarkdown(SweepKeys()) +
           "\nEvery other key of a sweep file is a key of its base experiment (track "
           "--list-keys), merged over the base.\n";
  });
  CLI::App* merge = app.add_subcommand(
      "merge", "join sweep.shard-I-of-N.csv files from the folders given into --out/sweep.csv");
  std::vector<std::string> merge_dirs;
  std::string merge_out, merge_config;
  merge->add_option("dirs", merge_dirs, "folders holding shard files")->required();
  merge->add_option("--out", merge_out, "folder for sweep.csv")->required();
  merge->add_option("--config", merge_config,
                    "the sweep file: checks the point count, names it in the rerun command");
  app.require_subcommand(0, 1);
  RefuseEmptyValues(app);
  try {
    app.parse(argc, argv);
    if (!merge->parsed() && (config_path.empty() || out_dir.empty())) {
      throw CLI::ValidationError("--config and --out", "are required (or use `sweep merge`)");
    }
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, or --list-keys printed the keys
  } catch (const CLI::ParseError& e) {
    std::cerr << "sweep: error: " << MessageLine(e.what()) << " (see --help)\n";
    return 2;
  }

  if (merge->parsed()) return Merge(merge_dirs, merge_out, merge_config);
  CheckOutDir(out_dir);
  std::optional<Shard> shard;
  if (!shard_text.empty()) {
    shard = ParseShard(shard_text);
  } else {
    shard = ShardFromEnvironment([](const char* name) { return std::getenv(name); }, shards);
  }
  const SweepConfig sweep = LoadSweepConfig(config_path);
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  std::optional<ProgressLines> lines;
  if (progress) {
    long mine = 0;
    const Shard s = shard.value_or(Shard{});
    for (const SweepPoint& p : sweep.points) mine += p.index % s.count == s.index ? 1 : 0;
    lines.emplace(mine);
  }
  SweepTable table = RunSweep(sweep, shard.value_or(Shard{}), threads, [&](long done, long total) {
    if (lines) {
      lines->PointDone();
      return;
    }
    const auto now = std::chrono::steady_clock::now();
    if (quiet || (done < total && now - last < std::chrono::seconds(2))) return;
    last = now;
    const double elapsed = std::chrono::duration<double>(now - start).count();
    std::cerr << "sweep: " << done << "/" << total << " points, " << static_cast<long>(elapsed)
              << " s, about "
              << static_cast<long>(elapsed / static_cast<double>(done) *
                                   static_cast<double>(total - done))
              << " s left\n";
  });
  lines.reset();
  if (shard) table.stamp = ShardStamp(sweep, *shard);
  fs::create_directories(out_dir);
  const fs::path file = fs::path(out_dir) / (shard ? ShardFileName(*shard) : "sweep.csv");
  WriteSweepTable(table, file);
  std::cerr << "sweep: " << table.rows.size() << " points (" << table.not_ok << " not ok) into "
            << file.string() << '\n';
  // A shard whose points all failed is not the sweep's failure: the merge judges the whole.
  return shard ? 0 : AllFailedStatus("sweep", table);
}

}  // namespace

int main(int argc, char** argv) {
  // ReportErrors: one line with control characters and invisible ones escaped (a shard's CRLF
  // or byte-order mark echoed in a message), status 2 for bad input and 1 for a failure.
  int status = 0;
  const int reported = ReportErrors("sweep", [&] { status = Run(argc, argv); });
  return reported != 0 ? reported : status;
}
