#pragma once

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace leglab::experiments {

/// The results could not be written (a full disk, a folder that vanished): not bad input,
/// not a bug. Programs print it and exit with status 1.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The files a run writes, staged in a temporary folder and moved into `--out` only by
/// Commit(): a run that fails leaves the file system as it was (not even `--out`'s parent
/// folders are created). Destroying an uncommitted OutputDir removes the staging folder.
class OutputDir {
 public:
  /// Stages next to `final_dir` when its parent exists (so Commit() renames), else in the
  /// system's temporary folder. `owned_prefixes` name the files this program writes (e.g.
  /// "table2.", "trace_"): Commit() removes earlier ones from `final_dir`, so no stale output
  /// of a previous run sits beside the new one. Throws std::runtime_error if it cannot stage.
  OutputDir(std::filesystem::path final_dir, std::vector<std::string> owned_prefixes);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Where to write `name` (a plain file name) while staging.
  std::filesystem::path Path(const std::string& name) const;

  /// Creates `final_dir` (and its parents) if needed, removes its files that start with an
  /// owned prefix, and moves every staged file into it. Other files there are left alone.
  void Commit();

 private:
  std::filesystem::path final_dir_;
  std::vector<std::string> owned_prefixes_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

/// Writes `text` to `path`; throws OutputError naming the file if it cannot.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);

/// A CSV file with a fixed header. Numbers are written in the shortest form that reads back
/// to the same double. Close() reports a failed write.
class CsvWriter {
 public:
  /// Throws OutputError if `path` cannot be opened.
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns);
  /// One row: text cells (e.g. a joint name) are written as given.
  CsvWriter& Cell(double value);
  CsvWriter& Cell(long value);
  CsvWriter& Cell(const std::string& text);
  void EndRow();
  /// Flushes and closes; throws OutputError naming the file if any write failed.
  void Close();

 private:
  void Separator();
  std::filesystem::path path_;
  std::ofstream out_;
  size_t columns_;
  size_t in_row_ = 0;
};

/// Shortest round-trip text of a double.
std::string FormatDouble(double value);

}  // namespace leglab::experiments
