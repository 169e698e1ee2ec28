// What the tests that run a program as a user does share: a scratch folder per test, and a
// command run from the source tree with its output captured.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace leglab::testing {

/// The whole text of `path` ("" when it cannot be read).
inline std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A program's exit status (-1 when it did not exit) and what it printed.
struct ProgramResult {
  int status = -1;
  std::string stderr_text;
  std::string stdout_text;
};

/// A test with a scratch folder `dir_` of its own (the test's name and the process id: ctest
/// runs tests as parallel processes, and the release and sanitizer suites may run at once),
/// empty at the start and removed at the end.
class ScratchDirTest : public ::testing::Test {
 protected:
  explicit ScratchDirTest(std::string prefix) : prefix_(std::move(prefix)) {}

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (prefix_ + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
            std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Runs `command` (a shell command line) from the source tree, capturing its output.
  ProgramResult RunFromSourceTree(const std::string& command) const {
    const std::filesystem::path out = dir_ / "stdout";
    const std::filesystem::path err = dir_ / "stderr";
    const std::string full = "cd '" LEGLAB_SOURCE_DIR "' && " + command + " >'" + out.string() +
                             "' 2>'" + err.string() + "'";
    const int raw = std::system(full.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, ReadText(err), ReadText(out)};
  }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace leglab::testing
