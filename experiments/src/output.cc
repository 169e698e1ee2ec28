#include "leglab/experiments/output.h"

#include <unistd.h>

#include <cassert>
#include <charconv>
#include <stdexcept>
#include <system_error>

namespace leglab::experiments {

namespace fs = std::filesystem;

OutputDir::OutputDir(fs::path final_dir, std::vector<std::string> owned_prefixes)
    : final_dir_(std::move(final_dir)), owned_prefixes_(std::move(owned_prefixes)) {
  const fs::path parent = fs::absolute(final_dir_).parent_path();
  std::error_code ec;
  // Beside --out a commit is a rename; with no parent yet, stage where creating leaves no trace.
  const fs::path where = fs::is_directory(parent, ec) ? parent : fs::temp_directory_path();
  for (int attempt = 0;; ++attempt) {
    std::string name = final_dir_.filename().string();
    name.insert(0, 1, '.');
    name += ".staging-" + std::to_string(::getpid()) + "-" + std::to_string(attempt);
    staging_ = where / name;
    if (fs::create_directory(staging_, ec)) break;
    if (ec || attempt > 100) {
      throw OutputError("cannot create a staging folder in " + where.string() + ": " +
                        (ec ? ec.message() : "too many attempts"));
    }
  }
}

OutputDir::~OutputDir() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

fs::path OutputDir::Path(const std::string& name) const { return staging_ / name; }

void OutputDir::Commit() {
  assert(!committed_);
  fs::create_directories(final_dir_);
  for (const auto& entry : fs::directory_iterator(final_dir_)) {
    const std::string name = entry.path().filename().string();
    for (const std::string& prefix : owned_prefixes_) {
      if (entry.is_regular_file() && name.rfind(prefix, 0) == 0) fs::remove(entry.path());
    }
  }
  for (const auto& entry : fs::directory_iterator(staging_)) {
    const fs::path target = final_dir_ / entry.path().filename();
    std::error_code ec;
    fs::rename(entry.path(), target, ec);
    if (ec) {  // staged on another file system: copy instead
      fs::copy_file(entry.path(), target, fs::copy_options::overwrite_existing);
    }
  }
  committed_ = true;
}

void WriteTextFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  out.close();
  if (!out) throw OutputError("cannot write " + path.string());
}

std::string FormatDouble(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

CsvWriter::CsvWriter(const fs::path& path, const std::vector<std::string>& columns)
    : path_(path), out_(path), columns_(columns.size()) {
  if (!out_) throw OutputError("cannot write " + path.string());
  for (const std::string& c : columns) Cell(c);
  EndRow();
}

void CsvWriter::Separator() {
  if (in_row_++ > 0) out_ << ',';
}

CsvWriter& CsvWriter::Cell(double value) {
  Separator();
  out_ << FormatDouble(value);
  return *this;
}

CsvWriter& CsvWriter::Cell(long value) {
  Separator();
  out_ << value;
  return *this;
}

CsvWriter& CsvWriter::Cell(const std::string& text) {
  Separator();
  out_ << text;
  return *this;
}

void CsvWriter::EndRow() {
  assert(in_row_ == columns_);
  out_ << '\n';
  in_row_ = 0;
}

void CsvWriter::Close() {
  out_.close();
  if (!out_) throw OutputError("cannot write " + path_.string());
}

}  // namespace leglab::experiments
