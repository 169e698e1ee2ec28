#include "leglab/experiments/output.h"

#include <unistd.h>

#include <cassert>
#include <charconv>
#include <stdexcept>
#include <system_error>

namespace leglab::experiments {

namespace fs = std::filesystem;

OutputDir::OutputDir(fs::path final_dir) : final_dir_(std::move(final_dir)) {
  fs::path parent = fs::absolute(final_dir_).parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  for (int attempt = 0;; ++attempt) {
    std::string name = final_dir_.filename().string();
    name.insert(0, 1, '.');
    name += ".staging-" + std::to_string(::getpid()) + "-" + std::to_string(attempt);
    staging_ = parent / name;
    if (fs::create_directory(staging_, ec)) break;
    if (ec || attempt > 100) {
      throw std::runtime_error("cannot create a staging folder in " + parent.string() + ": " +
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
  for (const auto& entry : fs::directory_iterator(staging_)) {
    fs::rename(entry.path(), final_dir_ / entry.path().filename());
  }
  committed_ = true;
}

std::string FormatDouble(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

CsvWriter::CsvWriter(const fs::path& path, const std::vector<std::string>& columns)
    : out_(path), columns_(columns.size()) {
  if (!out_) throw std::runtime_error("cannot write " + path.string());
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

}  // namespace leglab::experiments
