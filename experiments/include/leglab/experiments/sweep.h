#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/app/output_docs.h"
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

/// A sweep's identity: 16 hex digits of the FNV-1a 64 hash of its definition as loaded (the
/// swept keys, every point's index and values, and the base config merged with the sweep
/// file's other keys, as text). Two sweep files that run the same points have the same id.
/// Throws InputError when the base config is bad.
std::string SweepId(const SweepConfig& sweep);

/// A shard file's first line, naming the sweep and the shard it is:
/// "# sweep <SweepId> shard I of N, P points" (P: the whole sweep's points). Throws as SweepId.
std::string ShardStamp(const SweepConfig& sweep, const Shard& shard);

/// A sweep's table: a header and one CSV line per point (no newline), in index order.
struct SweepTable {
  /// A shard file's first line (ShardStamp), written before the header; empty for sweep.csv,
  /// which stays a plain CSV file.
  std::string stamp;
  std::string header;
  std::vector<std::string> rows;
  long not_ok = 0;  ///< rows whose status is not `ok`
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

/// Writes `table` (its stamp first, when set) to `path` atomically (a temporary file beside it,
/// then a rename): a reader never sees half a table. Throws std::runtime_error naming the file.
void WriteSweepTable(const SweepTable& table, const std::filesystem::path& path);

/// What merging shard files found.
struct MergeResult {
  SweepTable table;          ///< every row, in index order, when complete
  int shard_count = 0;       ///< N of the shards found
  std::vector<int> missing;  ///< shard indices without a file, ascending
};

/// Finds every sweep.shard-I-of-N.csv in `dirs` and joins their rows in index order: the same
/// bytes as the unsharded sweep.csv. Missing shards are reported in `missing` (then `table` is
/// not complete and no file is read). Otherwise every shard must be whole and of one sweep:
/// throws InputError naming the file (and the line and column) for no shard files, shards of
/// different N, a shard found twice, a stamp (ShardStamp) that is missing, is not the file
/// name's shard, or names another sweep than the other shards (or than `sweep`, when given),
/// another header, a row missing, extra or out of order (by its index), or a row that does
/// not parse against the header: another number of cells, a status `ok` with a result cell
/// that is not a finite number (model_source: `identified` or `given`), or a failed point
/// with result cells.
MergeResult MergeShards(const std::vector<std::filesystem::path>& dirs,
                        const SweepConfig* sweep = nullptr);

/// The Slurm command that reruns only `missing` shards of `shard_count` with
/// scripts/sweep_slurm.sh, e.g. "sbatch --array=1,3-4 scripts/sweep_slurm.sh SWEEP DIR 5".
std::string SlurmRerunCommand(const std::vector<int>& missing, int shard_count,
                              const std::string& sweep_file, const std::string& out_dir);

/// The columns of sweep.csv (and of each sweep.shard-I-of-N.csv), one row per point. Those
/// named with `<...>` are several, named when the sweep is read (ResultColumns).
inline constexpr std::array<ColumnDoc, 10> kSweepColumns{{
    {"index", "", "the point's index in the sweep's order, from 0"},
    {"<key>", "", "each swept key's value at the point (YAML text), in the sweep file's order"},
    {"status", "", "ok, or why the point could not run (bad input at that point)"},
    {"<mode>_<joint>_l2_deg", "deg", "each base mode's joint L2 distance (Table 2's mean)"},
    {"<mode>_foot_l2_cm", "cm", "each base mode's foot L2 distance"},
    {"<mode>_<parameter>", "", "a searched mode's chosen parameter (time_shift_k)"},
    {"floor_<joint>_l2_deg", "deg",
     "the floor's joint L2 distance (the best any controller can do)"},
    {"floor_foot_l2_cm", "cm", "the floor's foot L2 distance"},
    {"model_source", "", "where the controllers' models came from (identified, given)"},
    {"model_<joint>_<field>", "",
     "the models used: v_max_deg_per_tick, theta0_deg, lag_ticks, accel_ticks per joint"},
}};

/// What sweep writes: its `--list-outputs`.
std::span<const OutputDoc> SweepOutputs();

}  // namespace leglab::experiments
