#pragma once

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace leglab::experiments {

/// The files a run writes, staged in a temporary folder beside `--out` and moved into place
/// only by Commit(): a run that fails leaves `--out` as it was. Destroying an uncommitted
/// OutputDir removes the staging folder.
class OutputDir {
 public:
  /// Creates the staging folder next to `final_dir` (which need not exist yet).
  /// Throws std::runtime_error if it cannot.
  explicit OutputDir(std::filesystem::path final_dir);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Where to write `name` (a plain file name) while staging.
  std::filesystem::path Path(const std::string& name) const;

  /// Creates `final_dir` if needed and moves every staged file into it, replacing files of
  /// the same name; other files there are left alone.
  void Commit();

 private:
  std::filesystem::path final_dir_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

/// A CSV file with a fixed header. Numbers are written in the shortest form that reads back
/// to the same double.
class CsvWriter {
 public:
  /// Throws std::runtime_error if `path` cannot be opened.
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns);
  /// One row: text cells (e.g. a joint name) are written as given.
  CsvWriter& Cell(double value);
  CsvWriter& Cell(long value);
  CsvWriter& Cell(const std::string& text);
  void EndRow();

 private:
  void Separator();
  std::ofstream out_;
  size_t columns_;
  size_t in_row_ = 0;
};

/// Shortest round-trip text of a double.
std::string FormatDouble(double value);

}  // namespace leglab::experiments
