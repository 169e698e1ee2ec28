// Sweeps: the points a sweep file describes, shards and their merge, and the sweep program's
// contract (bad sweep files are exit 2 with nothing written; a bad point is its row's status).
#include "leglab/experiments/sweep.h"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "leglab/sim/sim_config.h"

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

const std::string kConfigs = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
const std::string kSweepBin = LEGLAB_SWEEP_BIN;
// Run as if outside any job array, even when the tests run inside one.
const std::string kNoJobArray =
    "env -u SLURM_ARRAY_TASK_ID -u SLURM_ARRAY_TASK_COUNT -u JOB_COMPLETION_INDEX ";

// A fast base: the ideal plant with a given model (no identification), two measured steps.
const std::string kFastBase =
    "base: " + kConfigs + "track.yaml\n" +
    "plant: model\n"
    "model: {v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}\n"
    "controller: {modes: [direct, time_shift, model_based]}\n"
    "warmup_steps: 2\n"
    "steps: 2\n";

class SweepTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("leglab_sweep_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }

  // Runs the sweep program with `args`; returns its exit status and standard error.
  std::pair<int, std::string> Sweep(const std::string& args) const {
    const fs::path err = dir_ / "stderr.txt";
    const std::string command =
        kNoJobArray + kSweepBin + " " + args + " >/dev/null 2>'" + err.string() + "'";
    const int raw = std::system(command.c_str());
    std::stringstream text;
    text << std::ifstream(err).rdbuf();
    fs::remove(err);
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text.str()};
  }

  // Expects exit status 2 with one line naming `needle`, and `out` not created.
  void ExpectBadInput(const std::string& args, const fs::path& out, const std::string& needle) {
    const auto [status, err] = Sweep(args);
    EXPECT_EQ(status, 2) << args << "\n" << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find(needle), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }

  fs::path dir_;
};

std::string ReadFile(const fs::path& path) {
  std::stringstream s;
  s << std::ifstream(path, std::ios::binary).rdbuf();
  return s.str();
}

// The grid is the cartesian product in odometer order (last key fastest), counted by hand.
TEST_F(SweepTest, AGridIsTheCartesianProductLastKeyFastest) {
  const SweepConfig sweep =
      LoadSweepConfig(Write("grid.yaml", kFastBase + "grid:\n  servo.delay_ms: [32, 48]\n"
                                                     "  track.t_step_ticks: [60, 88, 100]\n"));
  ASSERT_EQ(sweep.keys, (std::vector<std::string>{"servo.delay_ms", "track.t_step_ticks"}));
  const std::vector<std::vector<std::string>> expected = {
      {"32", "60"}, {"32", "88"}, {"32", "100"}, {"48", "60"}, {"48", "88"}, {"48", "100"}};
  ASSERT_EQ(sweep.points.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(sweep.points[i].index, static_cast<long>(i));
    EXPECT_EQ(sweep.points[i].values, expected[i]) << i;
  }
  // The file's other keys become leaf overrides (a deep merge), before the point's keys.
  const std::vector<std::string> overrides = sweep.PointOverrides(sweep.points[4]);
  EXPECT_EQ(overrides.back(), "track.t_step_ticks=88");
  EXPECT_NE(std::find(overrides.begin(), overrides.end(), "model.lag_ticks=4"), overrides.end());
  EXPECT_NE(std::find(overrides.begin(), overrides.end(), "steps=2"), overrides.end());
}

// A sample: count points, each value inside its range, integers when the range is written in
// integers, the same points for the same seed and others for another seed.
TEST_F(SweepTest, ASampleIsSeededAndInsideItsRanges) {
  auto sample = [&](int seed) {
    return LoadSweepConfig(
        Write("sample.yaml", kFastBase + "sample:\n  count: 200\n  seed: " + std::to_string(seed) +
                                 "\n  keys:\n"
                                 "    servo.max_speed_deg_s: {min: 187.5, max: 437.5}\n"
                                 "    servo.delay_ms: {min: 24, max: 72}\n"));
  };
  const SweepConfig a = sample(7), b = sample(7), c = sample(8);
  ASSERT_EQ(a.points.size(), 200u);
  std::set<std::string> delays;
  for (const SweepPoint& p : a.points) {
    const double speed = std::stod(p.values[0]);
    EXPECT_GE(speed, 187.5);
    EXPECT_LE(speed, 437.5);
    const long delay = std::stol(p.values[1]);
    EXPECT_EQ(std::to_string(delay), p.values[1]);  // an integer, written as one
    EXPECT_GE(delay, 24);
    EXPECT_LE(delay, 72);
    delays.insert(p.values[1]);
  }
  // 200 draws over 49 integers: both ends appear (chance of missing one < 200 * (48/49)^200).
  EXPECT_TRUE(delays.count("24") && delays.count("72"));
  for (size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i].values, b.points[i].values);
  int same = 0;
  for (size_t i = 0; i < a.points.size(); ++i) same += a.points[i].values == c.points[i].values;
  EXPECT_LT(same, 5);
}

// A sampled key with step: only min + k step (k = 0, 1, ...; max too when it is on that
// lattice, to rounding), drawn uniformly: servo.delay_ms by the control tick's 8 ms, written as
// integers, and a decimal step whose max is off by rounding ((0.5 - 0.1) / 0.1 = 3.999...). Over
// 700 draws each of 7 delays is expected 100 times (binomial sd 9.3): each within 60..140, and
// each of 5 fractions 140 times (sd 10.6): within 90..190.
TEST_F(SweepTest, ASteppedSampleDrawsOnlyItsLattice) {
  const SweepConfig sweep = LoadSweepConfig(Write(
      "stepped.yaml", kFastBase +
                          "sample:\n  count: 700\n  seed: 3\n  keys:\n"
                          "    servo.delay_ms: {min: 24, max: 72, step: 8}\n"
                          "    optimal.request_smoothing: {min: 0.1, max: 0.5, step: 0.1}\n"));
  ASSERT_EQ(sweep.points.size(), 700u);
  std::map<std::string, int> delays, fractions;
  for (const SweepPoint& p : sweep.points) {
    ++delays[p.values[0]];
    ++fractions[p.values[1]];
  }
  const std::map<std::string, int> expected_delays = {{"24", 0}, {"32", 0}, {"40", 0}, {"48", 0},
                                                      {"56", 0}, {"64", 0}, {"72", 0}};
  ASSERT_EQ(delays.size(), expected_delays.size());
  for (const auto& [value, count] : delays) {
    EXPECT_TRUE(expected_delays.count(value)) << value;
    EXPECT_GT(count, 60) << value;
    EXPECT_LT(count, 140) << value;
  }
  ASSERT_EQ(fractions.size(), 5u);
  for (const auto& [value, count] : fractions) {
    EXPECT_TRUE(value == "0.1" || value == "0.2" || value == "0.3" || value == "0.4" ||
                value == "0.5")
        << value;  // as written, not 0.30000000000000004
    EXPECT_GT(count, 90) << value;
    EXPECT_LT(count, 190) << value;
  }
  // Without step the same file draws other values: step is what makes the lattice.
  const SweepConfig plain =
      LoadSweepConfig(Write("plain.yaml", kFastBase + "sample:\n  count: 700\n  seed: 3\n  keys:\n"
                                                      "    servo.delay_ms: {min: 24, max: 72}\n"));
  std::set<std::string> plain_delays;
  for (const SweepPoint& p : plain.points) plain_delays.insert(p.values[0]);
  EXPECT_GT(plain_delays.size(), 7u);
}

TEST(Shard, ParsesIOfNAndRejectsTheRest) {
  EXPECT_EQ(ParseShard("0/1"), (Shard{0, 1}));
  EXPECT_EQ(ParseShard("2/3"), (Shard{2, 3}));
  for (const char* bad : {"3/2", "0/0", "2/2", "-1/2", "1", "a/b", "1/", "/2", "1/2/3", " 1/2"}) {
    EXPECT_THROW(ParseShard(bad), InputError) << bad;
  }
}

TEST(Shard, ComesFromSlurmOrKubernetesWhenNoFlagIsGiven) {
  auto env = [](const std::map<std::string, std::string>& vars) {
    return [vars](const char* name) -> const char* {
      const auto it = vars.find(name);
      return it == vars.end() ? nullptr : it->second.c_str();
    };
  };
  EXPECT_EQ(ShardFromEnvironment(env({}), std::nullopt), std::nullopt);
  EXPECT_EQ(ShardFromEnvironment(
                env({{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_COUNT", "8"}}), std::nullopt),
            (Shard{3, 8}));
  // A rerun of missing shards (--array=3,7) has a task count of 2: --shards gives the real N.
  EXPECT_EQ(
      ShardFromEnvironment(env({{"SLURM_ARRAY_TASK_ID", "7"}, {"SLURM_ARRAY_TASK_COUNT", "2"}}), 8),
      (Shard{7, 8}));
  EXPECT_EQ(ShardFromEnvironment(env({{"JOB_COMPLETION_INDEX", "4"}}), 5), (Shard{4, 5}));
  EXPECT_THROW(ShardFromEnvironment(env({{"JOB_COMPLETION_INDEX", "4"}}), std::nullopt),
               InputError);
  EXPECT_THROW(ShardFromEnvironment(env({{"JOB_COMPLETION_INDEX", "5"}}), 5), InputError);
  EXPECT_THROW(
      ShardFromEnvironment(env({{"SLURM_ARRAY_TASK_ID", "x"}, {"SLURM_ARRAY_TASK_COUNT", "8"}}),
                           std::nullopt),
      InputError);
}

TEST(Shard, TheRerunCommandNamesOnlyTheMissingShards) {
  EXPECT_EQ(SlurmRerunCommand({1, 3, 4, 5, 9}, 10, "s.yaml", "out"),
            "sbatch --array=1,3-5,9 scripts/sweep_slurm.sh s.yaml out 10");
}

// Every split of a sweep into N = 1..points+1 shards merges into the unsharded table byte for
// byte (files written and read back as the programs do).
TEST_F(SweepTest, AnySplitIntoShardsMergesIntoTheUnshardedTable) {
  const SweepConfig sweep = LoadSweepConfig(Write(
      "s.yaml", kFastBase + "grid:\n  servo.delay_ms: [32]\n  track.t_step_ticks: [40, 3, 64]\n"
                            "  controller.pwl_segments: [4, 8]\n"));
  const long points = static_cast<long>(sweep.points.size());
  ASSERT_EQ(points, 6);
  const SweepTable whole = RunSweep(sweep, Shard{}, 2);
  EXPECT_EQ(whole.not_ok, 2);  // t_step 3 is below the minimum of 4, at both segment counts
  WriteSweepTable(whole, dir_ / "sweep.csv");
  const std::string expected = ReadFile(dir_ / "sweep.csv");
  for (int n = 1; n <= points + 1; ++n) {
    const fs::path shards = dir_ / ("n" + std::to_string(n));
    fs::create_directories(shards);
    for (int i = 0; i < n; ++i) {
      const Shard shard{i, n};
      SweepTable table = RunSweep(sweep, shard, 1);
      table.stamp = ShardStamp(sweep, shard);
      WriteSweepTable(table, shards / ShardFileName(shard));
    }
    const MergeResult merged = MergeShards({shards}, &sweep);
    ASSERT_TRUE(merged.missing.empty());
    EXPECT_EQ(merged.table.not_ok, 2);
    WriteSweepTable(merged.table, shards / "sweep.csv");
    EXPECT_EQ(ReadFile(shards / "sweep.csv"), expected) << n << " shards";
  }
}

// A bad value at one point is that row's status, naming the key; the other points run.
TEST_F(SweepTest, ABadValueIsItsPointsStatusNotTheSweeps) {
  const SweepConfig sweep =
      LoadSweepConfig(Write("s.yaml", kFastBase + "grid:\n  servo.delay_ms: [32, -8, 48]\n"));
  const SweepTable table = RunSweep(sweep, Shard{}, 2);
  ASSERT_EQ(table.rows.size(), 3u);
  EXPECT_EQ(table.not_ok, 1);
  EXPECT_EQ(table.rows[0].rfind("0,32,ok,", 0), 0u) << table.rows[0];
  EXPECT_EQ(table.rows[2].rfind("2,48,ok,", 0), 0u) << table.rows[2];
  EXPECT_EQ(table.rows[1].rfind("1,-8,", 0), 0u) << table.rows[1];
  EXPECT_NE(table.rows[1].find("delay_ms"), std::string::npos) << table.rows[1];
}

// A sweep over `urdf` with one broken robot among good ones: that point's status says why (the
// link and the field), and the good points' rows are whole and equal (the same robot).
TEST_F(SweepTest, ABrokenRobotIsItsPointsStatus) {
  const std::string good = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";
  std::string urdf = ReadFile(good);
  const std::string mass = "<mass value=\"0.073\"";
  ASSERT_NE(urdf.find(mass), std::string::npos);
  urdf.replace(urdf.find(mass), mass.size(), "<mass value=\"1e-30\"");
  const std::string bad = Write("bad.urdf", urdf);
  const SweepConfig sweep = LoadSweepConfig(
      Write("s.yaml", kFastBase + "grid:\n  urdf: [" + good + ", " + bad + ", " + good + "]\n"));
  const SweepTable table = RunSweep(sweep, Shard{}, 2);
  ASSERT_EQ(table.rows.size(), 3u);
  EXPECT_EQ(table.not_ok, 1);
  EXPECT_NE(table.rows[1].find("link 'upper_leg' mass must be in"), std::string::npos)
      << table.rows[1];
  const auto results = [](const std::string& row) { return row.substr(row.find(",ok,")); };
  ASSERT_NE(table.rows[0].find(",ok,"), std::string::npos) << table.rows[0];
  ASSERT_NE(table.rows[2].find(",ok,"), std::string::npos) << table.rows[2];
  EXPECT_EQ(results(table.rows[0]), results(table.rows[2]));
}

// A point whose simulation breaks down (settings each in range: a leg with a shin reaching
// 0.5 m comes apart mid-walk at 2000 deg/s) is that point's status; the other points' rows are
// whole and their own.
// A cycle of 88 joint-angle rows (a gentle wave inside every joint limit) for desired.csv.
std::string WaveCsv() {
  std::ostringstream csv;
  csv << "tick,rotator_deg,abductor_deg,knee_deg\n";
  for (int t = 0; t < 88; ++t) {
    csv << t << "," << 10 + 20 * std::sin(2 * M_PI * t / 88) << ",5,"
        << 60 + 15 * std::cos(2 * M_PI * t / 88) << "\n";
  }
  return csv.str();
}

// The front leg with its shin 0.5 m long, which ODE's hinges cannot hold at high speeds.
std::string LongShinUrdf() {
  std::string urdf = ReadFile(std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{R"(<origin xyz="-0.011001 0 -0.038457")",
                                            R"(<origin xyz="-0.011001 0 -0.3")"},
        {R"(<origin xyz="-0.01888 0 -0.066")", R"(<origin xyz="-0.01888 0 -0.5")"}}) {
    EXPECT_NE(urdf.find(from), std::string::npos) << from;
    if (urdf.find(from) != std::string::npos) urdf.replace(urdf.find(from), from.size(), to);
  }
  return urdf;
}

// A sweep of the long-shinned leg walking a gentle wave with a given model at gain 1000.
std::string LongShinSweep(const std::string& urdf_path, const std::string& wave_path,
                          const std::string& grid) {
  return "base: " + kConfigs + "track.yaml\n" + "urdf: " + urdf_path +
         "\ndesired: {csv: " + wave_path +
         "}\nmodel: {v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}\n"
         "controller: {modes: [direct]}\n"
         "warmup_steps: 1\n"
         "steps: 2\n"
         "servo: {gain_per_s: 1000}\n"
         "grid:\n" +
         grid;
}

TEST_F(SweepTest, ASimulationBreakdownIsItsPointsStatus) {
  const SweepConfig sweep = LoadSweepConfig(Write(
      "s.yaml", LongShinSweep(Write("long_shin.urdf", LongShinUrdf()), Write("wave.csv", WaveCsv()),
                              "  servo.max_speed_deg_s: [1000, 2000, 1000]\n")));
  const SweepTable table = RunSweep(sweep, Shard{}, 2);
  ASSERT_EQ(table.rows.size(), 3u);
  EXPECT_EQ(table.not_ok, 1);
  EXPECT_EQ(table.rows[1].rfind("1,2000,\"the simulation broke down under these settings "
                                "(servo.max_speed_deg_s 2000, servo.gain_per_s 1000, ",
                                0),
            0u)
      << table.rows[1];
  const auto results = [](const std::string& row) { return row.substr(row.find(",ok,")); };
  ASSERT_NE(table.rows[0].find(",ok,"), std::string::npos) << table.rows[0];
  ASSERT_NE(table.rows[2].find(",ok,"), std::string::npos) << table.rows[2];
  EXPECT_EQ(results(table.rows[0]), results(table.rows[2]));
}

// A sweep over the engine: at 2000 deg/s the long shin comes apart on ODE (its point's status)
// and walks on DART, whose joints cannot open.
TEST_F(SweepTest, OverTheEngine) {
  if (!sim::BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  const SweepConfig sweep = LoadSweepConfig(
      Write("s.yaml", LongShinSweep(Write("long_shin.urdf", LongShinUrdf()),
                                    Write("wave.csv", WaveCsv()), "  sim.engine: [ode, dart]\n") +
                          "servo.max_speed_deg_s: 2000\n"));
  const SweepTable table = RunSweep(sweep, Shard{}, 2);
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.not_ok, 1);
  EXPECT_EQ(table.rows[0].rfind("0,ode,\"the simulation broke down under these settings "
                                "(servo.max_speed_deg_s 2000, ",
                                0),
            0u)
      << table.rows[0];
  EXPECT_EQ(table.rows[1].rfind("1,dart,ok,", 0), 0u) << table.rows[1];
}

// The sweep program: shards written where asked, merged into sweep.csv byte for byte; missing
// shards named with the command that reruns them.
TEST_F(SweepTest, TheProgramShardsAndMerges) {
  const std::string file =
      Write("s.yaml", kFastBase + "grid:\n  track.t_step_ticks: [48, 64, 80, 96, 112]\n");
  const fs::path whole = dir_ / "whole", parts = dir_ / "parts", merged = dir_ / "merged";
  ASSERT_EQ(Sweep("--config " + file + " --out " + whole.string() + " --threads 2").first, 0);
  ASSERT_TRUE(fs::exists(whole / "sweep.csv"));
  for (int i : {0, 2}) {
    ASSERT_EQ(Sweep("--config " + file + " --out " + parts.string() + " --shard " +
                    std::to_string(i) + "/3")
                  .first,
              0);
  }
  const auto [missing_status, missing_err] =
      Sweep("merge " + parts.string() + " --out " + merged.string() + " --config " + file);
  EXPECT_EQ(missing_status, 2) << missing_err;
  EXPECT_NE(missing_err.find("sweep.shard-1-of-3.csv"), std::string::npos) << missing_err;
  EXPECT_NE(missing_err.find("sbatch --array=1 scripts/sweep_slurm.sh " + file), std::string::npos)
      << missing_err;
  EXPECT_FALSE(fs::exists(merged));
  // The missing shard from a Slurm job array's environment.
  const std::string slurm = "SLURM_ARRAY_TASK_ID=1 SLURM_ARRAY_TASK_COUNT=3 ";
  const int raw = std::system((kNoJobArray + slurm + kSweepBin + " --quiet --config " + file +
                               " --out " + parts.string() + " 2>/dev/null")
                                  .c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0);
  ASSERT_EQ(
      Sweep("merge " + parts.string() + " --out " + merged.string() + " --config " + file).first,
      0);
  EXPECT_EQ(ReadFile(merged / "sweep.csv"), ReadFile(whole / "sweep.csv"));
}

// A shard file's first line names its sweep and shard; sweep.csv stays a plain CSV file. The
// id is FNV-1a 64 of the definition: the same file elsewhere gives the same id, another grid
// or another base key another.
TEST_F(SweepTest, AShardNamesItsSweepOnItsFirstLine) {
  const std::string grid = "grid:\n  track.t_step_ticks: [48, 64, 80]\n";
  const SweepConfig sweep = LoadSweepConfig(Write("a.yaml", kFastBase + grid));
  const std::string id = SweepId(sweep);
  ASSERT_EQ(id.size(), 16u);
  EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
  EXPECT_EQ(ShardStamp(sweep, Shard{1, 2}), "# sweep " + id + " shard 1 of 2, 3 points");
  EXPECT_EQ(SweepId(LoadSweepConfig(Write("same.yaml", kFastBase + grid))), id);
  EXPECT_NE(SweepId(LoadSweepConfig(
                Write("grid.yaml", kFastBase + "grid:\n  track.t_step_ticks: [48, 64, 88]\n"))),
            id);
  EXPECT_NE(SweepId(LoadSweepConfig(Write("base.yaml", kFastBase + "seed: 9\n" + grid))), id);
  const fs::path out = dir_ / "out";
  ASSERT_EQ(
      Sweep("--config " + (dir_ / "a.yaml").string() + " --out " + out.string() + " --shard 1/2")
          .first,
      0);
  EXPECT_EQ(ReadFile(out / "sweep.shard-1-of-2.csv")
                .rfind(ShardStamp(sweep, Shard{1, 2}) + "\nindex,track.t_step_ticks,status,", 0),
            0u);
  ASSERT_EQ(Sweep("--config " + (dir_ / "a.yaml").string() + " --out " + out.string()).first, 0);
  EXPECT_EQ(ReadFile(out / "sweep.csv").rfind("index,", 0), 0u);
}

// What `sweep merge` refuses: shards that are not whole, not of one sweep, or hold rows that
// do not parse against their header. Each is one line naming the file (and the line and
// column), exit 2, and no sweep.csv.
class SweepMergeTest : public SweepTest {
 protected:
  // The sweep of 5 points in 3 shards in `parts_` (shard 0: points 0 and 3; 1: 1 and 4; 2: 2).
  void SetUp() override {
    SweepTest::SetUp();
    parts_ = dir_ / "parts";
    file_ = Write("s.yaml", kFastBase + "grid:\n  track.t_step_ticks: [48, 64, 80, 96, 112]\n");
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(Sweep("--config " + file_ + " --out " + parts_.string() + " --shard " +
                      std::to_string(i) + "/3")
                    .first,
                0);
    }
  }

  std::vector<std::string> Lines(const std::string& shard) const {
    std::vector<std::string> lines;
    std::ifstream in(parts_ / shard);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
  void WriteLines(const fs::path& path, const std::vector<std::string>& lines) const {
    std::ofstream out(path, std::ios::binary);
    for (const std::string& line : lines) out << line << '\n';
  }

  // Merging parts_ (with --config, when `config`) is bad input naming each of `needles`.
  void ExpectRefused(const std::vector<std::string>& needles, bool config = true,
                     const std::string& extra_dirs = "") {
    const fs::path merged = dir_ / "merged";
    const std::string args = "merge " + parts_.string() + extra_dirs + " --out " + merged.string() +
                             (config ? " --config " + file_ : "");
    const auto [status, err] = Sweep(args);
    EXPECT_EQ(status, 2) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    for (const std::string& needle : needles) {
      EXPECT_NE(err.find(needle), std::string::npos) << needle << " in " << err;
    }
    EXPECT_FALSE(fs::exists(merged / "sweep.csv"));
  }

  std::string file_;
  fs::path parts_;
};

TEST_F(SweepMergeTest, TheShardsAsWrittenMerge) {
  const auto [status, err] =
      Sweep("merge " + parts_.string() + " --out " + (dir_ / "m").string() + " --config " + file_);
  EXPECT_EQ(status, 0) << err;
  EXPECT_TRUE(fs::exists(dir_ / "m" / "sweep.csv"));
}

TEST_F(SweepMergeTest, AShardMissingItsLastRowIsRefused) {
  std::vector<std::string> lines = Lines("sweep.shard-0-of-3.csv");
  ASSERT_EQ(lines.size(), 4u);  // stamp, header, points 0 and 3
  lines.pop_back();
  WriteLines(parts_ / "sweep.shard-0-of-3.csv", lines);
  ExpectRefused({"sweep.shard-0-of-3.csv", "point 3 is missing"});
  ExpectRefused({"sweep.shard-0-of-3.csv", "point 3 is missing"}, false);
}

// A shard of another grid in place of shard 1, with and without --config; and every shard of
// this sweep when --config names the other.
TEST_F(SweepMergeTest, AShardOfAnotherSweepIsRefused) {
  const std::string other =
      Write("other.yaml", kFastBase + "grid:\n  track.t_step_ticks: [48, 64, 80, 96, 120]\n");
  const fs::path elsewhere = dir_ / "other";
  ASSERT_EQ(Sweep("--config " + other + " --out " + elsewhere.string() + " --shard 1/3").first, 0);
  fs::copy_file(elsewhere / "sweep.shard-1-of-3.csv", parts_ / "sweep.shard-1-of-3.csv",
                fs::copy_options::overwrite_existing);
  ExpectRefused({"sweep.shard-1-of-3.csv", "line 1", "a shard of sweep"}, false);
  ExpectRefused({"sweep.shard-1-of-3.csv", "line 1", "a shard of sweep",
                 "but '" + file_ + "' is sweep " + SweepId(LoadSweepConfig(file_))});
  file_ = other;  // --config naming the other sweep: shards 0 and 2 are not of it
  ExpectRefused({"sweep.shard-0-of-3.csv", "line 1", "a shard of sweep"});
}

// A shard saved with Windows line ends and a byte-order mark: the message echoes its first line
// with both escaped, on one line, never the raw bytes.
TEST_F(SweepMergeTest, ACrlfShardWithAByteOrderMarkIsEchoedEscaped) {
  std::vector<std::string> lines = Lines("sweep.shard-2-of-3.csv");
  lines[0] = "\xEF\xBB\xBF" + lines[0] + "\r";
  WriteLines(parts_ / "sweep.shard-2-of-3.csv", lines);
  ExpectRefused({"sweep.shard-2-of-3.csv", "line 1", "got '\\ufeff# sweep", "\\r'"}, false);
  const auto [status, err] = Sweep("merge " + parts_.string() + " --out " + (dir_ / "m").string());
  EXPECT_EQ(err.find('\r'), std::string::npos);
  EXPECT_EQ(err.find("\xEF\xBB\xBF"), std::string::npos);
}

TEST_F(SweepMergeTest, AGarbageRowIsRefused) {
  std::vector<std::string> lines = Lines("sweep.shard-2-of-3.csv");
  ASSERT_EQ(lines.size(), 3u);
  lines[2] = "2,80,ok,1,2,3,4,5";
  WriteLines(parts_ / "sweep.shard-2-of-3.csv", lines);
  ExpectRefused({"sweep.shard-2-of-3.csv", "line 3", "8 cells, the header has"});
}

TEST_F(SweepMergeTest, NaNInANumberIsRefused) {
  std::vector<std::string> lines = Lines("sweep.shard-1-of-3.csv");
  ASSERT_EQ(lines[3].rfind("4,112,ok,", 0), 0u) << lines[3];
  // The first result cell, column 4 (index, track.t_step_ticks, status before it).
  const size_t start = std::string("4,112,ok,").size();
  lines[3].replace(start, lines[3].find(',', start) - start, "NaN");
  WriteLines(parts_ / "sweep.shard-1-of-3.csv", lines);
  ExpectRefused(
      {"sweep.shard-1-of-3.csv", "line 4 (point 4), column 4 'direct_rotator_l2_deg'", "'NaN'"});
}

TEST_F(SweepMergeTest, ADuplicatedShardIsRefused) {
  // The same shard in two folders.
  const fs::path copy = dir_ / "copy";
  fs::create_directories(copy);
  fs::copy_file(parts_ / "sweep.shard-2-of-3.csv", copy / "sweep.shard-2-of-3.csv");
  ExpectRefused({"shard 2 found twice"}, true, " " + copy.string());
  // Shard 0 copied in place of shard 1.
  fs::copy_file(parts_ / "sweep.shard-0-of-3.csv", parts_ / "sweep.shard-1-of-3.csv",
                fs::copy_options::overwrite_existing);
  ExpectRefused({"sweep.shard-1-of-3.csv", "line 1", "the stamp says shard 0 of 3"});
}

// A sweep whose every point fails exits 3, its sweep.csv written (each row says why); so does
// the merge of such shards, while each shard, a part of the whole, exits 0.
TEST_F(SweepTest, ASweepWhoseEveryPointFailsExitsThree) {
  const std::string file = Write("s.yaml", kFastBase + "grid:\n  track.t_step_ticks: [3, 2]\n");
  const fs::path whole = dir_ / "whole", parts = dir_ / "parts", merged = dir_ / "merged";
  const auto [status, err] = Sweep("--config " + file + " --out " + whole.string());
  EXPECT_EQ(status, 3) << err;
  EXPECT_NE(err.find("every one of the 2 points failed"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(whole / "sweep.csv"));
  for (int i : {0, 1}) {
    EXPECT_EQ(Sweep("--config " + file + " --out " + parts.string() + " --shard " +
                    std::to_string(i) + "/2")
                  .first,
              0);
  }
  const auto [merge_status, merge_err] =
      Sweep("merge " + parts.string() + " --out " + merged.string() + " --config " + file);
  EXPECT_EQ(merge_status, 3) << merge_err;
  EXPECT_EQ(ReadFile(merged / "sweep.csv"), ReadFile(whole / "sweep.csv"));
  // One failed point among ok ones is not the sweep's failure.
  const std::string mixed = Write("m.yaml", kFastBase + "grid:\n  track.t_step_ticks: [3, 48]\n");
  EXPECT_EQ(Sweep("--config " + mixed + " --out " + (dir_ / "mixed").string()).first, 0);
}

// A broken sweep file or shard spec is the user's: one line, exit 2, nothing written.
TEST_F(SweepTest, BadSweepFilesAreExitTwoWithNothingWritten) {
  const fs::path out = dir_ / "out";
  auto bad = [&](const std::string& name, const std::string& text, const std::string& needle,
                 const std::string& extra = "") {
    ExpectBadInput("--config " + Write(name, text) + " --out " + out.string() + extra, out, needle);
  };
  bad("unknown.yaml", kFastBase + "grid:\n  servo.dealy_ms: [32]\n", "servo.dealy_ms");
  bad("empty_grid.yaml", kFastBase + "grid: {}\n", "grid");
  bad("empty_list.yaml", kFastBase + "grid:\n  servo.delay_ms: []\n", "grid.servo.delay_ms");
  bad("both.yaml",
      kFastBase + "grid:\n  servo.delay_ms: [32]\nsample: {count: 1, seed: 1, keys: {}}\n",
      "either grid: or sample:");
  bad("neither.yaml", kFastBase, "either grid: or sample:");
  bad("no_base.yaml", "grid:\n  servo.delay_ms: [32]\n", "base");
  bad("bad_base.yaml", kFastBase + "stepz: 3\ngrid:\n  servo.delay_ms: [32]\n", "stepz");
  bad("count.yaml", kFastBase + "sample: {count: 0, seed: 1, keys: {steps: {min: 1, max: 2}}}\n",
      "sample.count");
  bad("range.yaml", kFastBase + "sample: {count: 3, seed: 1, keys: {steps: {min: 5, max: 2}}}\n",
      "sample.keys.steps");
  for (const char* step : {"0", "-8", "nan", "x", ".inf"}) {
    bad("step.yaml",
        kFastBase + "sample: {count: 3, seed: 1, keys: {steps: {min: 1, max: 2, step: " + step +
            "}}}\n",
        "sample.keys.steps");
  }
  bad("extra.yaml",
      kFastBase + "sample: {count: 3, seed: 1, keys: {steps: {min: 1, max: 2, stpe: 1}}}\n",
      "sample.keys.steps");
  const std::string good = kFastBase + "grid:\n  servo.delay_ms: [32]\n";
  bad("shard1.yaml", good, "--shard '3/2'", " --shard 3/2");
  bad("shard2.yaml", good, "--shard '0/0'", " --shard 0/0");
  ExpectBadInput(
      "--config " + Write("missing.yaml", good) + " --out " + out.string() + " --shards 0", out,
      "--shards");
}

}  // namespace
}  // namespace leglab::experiments
