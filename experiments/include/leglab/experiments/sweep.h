#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/experiments/config.h"

namespace leglab::experiments {

/// Which of a sweep's points one process runs: those with index % count == index.
struct Shard {
  int index = 0;
  int count = 1;
  friend bool operator==(const Shard&, const Shard&) = default;
};

/// Parses `--shard I/N` (0 <= I < N <= 10^6); throws InputError quoting the text.
Shard ParseShard(std::string_view text);

/// The shard a cluster's job array asks for, when no --shard is given: SLURM_ARRAY_TASK_ID as
/// the index with SLURM_ARRAY_TASK_COUNT (or `shards` when given) as the count; else
/// Kubernetes' JOB_COMPLETION_INDEX with `shards` as the count (an Indexed Job does not pass
/// its completions). Empty when neither variable is set. `getenv` is the environment (a
/// parameter so tests can supply one). Throws InputError naming the variable for a value
/// that is not a number, an index not below the count, or JOB_COMPLETION_INDEX without
/// `shards`.
std::optional<Shard> ShardFromEnvironment(const std::function<const char*(const char*)>& getenv,
                                          std::optional<int> shards);

/// The file a shard writes: "sweep.shard-I-of-N.csv".
std::string ShardFileName(const Shard& shard);

/// A sweep's table: a header and one CSV line per point (no newline), in index order.
struct SweepTable {
  std::string header;
  std::vector<std::string> rows;
  long not_ok = 0;  ///< rows whose status is not `ok` (RunSweep only)
};

/// Runs the points of `sweep` in `shard` on `threads` threads (each point single-threaded,
/// so the rows do not depend on the count) and returns their rows. A point's row: index,
/// each swept key's value, status (`ok`, or the one-line error of a point that could not run),
/// then for every mode of the base config its joint L2s (deg) and foot L2 (cm) means and its
/// chosen parameters (time_shift's k), the floor's, and each joint's model (identified, or the
/// point's model.*). Throws InputError when the base config itself is bad or a swept key is
/// not a config key (UnknownKeyError): the sweep file is wrong, not one point.
/// `on_point_done(done, total)` is called after each point (from worker threads, serialised).
SweepTable RunSweep(const SweepConfig& sweep, const Shard& shard, int threads,
                    const std::function<void(long, long)>& on_point_done = {});

/// Writes `table` to `path` atomically (a temporary file beside it, then a rename): a reader
/// never sees half a table. Throws std::runtime_error naming the file.
void WriteSweepTable(const SweepTable& table, const std::filesystem::path& path);

/// What merging shard files found.
struct MergeResult {
  SweepTable table;          ///< every row, in index order, when complete
  int shard_count = 0;       ///< N of the shards found
  std::vector<int> missing;  ///< shard indices without a file, ascending
};

/// Finds every sweep.shard-I-of-N.csv in `dirs` and joins their rows in index order: the same
/// bytes as the unsharded sweep.csv. Throws InputError for no shard files, shards of different
/// N or headers, a shard found twice, or a file whose rows are not its shard's. Missing shards
/// are reported in `missing` (then `table` is not complete).
MergeResult MergeShards(const std::vector<std::filesystem::path>& dirs);

/// The Slurm command that reruns only `missing` shards of `shard_count` with
/// scripts/sweep-slurm.sh, e.g. "sbatch --array=1,3-4 scripts/sweep-slurm.sh SWEEP DIR 5".
std::string SlurmRerunCommand(const std::vector<int>& missing, int shard_count,
                              const std::string& sweep_file, const std::string& out_dir);

}  // namespace leglab::experiments
