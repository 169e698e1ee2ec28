#pragma once

// Test helper: a copy of a shipped URDF with text edits, in a temporary file of the running
// test's own that is removed with the object.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace leglab::sim::testing {

/// The whole text of the file at `path` (empty when it cannot be read).
inline std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// (from, to) pairs: the first occurrence of each `from` is replaced by its `to`.
using Edits = std::vector<std::pair<std::string, std::string>>;

/// A copy of the URDF at `source` with `edits` applied (a `from` that is not found fails the
/// test), written to a temporary file named after the running test and this process.
class TempUrdf {
 public:
  TempUrdf(const std::string& source, const Edits& edits) {
    std::string text = ReadFile(source);
    for (const auto& [from, to] : edits) {
      const std::size_t at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) {
        text.replace(at, from.size(), to);
      }
    }
    std::string name = std::string("leglab_") +
                       ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
                       std::to_string(::getpid()) + ".urdf";
    std::replace(name.begin(), name.end(), '/', '_');  // parameterised tests: "Name/0"
    path_ = (std::filesystem::temp_directory_path() / name).string();
    std::ofstream(path_) << text;
  }
  TempUrdf(const std::string& source, const std::string& from, const std::string& to)
      : TempUrdf(source, Edits{{from, to}}) {}
  ~TempUrdf() { std::filesystem::remove(path_); }
  TempUrdf(const TempUrdf&) = delete;
  TempUrdf& operator=(const TempUrdf&) = delete;

  /// Where the edited copy is.
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace leglab::sim::testing
