// sweep: runs a base experiment (track) at every point of a grid or a seeded random sample of
// config values and writes one row per point to sweep.csv; with --shard I/N (or a Slurm or
// Kubernetes job array) only every N-th point, into sweep.shard-I-of-N.csv. `sweep merge`
// joins the shards into the sweep.csv an unsharded run writes, byte for byte. Exit status: 0,
// 2 for bad input (nothing written), 3 when every point of the sweep failed (sweep.csv
// written), 1 for our failures.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "leglab/experiments/config.h"
#include "leglab/experiments/output.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/sweep.h"

namespace {

using namespace leglab::experiments;
namespace fs = std::filesystem;

// --out checked as every program checks it, before any point runs.
void CheckOutDir(const std::string& out) { CheckOutFolder(out, {"sweep."}); }

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
  SweepTable table = RunSweep(sweep, shard.value_or(Shard{}), threads, [&](long done, long total) {
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
  try {
    return Run(argc, argv);
  } catch (const InputError& e) {
    std::cerr << "sweep: error: " << e.what() << '\n';
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "sweep: failed: " << e.what() << '\n';
    return 1;
  }
}
