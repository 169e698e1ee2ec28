#pragma once

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace leglab {

/// The results could not be written (a full disk, a folder that vanished): not bad input,
/// not a bug. Programs print it and exit with status 1.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The files a run writes, staged in a folder beside `--out` and moved into it only by
/// Commit(), all at once: `--out` holds either the previous results or the new ones, never a
/// mix. A run that fails leaves the file system as it was (not even `--out`'s parent folders
/// are created), and so does one interrupted by SIGINT, SIGTERM or SIGHUP once
/// InstallInterruptCleanup() has run. Destroying an uncommitted OutputDir removes the staging
/// folder.
///
/// One run at a time per `--out`: an OutputDir holds an advisory lock (flock) on the lock file
/// `.<name>.lock` beside `--out` from its construction until its commit or destruction, and a
/// second OutputDir on the same folder, in this process or another, is refused at construction.
/// When `--out`'s parent does not exist yet the lock file is in the temporary folder instead
/// (named after `--out`'s absolute path), and the commit, once it has created the parents,
/// takes the one beside `--out` before it moves the results in. The lock file is removed when the
/// lock is released (and by the interrupt clean-up), so a finished run leaves nothing beside
/// `--out`; one left by a killed process holds no lock and is taken over.
class OutputDir {
 public:
  /// Checks `final_dir` before anything runs and stages beside it (in its parent, or when that
  /// does not exist yet in the system's temporary folder). `owned_prefixes` name the files
  /// this program may write (e.g. "table2.", "trace_"): a folder of `final_dir` so named is
  /// refused before the run. The commit replaces exactly the files written this run, by full
  /// name, and keeps every other file and folder of `final_dir` (another program's results,
  /// the user's own files, an earlier run's outputs this one did not write).
  /// Throws InputError naming `--out` when it is empty, exists and is not a folder, holds a
  /// folder where this program writes a file, lies where nothing can be created, or is being
  /// written by another run ("--out '<out>' is being written by another run (process <pid>)").
  OutputDir(std::filesystem::path final_dir, std::vector<std::string> owned_prefixes);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  /// Where to write `name` (a plain file name) while staging.
  std::filesystem::path Path(const std::string& name) const;

  /// Makes the staged files `final_dir`'s: the files and folders of `final_dir` that this run
  /// did not write are linked (or moved, for folders) into the staging folder, which then
  /// replaces `final_dir` in one rename (renameat2 RENAME_EXCHANGE; where the file system
  /// lacks it, two renames with a moment in between where `final_dir` is missing). When
  /// `final_dir` is a mount point or holds one (a folder no rename can move), the staged files
  /// are renamed into it one by one instead, each whole, and nothing of it is moved. Creates
  /// `final_dir`'s parents if needed, and releases the lock. Throws OutputError if it cannot
  /// (also when, staged in the temporary folder, another run took the lock beside `final_dir`
  /// in the meantime).
  void Commit();

 private:
  // Commit's way for a `final_dir` that is or holds a mount point: the staged files renamed in
  // one by one (copied under a hidden name first across a mount), nothing of it moved.
  void CommitFileByFile();

  std::filesystem::path final_dir_;
  std::vector<std::string> owned_prefixes_;
  std::filesystem::path staging_;
  bool committed_ = false;
  // The lock file held (see the class comment) and its descriptor; -1 when none is held.
  std::filesystem::path lock_path_;
  int lock_fd_ = -1;
};

/// From now on SIGINT, SIGTERM and SIGHUP remove every staging folder of this process and exit
/// with status 128 + the signal, after printing "<program>: interrupted by signal N" on
/// stderr. The signals are blocked in the calling thread and waited for by a watcher thread
/// (sigwait), so the clean-up runs as ordinary code, never inside a signal handler, and a
/// commit in progress finishes first. Call it once, from main's thread before any other
/// thread starts (threads inherit the blocked signals).
void InstallInterruptCleanup(const std::string& program);

/// Checks `out` (--out) before a run: a folder, or a path where one can be made, that is not
/// the root, holds no non-file named like an `owned_prefixes` output, and can be written.
/// Returns it absolute and normalised. Throws InputError "--out '<out>' ..." otherwise.
std::filesystem::path CheckOutFolder(const std::filesystem::path& out,
                                     const std::vector<std::string>& owned_prefixes);

/// Writes `text` to `path`; throws OutputError naming the file if it cannot.
void WriteTextFile(const std::filesystem::path& path, const std::string& text);

/// Receives a table row by row, cell by cell: CsvWriter writes it to a file, ColumnTable keeps
/// it. A row has as many cells as the table has columns.
class RowSink {
 public:
  virtual ~RowSink() = default;
  /// The next cell of the current row: a number or a text (e.g. a joint name).
  virtual RowSink& Cell(double value) = 0;
  virtual RowSink& Cell(long value) = 0;
  virtual RowSink& Cell(const std::string& text) = 0;
  /// Ends the current row (it must have a cell in every column).
  virtual void EndRow() = 0;

 protected:
  // Copied and moved only as part of a derived sink (no slicing through a RowSink&).
  RowSink() = default;
  RowSink(const RowSink&) = default;
  RowSink(RowSink&&) = default;
  RowSink& operator=(const RowSink&) = default;
  RowSink& operator=(RowSink&&) = default;
};

/// A table kept in memory, column by column: the values a CsvWriter with the same columns would
/// write, before they are formatted.
struct ColumnTable final : RowSink {
  /// An empty table with these columns.
  explicit ColumnTable(std::vector<std::string> column_names);
  using Column = std::variant<std::vector<double>, std::vector<long>, std::vector<std::string>>;
  std::vector<std::string> names;
  /// One per name; a column holds the type of its first cell (a later cell of another type is a
  /// bug: assert).
  std::vector<Column> columns;

  ColumnTable& Cell(double value) override;
  ColumnTable& Cell(long value) override;
  ColumnTable& Cell(const std::string& text) override;
  void EndRow() override;
  /// The rows ended so far.
  size_t rows() const { return rows_; }

 private:
  template <typename T>
  ColumnTable& Append(T value);
  size_t in_row_ = 0;
  size_t rows_ = 0;
};

/// A CSV file with a fixed header. Numbers are written in the shortest form that reads back
/// to the same double. Close() reports a failed write.
class CsvWriter final : public RowSink {
 public:
  /// Throws OutputError if `path` cannot be opened. With `append`, rows go after those already
  /// in `path` and the header is written only when the file is new (several runs, one table).
  CsvWriter(const std::filesystem::path& path, const std::vector<std::string>& columns,
            bool append = false);
  /// Writes what is still buffered (as the stream's own destructor would flush it).
  ~CsvWriter() override;
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  /// One row: text cells (e.g. a joint name) are written as given.
  CsvWriter& Cell(double value) override;
  CsvWriter& Cell(long value) override;
  CsvWriter& Cell(const std::string& text) override;
  void EndRow() override;
  /// Flushes and closes; throws OutputError naming the file if any write failed.
  void Close();

 private:
  void Separator();
  void Flush();
  std::filesystem::path path_;
  std::ofstream out_;
  // Rows not yet handed to out_: formatting into one string and writing it in large pieces
  // costs a fraction of a stream insertion per cell.
  std::string pending_;
  size_t columns_;
  size_t in_row_ = 0;
};

/// Shortest round-trip text of a double (FormatNumber, kShortest).
std::string FormatDouble(double value);

}  // namespace leglab
