#include "leglab/app/output.h"

#include <gtest/gtest.h>

#include "leglab/app/input_error.h"

#include <sys/mount.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace leglab {
namespace {

namespace fs = std::filesystem;

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(OutputDir, NothingAppearsUntilCommit) {
  const fs::path out = fs::temp_directory_path() / "leglab_output_test";
  fs::remove_all(out);
  {
    OutputDir dir(out, {"a."});
    std::ofstream(dir.Path("a.txt")) << "a";
    EXPECT_FALSE(fs::exists(out));
  }  // not committed: the staging folder goes, --out never appears
  EXPECT_FALSE(fs::exists(out));
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    EXPECT_EQ(e.path().filename().string().find(".leglab_output_test.staging"), std::string::npos);
  }
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "keep";
  {
    OutputDir dir(out, {"a."});
    std::ofstream(dir.Path("a.txt")) << "new";
    dir.Commit();
  }
  EXPECT_EQ(Read(out / "a.txt"), "new");
  EXPECT_EQ(Read(out / "keep.txt"), "keep");
  fs::remove_all(out);
}

// The commit replaces the files this run wrote, by full name, and nothing else: not the user's
// files named like the program's outputs, nor an earlier run's output this run did not write.
TEST(OutputDir, ACommitReplacesExactlyTheFilesItWrote) {
  const fs::path out = fs::temp_directory_path() / "leglab_output_owned";
  fs::remove_all(out);
  fs::create_directories(out);
  std::ofstream(out / "trace_direct.csv") << "old";
  std::ofstream(out / "trace_model_based.csv") << "an earlier run's";
  std::ofstream(out / "trace_custom_mine.csv") << "the user's";
  std::ofstream(out / "table1.json") << "another program's";
  {
    OutputDir dir(out, {"trace_", "table2."});
    std::ofstream(dir.Path("trace_direct.csv")) << "new";
    dir.Commit();
  }
  EXPECT_EQ(Read(out / "trace_direct.csv"), "new");
  EXPECT_EQ(Read(out / "trace_model_based.csv"), "an earlier run's");
  EXPECT_EQ(Read(out / "trace_custom_mine.csv"), "the user's");
  EXPECT_EQ(Read(out / "table1.json"), "another program's");
  fs::remove_all(out);
}

TEST(OutputDir, AFailedRunCreatesNoParentFolders) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_nested";
  fs::remove_all(root);
  { OutputDir dir(root / "a" / "b" / "out", {}); }  // not committed
  EXPECT_FALSE(fs::exists(root));
  {
    OutputDir dir(root / "a" / "b" / "out", {});
    std::ofstream(dir.Path("x.txt")) << "x";
    dir.Commit();  // staged in the temporary folder, copied or renamed into place
  }
  EXPECT_EQ(Read(root / "a" / "b" / "out" / "x.txt"), "x");
  fs::remove_all(root);
}

TEST(OutputDir, ACommitSwapsInTheNewFilesAndKeepsTheRest) {
  const fs::path out = fs::temp_directory_path() / "leglab_output_swap";
  fs::remove_all(out);
  fs::create_directories(out / "hind");
  std::ofstream(out / "hind" / "table2.md") << "hind";
  std::ofstream(out / "table1.json") << "identify's";
  std::ofstream(out / "table2.md") << "old";
  fs::create_symlink("table1.json", out / "latest.json");
  {
    OutputDir dir(out, {"table2."});
    std::ofstream(dir.Path("table2.md")) << "new";
    EXPECT_EQ(Read(out / "table2.md"), "old");  // nothing changes before the commit
    dir.Commit();
  }
  EXPECT_EQ(Read(out / "table2.md"), "new");
  EXPECT_EQ(Read(out / "table1.json"), "identify's");
  EXPECT_EQ(Read(out / "hind" / "table2.md"), "hind");
  EXPECT_EQ(fs::read_symlink(out / "latest.json"), "table1.json");
  for (const auto& e : fs::directory_iterator(out.parent_path())) {
    EXPECT_EQ(e.path().filename().string().find(".leglab_output_swap.staging"), std::string::npos);
  }
  fs::remove_all(out);
}

TEST(OutputDir, OutProblemsAreBadInput) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_bad";
  fs::remove_all(root);
  fs::create_directories(root / "out" / "table2.md");
  std::ofstream(root / "file") << "x";
  EXPECT_THROW(OutputDir("", {}), InputError);
  EXPECT_THROW(OutputDir(root / "file", {}), InputError);
  EXPECT_THROW(OutputDir(root / "file" / "out", {}), InputError);
  EXPECT_THROW(OutputDir(root / "out", {"table2."}), InputError);
  EXPECT_NO_THROW(OutputDir(root / "out", {"trace_"}));
  fs::remove_all(root);
}

// What constructing an OutputDir on `out` throws as InputError ("" if it does not).
std::string Refusal(const fs::path& out) {
  try {
    OutputDir dir(out, {"a."});
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A link that leads nowhere is refused before the run: dangling, a loop, or a loop on the way.
TEST(OutputDir, ADanglingOrLoopingLinkIsRefusedAtOnce) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_links";
  fs::remove_all(root);
  fs::create_directories(root / "real");
  fs::create_symlink(root / "nowhere" / "out", root / "dangling");
  fs::create_symlink(root / "loop_b", root / "loop_a");
  fs::create_symlink(root / "loop_a", root / "loop_b");
  fs::create_symlink(root / "real", root / "to_real");
  EXPECT_EQ(Refusal(root / "dangling")
                .rfind("--out '" + (root / "dangling").string() + "' is a symbolic link to '" +
                           (root / "nowhere" / "out").string() + "', which cannot be followed",
                       0),
            0u)
      << Refusal(root / "dangling");
  EXPECT_NE(Refusal(root / "loop_a").find("is a loop of symbolic links"), std::string::npos)
      << Refusal(root / "loop_a");
  EXPECT_NE(Refusal(root / "loop_a" / "out").find("cannot be looked up"), std::string::npos)
      << Refusal(root / "loop_a" / "out");
  EXPECT_EQ(Refusal(root / "to_real"), "");  // a link to a folder is fine
  EXPECT_FALSE(fs::exists(root / "nowhere"));
  fs::remove_all(root);
}

// The names in `folder`.
std::vector<std::string> Names(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

// One run at a time per --out: a second OutputDir on the same folder is refused, naming --out and
// this process, while the first lives and has not committed; a folder beside it is not locked.
TEST(OutputDir, ASecondRunIntoTheSameOutIsRefusedUntilTheFirstCommits) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_lock";
  fs::remove_all(root);
  fs::create_directories(root);
  const fs::path out = root / "out";
  const std::string expected = "--out '" + out.string() +
                               "' is being written by another run (process " +
                               std::to_string(::getpid()) + ")";
  {
    OutputDir first(out, {"a."});
    std::ofstream(first.Path("a.txt")) << "first";
    EXPECT_EQ(Refusal(out).rfind(expected, 0), 0U) << Refusal(out);
    // The same folder by another path: refused, named as given.
    EXPECT_EQ(Refusal(root / "." / "out")
                  .rfind("--out '" + (root / "." / "out").string() + "' is being written", 0),
              0U);
    EXPECT_EQ(Refusal(root / "other"), "");
    first.Commit();
    EXPECT_EQ(Refusal(out), "");  // committed: free while `first` still exists
  }
  {
    OutputDir first(out, {"a."});
    EXPECT_NE(Refusal(out), "");
  }  // destroyed without a commit: free again
  {
    OutputDir second(out, {"a."});
    std::ofstream(second.Path("a.txt")) << "second";
    second.Commit();
  }
  EXPECT_EQ(Read(out / "a.txt"), "second");
  EXPECT_EQ(Names(root), std::vector<std::string>{"out"});  // no lock file left beside --out
  // The lock file of a killed run (nobody holds it): taken over, then removed.
  std::ofstream(root / ".out.lock") << "999999\n";
  EXPECT_EQ(Refusal(out), "");
  EXPECT_EQ(Names(root), std::vector<std::string>{"out"});
  fs::remove_all(root);
}

// With no parent folder yet the lock is in the temporary folder; a run that starts once the
// parent exists locks beside --out, and then the earlier run's commit is refused, not a silent
// overwrite.
TEST(OutputDir, ARunWithoutAParentFolderYetIsLockedToo) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_lock_nested";
  fs::remove_all(root);
  const fs::path out = root / "a" / "out";
  {
    OutputDir early(out, {"a."});
    EXPECT_NE(Refusal(out).find("is being written by another run"), std::string::npos);
    std::ofstream(early.Path("a.txt")) << "early";
    fs::create_directories(root / "a");
    OutputDir late(out, {"a."});
    std::ofstream(late.Path("a.txt")) << "late";
    EXPECT_THROW(early.Commit(), OutputError);
    late.Commit();
  }
  EXPECT_EQ(Read(out / "a.txt"), "late");
  EXPECT_EQ(Names(root / "a"), std::vector<std::string>{"out"});
  fs::remove_all(root);
  {
    OutputDir only(out, {"a."});
    std::ofstream(only.Path("a.txt")) << "only";
    only.Commit();
    EXPECT_EQ(Refusal(out), "");
  }
  EXPECT_EQ(Read(out / "a.txt"), "only");
  EXPECT_EQ(Names(root / "a"), std::vector<std::string>{"out"});
  fs::remove_all(root);
}

// A file system mounted inside --out, or --out a mount point itself: no rename can move a
// mount point, so the commit puts the new files in one by one and leaves --out's folders
// where they are, the mounted one with the user's file in it; no staging folder is left.
// Needs the right to mount (root in a container that allows it); skipped where there is none.
TEST(OutputDir, MountPointsInsideOutStayWhereTheyAre) {
  const fs::path root = fs::temp_directory_path() / "leglab_output_mount";
  ::umount((root / "out" / "mounted").c_str());  // left by a failed run of this test, if any
  fs::remove_all(root);
  fs::create_directories(root / "out" / "mounted");
  fs::create_directories(root / "out" / "plain");
  if (::mount("none", (root / "out" / "mounted").c_str(), "tmpfs", 0, nullptr) != 0) {
    fs::remove_all(root);
    GTEST_SKIP() << "cannot mount a tmpfs here";
  }
  std::ofstream(root / "out" / "mounted" / "mine.txt") << "the user's";
  std::ofstream(root / "out" / "plain" / "notes.txt") << "notes";
  std::ofstream(root / "out" / "table2.md") << "old";
  for (const fs::path& out : {root / "out", root / "out" / "mounted"}) {
    OutputDir dir(out, {"table2."});
    std::ofstream(dir.Path("table2.md")) << "new " + out.filename().string();
    std::ofstream(dir.Path("table2.json")) << "{}";
    dir.Commit();
    EXPECT_EQ(Read(out / "table2.md"), "new " + out.filename().string());
    EXPECT_EQ(Read(out / "table2.json"), "{}");
  }
  EXPECT_EQ(Read(root / "out" / "mounted" / "mine.txt"), "the user's");
  EXPECT_EQ(Read(root / "out" / "plain" / "notes.txt"), "notes");
  for (const fs::path& folder : {root, root / "out"}) {
    for (const auto& e : fs::directory_iterator(folder)) {
      EXPECT_EQ(e.path().filename().string().find("staging"), std::string::npos) << e.path();
    }
  }
  // Mounted read-only, the folder is refused before anything runs, and nothing is left.
  ASSERT_EQ(
      ::mount("none", (root / "out" / "mounted").c_str(), nullptr, MS_REMOUNT | MS_RDONLY, nullptr),
      0);
  try {
    OutputDir refused(root / "out" / "mounted", {"table2."});
    ADD_FAILURE() << "a read-only --out was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be written: Read-only file system"),
              std::string::npos)
        << e.what();
  }
  for (const auto& e : fs::directory_iterator(root / "out")) {
    EXPECT_EQ(e.path().filename().string().find("staging"), std::string::npos) << e.path();
  }
  EXPECT_EQ(::umount((root / "out" / "mounted").c_str()), 0);
  fs::remove_all(root);
}

// A disk that fills while the run writes: the write fails (OutputError, exit 1 in a program)
// and no staging folder is left; the user's file in --out is untouched. Skipped where nothing
// can be mounted.
TEST(OutputDir, AFullDiskLeavesNothingBehind) {
  const fs::path disk = fs::temp_directory_path() / "leglab_output_full";
  ::umount(disk.c_str());  // left by a failed run of this test, if any
  fs::remove_all(disk);
  fs::create_directories(disk);
  if (::mount("none", disk.c_str(), "tmpfs", 0, "size=64k") != 0) {
    fs::remove_all(disk);
    GTEST_SKIP() << "cannot mount a tmpfs here";
  }
  fs::create_directories(disk / "out");
  std::ofstream(disk / "out" / "mine.txt") << "the user's";
  EXPECT_THROW(
      {
        OutputDir dir(disk / "out", {"trace_"});
        CsvWriter csv(dir.Path("trace_big.csv"), {"x"});
        for (int i = 0; i < 100000; ++i) csv.Cell(static_cast<double>(i) + 0.125).EndRow();
        csv.Close();
        dir.Commit();
      },
      OutputError);
  EXPECT_EQ(Read(disk / "out" / "mine.txt"), "the user's");
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(disk)) left.push_back(e.path().filename());
  EXPECT_EQ(left, std::vector<std::string>{"out"});
  EXPECT_FALSE(fs::exists(disk / "out" / "trace_big.csv"));
  EXPECT_EQ(::umount(disk.c_str()), 0);
  fs::remove_all(disk);
}

TEST(Csv, ShortestRoundTripNumbers) {
  EXPECT_EQ(FormatDouble(0.1), "0.1");
  EXPECT_EQ(FormatDouble(2.5), "2.5");
  EXPECT_EQ(FormatDouble(-40.0), "-40");
  const double third = 1.0 / 3.0;
  EXPECT_EQ(std::stod(FormatDouble(third)), third);
  const fs::path p = fs::temp_directory_path() / "leglab_csv_test.csv";
  {
    CsvWriter csv(p, {"tick", "joint", "value"});
    csv.Cell(3L).Cell(std::string("knee")).Cell(0.25);
    csv.EndRow();
    csv.Close();
  }
  EXPECT_EQ(Read(p), "tick,joint,value\n3,knee,0.25\n");
  fs::remove(p);
}

}  // namespace
}  // namespace leglab
