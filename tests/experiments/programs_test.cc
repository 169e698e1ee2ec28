// The experiment programs run as a user runs them: flags, config files, exit status, files.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/sim/sim_config.h"

namespace {

namespace fs = std::filesystem;

struct Result {
  int status = -1;
  std::string stderr_text;
};

// Runs `command` from the source tree, capturing its standard error (stdout into `stdout_path`).
Result RunCommand(const std::string& command, const std::string& stdout_path = "/dev/null") {
  // One file per test: ctest runs the tests of this file as parallel processes.
  const fs::path err =
      fs::temp_directory_path() / (std::string("leglab_programs_") +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name() +
                                   "_" + std::to_string(::getpid()) + ".stderr");
  const std::string full = "cd '" LEGLAB_SOURCE_DIR "' && " + command + " >'" + stdout_path +
                           "' 2>'" + err.string() + "'";
  const int raw = std::system(full.c_str());
  Result r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream in(err);
  std::stringstream s;
  s << in.rdbuf();
  r.stderr_text = s.str();
  fs::remove(err);
  return r;
}

class ProgramsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The process id too: the release and asan suites may run at once.
    dir_ = fs::temp_directory_path() /
           (std::string("leglab_programs_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    out_ = dir_ / "out";
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }

  // Expects exit status 2, one line on stderr that contains `needle`, and no --out folder.
  void ExpectBadInput(const std::string& program, const std::string& args,
                      const std::string& needle) {
    const Result r = RunCommand(program + " --out '" + out_.string() + "' " + args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    EXPECT_NE(r.stderr_text.find(needle), std::string::npos) << r.stderr_text;
    EXPECT_FALSE(fs::exists(out_)) << args;
  }

  fs::path dir_;
  fs::path out_;
};

const std::string kIdentify = LEGLAB_IDENTIFY_BIN;
const std::string kTrack = LEGLAB_TRACK_BIN;
const std::string kFitWalk = LEGLAB_FIT_WALK_BIN;

// A desired.csv of `rows` ticks (a gentle wave inside every joint limit).
std::string DesiredCsv(int rows) {
  std::ostringstream csv;
  csv << "tick,rotator_deg,abductor_deg,knee_deg\n";
  for (int t = 0; t < rows; ++t) {
    csv << t << "," << 10 + 20 * std::sin(2 * M_PI * t / rows) << ",5,"
        << 60 + 15 * std::cos(2 * M_PI * t / rows) << "\n";
  }
  return csv.str();
}

TEST_F(ProgramsTest, IdentifyRejectsBadInputWithOneLineAndStatus2) {
  const std::string good = "--config experiments/configs/identify.yaml";
  ExpectBadInput(kIdentify, "--config " + (dir_ / "absent.yaml").string(), "absent.yaml");
  ExpectBadInput(kIdentify, "--config " + Write("bad.yaml", "identify: [unclosed\n"), "malformed");
  ExpectBadInput(kIdentify, good + " --set servo.gain_pr_s=3", "servo.gain_pr_s");
  ExpectBadInput(kIdentify, good + " --set controller.mode=pid", "controller.mode");
  ExpectBadInput(kIdentify, good + " --set servo.max_speed_deg_s=fast", "servo.max_speed_deg_s");
  ExpectBadInput(kIdentify, good + " --set servo.max_speed_deg_s=-5", "servo.max_speed_deg_s");
  ExpectBadInput(kIdentify, good + " --set urdf=/nonexistent/leg.urdf", "/nonexistent/leg.urdf");
  ExpectBadInput(kIdentify, good + " --set urdf=" + Write("broken.urdf", "<robot name='x'><link"),
                 "broken.urdf");
  ExpectBadInput(kIdentify, good + " --bogus-flag", "bogus");
  // Nothing written means no parent folders either.
  const Result nested = RunCommand(kIdentify + " --config " + (dir_ / "absent.yaml").string() +
                                   " --out '" + (dir_ / "new" / "deeper" / "out").string() + "'");
  EXPECT_EQ(nested.status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "new"));
  ExpectBadInput(kIdentify, "", "--config");
}

// A robot outside the physical ranges (a 1e-30 kg upper leg made ODE abort mid-run) is bad
// input found before anything runs: status 2, one line, no --out and no staging folder.
TEST_F(ProgramsTest, TrackRefusesARobotOutsideThePhysicalRanges) {
  std::ifstream in(LEGLAB_SOURCE_DIR "/robots/ers210a/leg.urdf");
  std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string mass = R"(<mass value="0.073"/>)";  // the first is the upper leg's
  urdf.replace(urdf.find(mass), mass.size(), R"(<mass value="1e-30"/>)");
  ExpectBadInput(kTrack,
                 "--config experiments/configs/track.yaml --set steps=1 --set warmup_steps=0 "
                 "--set urdf=" +
                     Write("tiny.urdf", urdf),
                 "link 'upper_leg' mass must be in [0.0001, 100] kg, got 1e-30");
  for (const auto& entry : fs::directory_iterator(out_.parent_path())) {
    EXPECT_NE(
        entry.path().filename().string().rfind("." + out_.filename().string() + ".staging-", 0), 0u)
        << entry.path();
  }
}

// Expects no staging folder of out_ beside it.
void ExpectNoStagingFolder(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out.parent_path())) {
    EXPECT_NE(
        entry.path().filename().string().rfind("." + out.filename().string() + ".staging-", 0), 0u)
        << entry.path();
  }
}

// The ERS-210A's leg with a shin reaching 0.5 m instead of 66 mm (the lower leg's centre of
// mass 0.3 m below the knee): every value inside its range.
std::string LongShinUrdf() {
  std::ifstream in(LEGLAB_SOURCE_DIR "/robots/ers210a/leg.urdf");
  std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&urdf](const std::string& from, const std::string& to) {
    const size_t at = urdf.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) urdf.replace(at, from.size(), to);
  };
  replace(R"(<origin xyz="-0.011001 0 -0.038457")", R"(<origin xyz="-0.011001 0 -0.3")");
  replace(R"(<origin xyz="-0.01888 0 -0.066")", R"(<origin xyz="-0.01888 0 -0.5")");
  return urdf;
}

// A top speed the physics step cannot follow (3.6 deg a step at 1 ms) is refused at load,
// naming both keys: status 2, one line, nothing written.
TEST_F(ProgramsTest, ATopSpeedThePhysicsStepCannotFollowIsRefused) {
  const std::string fast = " --set servo.max_speed_deg_s=3600 --set servo.gain_per_s=1000";
  const std::string needle =
      "servo.max_speed_deg_s 3600 with sim.physics_dt_ms 1 turns a joint 3.6 deg in one physics "
      "step";
  ExpectBadInput(kIdentify, "--config experiments/configs/identify.yaml" + fast, needle);
  ExpectNoStagingFolder(out_);
  ExpectBadInput(kTrack, "--config experiments/configs/track.yaml" + fast, needle);
  ExpectNoStagingFolder(out_);
  // A change of the running plant to that speed is refused at load too.
  ExpectBadInput(kTrack,
                 "--config experiments/configs/track.yaml --set 'plant_changes=[{at_step: 1, "
                 "set: {servo.max_speed_deg_s: 3600}}]'",
                 "plant_changes[0].set.servo.max_speed_deg_s 3600 with sim.physics_dt_ms 1 turns "
                 "a joint 3.6 deg");
  // The same speed at a finer step is accepted (a short run).
  const Result r = RunCommand(kIdentify + " --config experiments/configs/identify.yaml" + fast +
                              " --set sim.physics_dt_ms=0.5 --set identify.settle_cycles=1 "
                              "--set identify.record_cycles=1 --out '" +
                              out_.string() + "'");
  EXPECT_EQ(r.stderr_text.find("physics step"), std::string::npos) << r.stderr_text;
}

// Settings each inside its range under which the leg still comes apart mid-run (a long shin:
// the hinge's drift grows with the reach) are the user's: status 2, one line naming the
// settings of the moment, nothing written, the same line whatever the thread count.
TEST_F(ProgramsTest, ASimulationThatBreaksDownIsBadInput) {
  // Joint angles to walk (the long shin reaches no foot locus), and the identification's step
  // tests, which break it down at a high gain.
  const std::string robot = " --set urdf=" + Write("long_shin.urdf", LongShinUrdf()) +
                            " --set servo.max_speed_deg_s=1000 --set servo.gain_per_s=1000";
  const std::string track = "--config experiments/configs/track.yaml --set desired.csv=" +
                            Write("wave.csv", DesiredCsv(88)) + robot;
  const std::string settings =
      "the simulation broke down under these settings (servo.max_speed_deg_s 1000, "
      "servo.gain_per_s 1000, servo.damping 1.3, servo.smoothing_ms 48, servo.max_torque_nm 5.45, "
      "sim.engine ode, sim.physics_dt_ms 1, stand off): joint '";
  for (const std::string threads : {"1", "3"}) {
    ExpectBadInput(kIdentify,
                   "--config experiments/configs/identify.yaml --threads " + threads + robot,
                   settings);
    ExpectNoStagingFolder(out_);
    ExpectBadInput(kTrack, track + " --threads " + threads, settings);
    ExpectNoStagingFolder(out_);
  }
  // The same line from any thread count: the lowest joint's breakdown, not the first in time.
  const std::string identify = kIdentify + " --config experiments/configs/identify.yaml" + robot +
                               " --out '" + out_.string() + "'";
  EXPECT_EQ(RunCommand(identify + " --threads 1").stderr_text,
            RunCommand(identify + " --threads 3").stderr_text);
  // The walk alone (a given model) holds together at 1000 deg/s; a change of the running plant
  // to 2000 deg/s (2 deg a physics step, in range) breaks it down, and the line names the
  // settings after the change.
  const std::string walk = track +
                           " --set 'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, "
                           "accel_ticks: 6}' --set 'controller.modes=[direct]' --set "
                           "warmup_steps=1 --set steps=3";
  const Result r = RunCommand(kTrack + " --out '" + out_.string() + "' " + walk);
  EXPECT_EQ(r.status, 0) << r.stderr_text;
  fs::remove_all(out_);
  ExpectBadInput(kTrack,
                 walk + " --set 'plant_changes=[{at_step: 1, set: {servo.max_speed_deg_s: 2000}}]'",
                 "the simulation broke down under these settings (servo.max_speed_deg_s 2000, "
                 "servo.gain_per_s 1000, ");
}

// What breaks ODE's long-shinned leg down runs on DART, whose joints cannot come apart: the
// walk of ProgramsTest.ASimulationThatBreaksDownIsBadInput, the leg 0.5 m long, its plant
// changed to 2000 deg/s at gain 1000 (and 3600 deg/s, which ODE's bound refuses).
TEST_F(ProgramsTest, DartRunsTheLegThatComesApartOnOde) {
  if (!leglab::sim::BuiltWithDart())
    GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  const std::string walk =
      "--config experiments/configs/track.yaml --set desired.csv=" +
      Write("wave.csv", DesiredCsv(88)) + " --set urdf=" + Write("long_shin.urdf", LongShinUrdf()) +
      " --set servo.max_speed_deg_s=1000 --set servo.gain_per_s=1000"
      " --set 'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}'"
      " --set 'controller.modes=[direct]' --set warmup_steps=1 --set steps=3"
      " --set sim.engine=dart --set 'plant_changes=[{at_step: 1, set: {servo.max_speed_deg_s: ";
  for (const std::string top : {"2000", "3600"}) {
    const Result r = RunCommand(kTrack + " --out '" + out_.string() + "' " + walk + top + "}}]'");
    EXPECT_EQ(r.status, 0) << r.stderr_text;
    EXPECT_TRUE(fs::exists(out_ / "table2.json")) << top;
    fs::remove_all(out_);
  }
}

// A build without DART refuses sim.engine: dart as bad input: one line naming the key, exit 2,
// nothing written.
TEST_F(ProgramsTest, DartInABuildWithoutItIsBadInput) {
  if (leglab::sim::BuiltWithDart()) GTEST_SKIP() << "this build has DART";
  for (const std::string& program : {kIdentify, kTrack}) {
    const std::string config = program == kIdentify ? "identify.yaml" : "track.yaml";
    ExpectBadInput(program, "--config experiments/configs/" + config + " --set sim.engine=dart",
                   "error: config: sim.engine: dart, but this build of leglab has no DART");
  }
}

// Files over their size limits (4 MiB for configs, sweep files and URDFs, 1 MiB for a
// desired.csv) are refused before they are read: sparse files, so the test writes nothing.
TEST_F(ProgramsTest, FilesOverTheirSizeLimitsAreRefusedUnread) {
  const auto sparse = [this](const std::string& name, const std::string& start,
                             std::uintmax_t bytes) {
    std::string path = Write(name, start);
    fs::resize_file(path, bytes);
    return path;
  };
  const std::uintmax_t mib = 1 << 20;
  ExpectBadInput(kTrack, "--config " + sparse("big.yaml", "steps: 1\n", 4 * mib + 1),
                 "big.yaml' is 4194305 bytes, over the 4194304-byte limit");
  std::ifstream in(LEGLAB_SOURCE_DIR "/robots/ers210a/leg.urdf");
  const std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ExpectBadInput(kIdentify,
                 "--config experiments/configs/identify.yaml --set urdf=" +
                     sparse("big.urdf", urdf, 4 * mib + 1),
                 "big.urdf' is 4194305 bytes, over the 4194304-byte limit");
  const std::string track = "--config experiments/configs/track.yaml --set desired.csv=";
  ExpectBadInput(kTrack, track + sparse("big.csv", DesiredCsv(88), mib + 1),
                 "desired.csv '" + (dir_ / "big.csv").string() +
                     "' is 1048577 bytes, over the 1048576-byte limit");
  // At the limit a file is read: its own content decides (here the NUL bytes padding it).
  const Result r = RunCommand(kTrack + " --out '" + out_.string() + "' " + track +
                              sparse("limit.csv", DesiredCsv(88), mib));
  EXPECT_EQ(r.status, 2) << r.stderr_text;
  EXPECT_EQ(r.stderr_text.find("-byte limit"), std::string::npos) << r.stderr_text;
}

TEST_F(ProgramsTest, TrackRejectsBadInputWithOneLineAndStatus2) {
  // A given model skips identification, so each bad input is found at once.
  const std::string good =
      "--config experiments/configs/track.yaml --set 'model={v_max_deg_per_tick: 2.5, "
      "theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}' --set steps=1 --set "
      "warmup_steps=0";
  ExpectBadInput(kTrack, good + " --set controller.modes=[direct,pid]", "controller.modes");
  ExpectBadInput(kTrack, good + " --set controller.pwl_segments=200", "controller.pwl_segments");
  // A model under which eq. 3 overshoots every tick never settles: no joint's, the user's error.
  ExpectBadInput(kTrack,
                 "--config experiments/configs/track.yaml --set 'model={v_max_deg_per_tick: 8, "
                 "theta0_deg: 2, lag_ticks: 4, accel_ticks: 3}' --set steps=1 --set warmup_steps=0",
                 "model: eq. 3 under this model never settles");
  ExpectBadInput(kTrack,
                 good + " --set 'plant_changes=[{at_step: 0, set: {servo.max_speed_deg_s: -1}}]'",
                 "plant_changes[0].set.servo.max_speed_deg_s");
  ExpectBadInput(kTrack, good + " --set desired.locus.ground_below_shoulder_mm=200", "unreachable");
  ExpectBadInput(kTrack, good + " --set desired.locus.swing_end_speed_fraction=-0.5",
                 "desired.locus.swing_end_speed_fraction");
  ExpectBadInput(kTrack, good + " --set desired.locus.swing_end_speed_fraction=3",
                 "desired.locus.swing_end_speed_fraction");
  ExpectBadInput(kTrack, good + " --set desired.csv=" + (dir_ / "none.csv").string(), "none.csv");
  std::string csv = DesiredCsv(88);
  ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("short.csv", DesiredCsv(80)),
                 "80 rows");
  ExpectBadInput(
      kTrack,
      good + " --set desired.csv=" + Write("cols.csv", "tick,rotator_deg,knee_deg\n0,1,2\n"),
      "header");
  std::string nan = csv;
  const size_t row4 = nan.find("\n3,") + 1;
  nan.replace(row4, nan.find('\n', row4) - row4, "3,nan,5,60");
  ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("nan.csv", nan),
                 "row 4, rotator_deg is not finite");
  std::string wide = csv;
  wide.replace(row4, wide.find('\n', row4) - row4, "3,1,5,60,7");
  ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("wide.csv", wide),
                 "row 4 has 5 columns");
  std::string word = csv;
  word.replace(word.find(",5,"), 3, ",five,");
  ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("word.csv", word), "abductor_deg");
  std::string limit = csv;
  limit.replace(limit.find(",5,"), 3, ",95,");  // abductor limit 89
  ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("limit.csv", limit), "limits");
}

// fit_walk refuses bad input like every program, before its fit starts.
TEST_F(ProgramsTest, FitWalkRejectsBadInputWithOneLineAndStatus2) {
  const std::string good = "--config experiments/configs/track.yaml";
  ExpectBadInput(kFitWalk, "--config " + (dir_ / "absent.yaml").string(), "absent.yaml");
  ExpectBadInput(kFitWalk, good + " --set desired.locus.skew=5", "desired.locus.skew");
  ExpectBadInput(kFitWalk, good + " --set desired.locus.body_pitch_deg=.nan",
                 "desired.locus.body_pitch_deg");
  ExpectBadInput(kFitWalk, good + " --set desired.locus.lenght_mm=40", "desired.locus.lenght_mm");
  // A key the fit sets would be silently replaced: refused, naming it.
  ExpectBadInput(kFitWalk, good + " --set desired.locus.ground_fraction=0.6",
                 "--set desired.locus.ground_fraction: fit_walk fits this key");
  ExpectBadInput(kFitWalk, good + " --set desired.csv=" + Write("cycle.csv", DesiredCsv(88)),
                 "desired.csv");
  ExpectBadInput(kFitWalk, good + " --bogus-flag", "bogus");
  ExpectBadInput(kFitWalk, "", "--config");
  // An --out that is a file is found before the fit runs; the file is left as it was.
  const std::string file = Write("a_file", "keep");
  const Result r = RunCommand(kFitWalk + " " + good + " --out " + file);
  EXPECT_EQ(r.status, 2) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("--out"), std::string::npos) << r.stderr_text;
  std::ifstream in(file);
  std::string kept;
  in >> kept;
  EXPECT_EQ(kept, "keep");
}

// The test stand's values: a negative load, negative friction or a stop above the
// shoulder's walking height is bad input, for identify and track alike.
TEST_F(ProgramsTest, BadStandValuesAreBadInput) {
  const std::string id = "--config experiments/configs/identify_stand.yaml";
  const std::string track =
      "--config experiments/configs/track_stand.yaml --set 'model={v_max_deg_per_tick: 2.5, "
      "theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}' --set steps=1 --set warmup_steps=0";
  for (const std::string& program : {kIdentify, kTrack}) {
    const std::string& good = program == kIdentify ? id : track;
    ExpectBadInput(program, good + " --set stand.load_kg=-0.1",
                   "stand.load_kg must be in [0.01, 10] kg");
    // Next to no mass: refused as bad input, not an ODE assertion in the run (exit 1).
    ExpectBadInput(program, good + " --set stand.load_kg=1e-300",
                   "stand.load_kg must be in [0.01, 10] kg");
    ExpectBadInput(program, good + " --set stand.friction=-0.5",
                   "stand.friction must be in [0, 5]");
    ExpectBadInput(program, good + " --set stand.stop_below_shoulder_mm=-3",
                   "stand.stop_below_shoulder_mm must be in [0, 50] mm");
    ExpectBadInput(program, good + " --set stand.frction=1", "stand.frction");
  }
}

// Hostile numbers: every value that once crashed, overflowed, ran silent or
// produced non-finite results is refused before anything runs, naming the key as written.
TEST_F(ProgramsTest, HostileNumbersAreRefusedNamingTheKey) {
  const std::string id = "--config experiments/configs/identify.yaml";
  const std::string track = "--config experiments/configs/track.yaml";
  const std::string mb =
      "--config experiments/configs/controller_model_based.yaml"
      " --set 'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}'";
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      // row 1: SIGSEGV
      {kIdentify, id + " --set 'identify.lag_range_ticks=[0, 2147483647]'",
       "identify.lag_range_ticks must be in [0, 50] ticks"},
      // row 2: signed overflow
      {kIdentify, id + " --set identify.record_cycles=48806447",
       "identify.record_cycles must be in [1, 1000]"},
      {kIdentify, id + " --set identify.settle_cycles=2147483647",
       "identify.settle_cycles must be in [1, 1000]"},
      {kTrack, mb + " --set model.lag_ticks=2147483647", "model.lag_ticks must be in [0, 50]"},
      // row 3: a file named after a step height out of range
      {kIdentify, id + " --set 'identify.theta_test_deg=[1e300]'",
       "identify.theta_test_deg must be in [-180, 180] deg"},
      // row 4: nonsense tables
      {kIdentify, id + " --set sim.physics_dt_ms=1e-300", "sim.physics_dt_ms must be in [0.1, 2]"},
      {kIdentify, id + " --set sensor.noise_deg=1e300", "sensor.noise_deg must be in [0, 2] deg"},
      {kIdentify, id + " --set servo.max_speed_deg_s=1e-300", "servo.max_speed_deg_s must be in"},
      {kIdentify, id + " --set servo.max_torque_nm=1e-300", "servo.max_torque_nm must be in"},
      {kIdentify, id + " --set servo.delay_ms=80000", "servo.delay_ms must be in [0, 400] ms"},
      // row 5: exit 1 after a while; and the products that size a run
      {kTrack, track + " --set steps=2147483647", "steps must be in [1, 1000000]"},
      {kTrack, track + " --set track.t_step_ticks=2147483647", "track.t_step_ticks must be in"},
      {kTrack, mb + " --set model.accel_ticks=2147483647", "model.accel_ticks must be in"},
      {kTrack, track + " --set servo.damping=1e300", "servo.damping must be in [0, 10]"},
      {kTrack, track + " --set steps=1000000 --set warmup_steps=1000000",
       "(warmup_steps + steps) x track.t_step_ticks"},
      // 89 runs (every time-shift candidate run on its own, then the best) of 300005 steps.
      {kTrack, track + " --set steps=300000 --set track.search_shift=exhaustive", "would simulate"},
      {kIdentify,
       id + " --set 'identify.lag_range_ticks=[0, 50]' --set "
            "'identify.accel_range_ticks=[1, 50]' --set identify.record_cycles=100",
       "identify: 2550 (l, a) candidates"},
      // row 6: messages that named an internal
      {kIdentify, id + " --set servo.delay_ms=1e300", "servo.delay_ms must be in"},
      {kIdentify, id + " --set sensor.noise_deg=1e6", "sensor.noise_deg must be in"},
      {kTrack, mb + " --set model.v_max_deg_per_tick=.inf", "model.v_max_deg_per_tick must be in"},
      {kIdentify, id + " --set 'identify.theta_test_deg=[.nan]'",
       "identify.theta_test_deg must be in"},
      // row 8: silent for over 60 s
      {kIdentify, id + " --set sim.physics_dt_ms=0.001", "sim.physics_dt_ms must be in"},
      {kTrack, track + " --set warmup_steps=2147483647", "warmup_steps must be in"},
      {kTrack, track + " --set track.t_step_ticks=100000", "track.t_step_ticks must be in"},
      {kIdentify, id + " --set 'identify.accel_range_ticks=[1,600]'",
       "identify.accel_range_ticks must be in"},
  };
  // All are found while loading the config, so none of these runs anything.
  for (const auto& [program, args, needle] : cases) ExpectBadInput(program, args, needle);
}

// Row 12: what was accepted with the last value winning, rows duplicated or files overwritten.
TEST_F(ProgramsTest, DuplicatesAndKeysOfAnotherProgramAreRefused) {
  const std::string id = "--config experiments/configs/identify.yaml";
  ExpectBadInput(kIdentify,
                 "--config " + Write("dup.yaml", "extends: " LEGLAB_SOURCE_DIR
                                                 "/experiments/configs/identify.yaml\n"
                                                 "identify:\n  settle_cycles: 2\n"
                                                 "  settle_cycles: 3\n"),
                 "key 'identify.settle_cycles' is given twice");
  ExpectBadInput(kIdentify, id + " --set 'servo={gain_per_s: 3, gain_per_s: 4}'",
                 "'servo.gain_per_s' is given twice");
  ExpectBadInput(kIdentify, id + " --set 'identify.theta_test_deg=[40,40]'", "40 twice");
  ExpectBadInput(kTrack,
                 "--config experiments/configs/track.yaml --set controller.modes=[direct,direct]",
                 "'direct' twice");
  ExpectBadInput(kIdentify, id + " --set steps=5", "steps is not used by identify");
  ExpectBadInput(kIdentify, id + " --set controller.cm=closed",
                 "controller.cm is not used by identify");
  ExpectBadInput(kIdentify, id + " --set stepz=5", "unknown key 'stepz'");
  // Found by the fuzz harness: an alias inside its own anchor overflowed the stack.
  ExpectBadInput(kIdentify,
                 "--config " + Write("self.yaml", "robot: ers210a\na: &a [11ec\n *a, *a, *a]"),
                 "nests deeper than 64 levels");
}

// Row 12: a desired.csv is read strictly: what stod would take (hex, a sign, spaces, 7.0 for
// a tick) is refused, naming the row and column.
TEST_F(ProgramsTest, DesiredCsvCellsAreStrictlyDecimal) {
  const std::string good =
      "--config experiments/configs/track.yaml --set 'model={v_max_deg_per_tick: 2.5, "
      "theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}' --set steps=1 --set warmup_steps=0";
  const std::string csv = DesiredCsv(88);
  const size_t row8 = csv.find("\n7,") + 1;
  const std::string rest = csv.substr(csv.find(',', row8));
  for (const std::string tick : {"0x7", "+7", " 7", "7.0", "7e0", "07 "}) {
    const std::string bad = csv.substr(0, row8) + tick + rest;
    ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("tick.csv", bad),
                   "row 8, tick: '" + tick + "' is not a tick");
  }
  for (const std::string angle : {"0x1p3", "+5", " 5", "5 ", "5deg"}) {
    std::string bad = csv;
    bad.replace(bad.find(",5,", row8), 3, "," + angle + ",");
    ExpectBadInput(kTrack, good + " --set desired.csv=" + Write("angle.csv", bad),
                   "row 8, abductor_deg: '" + angle + "' is not a decimal number");
  }
}

// Row 8 and 9: --progress shows progress on stderr as plain lines (the first at once, then
// every 2 s), --quiet shows none, and stdout carries the table alone either way.
TEST_F(ProgramsTest, ProgressGoesToStderrAndQuietSilencesIt) {
  const std::string run = kIdentify + " --config experiments/configs/identify.yaml --out '" +
                          out_.string() + "' --set identify.record_cycles=2";
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  for (const std::string flag : {"--progress", "--quiet"}) {
    const fs::path stdout_file = dir_ / "stdout.txt";
    const Result r = RunCommand(run + " " + flag, stdout_file.string());
    ASSERT_EQ(r.status, 0) << r.stderr_text;
    EXPECT_EQ(read(stdout_file).rfind("# Table 1", 0), 0u) << flag;
    if (flag == "--quiet") {
      EXPECT_EQ(r.stderr_text, "");
    } else {
      EXPECT_EQ(r.stderr_text.rfind("identify: 0% of ", 0), 0u) << r.stderr_text;
      EXPECT_NE(r.stderr_text.find(" ticks after "), std::string::npos);
      EXPECT_EQ(r.stderr_text.find('\r'), std::string::npos);  // lines, not a bar
    }
  }
  fs::remove_all(out_);
  ExpectBadInput(kIdentify, "--config experiments/configs/identify.yaml --progress --quiet",
                 "--progress excludes --quiet");
}

TEST_F(ProgramsTest, TrackFollowsADesiredCsv) {
  const Result r = RunCommand(
      kTrack + " --config experiments/configs/track.yaml --out '" + out_.string() +
      "' --set 'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}'"
      " --set steps=2 --set warmup_steps=1 --set track.search_shift=false"
      " --set desired.csv=" +
      Write("wave.csv", DesiredCsv(88)));
  ASSERT_EQ(r.status, 0) << r.stderr_text;
  std::ifstream in(out_ / "table2.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["steps"], 2);
  // The run names its robot file, as table1.json does (leglab.results.animate draws from it).
  EXPECT_TRUE(j["plant"]["robot"].get<std::string>().ends_with("robots/ers210a/robot.yaml"))
      << j["plant"];
  for (const char* mode : {"direct", "time_shift", "model_based"}) {
    EXPECT_TRUE(fs::exists(out_ / (std::string("trace_") + mode + ".csv"))) << mode;
    EXPECT_TRUE(fs::exists(out_ / (std::string("foot_") + mode + ".csv"))) << mode;
    EXPECT_TRUE(j["foot_cm"].contains(mode)) << mode;
  }
  std::ifstream trace(out_ / "trace_model_based.csv");
  std::string header;
  std::getline(trace, header);
  EXPECT_EQ(header, "step,tick,joint,desired_deg,pwl_deg,request_deg,actual_deg,model_deg");
  std::ifstream foot(out_ / "foot_direct.csv");
  std::getline(foot, header);
  // The first eight columns as before; the test stand's four appended, zeros in the
  // air.
  EXPECT_EQ(header,
            "step,tick,desired_x_cm,desired_y_cm,desired_z_cm,actual_x_cm,actual_y_cm,actual_z_cm,"
            "contact_fz_n,contact_fx_n,contact_fy_n,carriage_z_mm");
  int rows = 0;
  for (std::string line; std::getline(foot, line); ++rows) {
    EXPECT_TRUE(line.ends_with(",0,0,0,0")) << line;
  }
  EXPECT_EQ(rows, 2 * 88);
}

TEST_F(ProgramsTest, ADirectRunDoesNotNeedWhatModelBasedNeeds) {
  // theta_0 < v_max breaks eq. 13, so the closed-form C_m refuses it; direct never uses C_m.
  const std::string args =
      "--config experiments/configs/controller_direct.yaml"
      " --set 'model={v_max_deg_per_tick: 2.5, theta0_deg: 1, lag_ticks: 4, accel_ticks: 6}'"
      " --set controller.cm=closed --set steps=1 --set warmup_steps=0";
  const Result r = RunCommand(kTrack + " --out '" + out_.string() + "' " + args);
  EXPECT_EQ(r.status, 0) << r.stderr_text;
  EXPECT_TRUE(fs::exists(out_ / "trace_direct.csv"));
  EXPECT_FALSE(fs::exists(out_ / "trace_model_based.csv"));
  fs::remove_all(out_);
  ExpectBadInput(kTrack, args + " --set controller.modes=[model_based]", "eq. 13");
}

// Reads every file of `dir` into name -> bytes.
std::map<std::string, std::string> FilesOf(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    files[entry.path().filename().string()].assign(std::istreambuf_iterator<char>(in), {});
  }
  return files;
}

TEST_F(ProgramsTest, AnyThreadCountGivesTheSameBytes) {
  const std::string short_identification =
      " --set identify.record_cycles=2 --set identify.settle_cycles=1";
  // The stand's too: ODE's contacts are made the same way on any thread.
  for (const char* config :
       {"identify.yaml", "track.yaml", "identify_stand_loaded.yaml", "track_stand.yaml"}) {
    const bool track = std::string(config).starts_with("track");
    const std::string program = track ? kTrack : kIdentify;
    // identify refuses track's keys.
    // On the stand one mode is enough: the parallel part is the identification.
    const std::string short_run =
        short_identification + (track ? " --set steps=2 --set warmup_steps=1" : "") +
        (std::string(config) == "track_stand.yaml" ? " --set controller.modes=[model_based]" : "");
    std::map<std::string, std::string> first;
    for (const int threads : {1, 2}) {
      const fs::path out = dir_ / ("threads" + std::to_string(threads));
      const Result r =
          RunCommand(program + " --config experiments/configs/" + config + " --out '" +
                     out.string() + "' --threads " + std::to_string(threads) + short_run);
      ASSERT_EQ(r.status, 0) << r.stderr_text;
      if (threads == 1) {
        first = FilesOf(out);
        EXPECT_GE(first.size(), 4u);
      } else {
        EXPECT_EQ(FilesOf(out), first) << config;
      }
    }
  }
  ExpectBadInput(kTrack, "--config experiments/configs/track.yaml --threads 0", "threads");
}

// 5 kg on the stand: the rotator and abductor hardly move in their step tests, and the fit
// gives them models no joint model is (v_max 3e-160 deg/tick averaged; theta_0 6e18 deg from
// every recorded tick). Such a model is refused where it is made, naming the joint, the tests
// and the settings, not printed as Table 1 (once it was, and then drove the leg).
TEST_F(ProgramsTest, IdentifyRefusesAJointNoModelFits) {
  for (const char* averaged : {"true", "false"}) {
    const Result r = RunCommand(
        kIdentify + " --config experiments/configs/identify_stand_loaded.yaml --out '" +
        out_.string() + "' --set stand.load_kg=5 --set identify.average_cycles=" + averaged);
    EXPECT_EQ(r.status, 2) << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    for (const char* needle : {"joint 'rotator'", "fit no joint model", "stand.load_kg 5"}) {
      EXPECT_NE(r.stderr_text.find(needle), std::string::npos) << needle << ": " << r.stderr_text;
    }
    EXPECT_FALSE(fs::exists(out_)) << averaged;
  }
}

// Settings in their ranges under which the step tests fit no joint model: exit 2 naming the
// joint and the setting, whichever thread finished first (the same joint every run).
TEST_F(ProgramsTest, IdentifyRefusesAbsurdModelsOfInRangeSettings) {
  for (const char* set : {"servo.delay_ms=400", "identify.lag_range_ticks=[50,50]",
                          "identify.theta_test_deg=[1e-300]", "servo.gain_per_s=1"}) {
    ExpectBadInput(kIdentify,
                   "--config experiments/configs/identify.yaml --set " + std::string(set),
                   "fit no joint model");
  }
  ExpectBadInput(kIdentify, "--config experiments/configs/identify.yaml --set servo.delay_ms=400",
                 "joint 'rotator'");
  ExpectBadInput(kTrack, "--config experiments/configs/track.yaml --set servo.delay_ms=400",
                 "delay_ms 400");
}

TEST_F(ProgramsTest, IdentifyWritesItsOutputs) {
  const Result r = RunCommand(kIdentify + " --config experiments/configs/identify.yaml --out '" +
                              out_.string() + "' --set identify.record_cycles=2");
  ASSERT_EQ(r.status, 0) << r.stderr_text;
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    for (const char* theta : {"40", "110"}) {
      const fs::path csv = out_ / (std::string("step_") + joint + "_" + theta + ".csv");
      ASSERT_TRUE(fs::exists(csv)) << csv;
      std::ifstream in(csv);
      std::string header;
      std::getline(in, header);
      EXPECT_EQ(header, "tick,request_deg,actual_deg,model_deg");
    }
  }
  std::ifstream in(out_ / "table1.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    for (const char* key :
         {"v_max_deg_per_tick", "theta0_deg", "lag_ticks", "accel_ticks", "fit_rms_deg"}) {
      EXPECT_TRUE(j["joints"][joint].contains(key)) << joint << " " << key;
    }
  }
  EXPECT_EQ(j["paper"]["v_max_deg_per_tick"], 2.5);
  EXPECT_EQ(j["paper"]["lag_ticks"], 4);
  EXPECT_TRUE(fs::exists(out_ / "table1.md"));
}

// Row 7: --out problems are bad input, found before anything runs.
TEST_F(ProgramsTest, OutProblemsAreFoundBeforeTheRun) {
  const std::string id = kIdentify + " --config experiments/configs/identify.yaml";
  auto expect = [&](const std::string& out, const std::string& needle) {
    const Result r = RunCommand(id + " --out '" + out + "'");
    EXPECT_EQ(r.status, 2) << out << "\n" << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    EXPECT_NE(r.stderr_text.find(needle), std::string::npos) << r.stderr_text;
  };
  const std::string file = Write("results.txt", "mine");
  expect(file, "exists and is not a folder");
  expect("", "--out: an empty value");
  expect(file + "/sub", "a file");
  // An unwritable parent: a folder without write permission, or (as root, who may write
  // anywhere) one where no folder can be created at all.
  if (::geteuid() == 0) {
    expect("/proc/1/leglab_out", "cannot be written");
  } else {
    fs::create_directories(dir_ / "locked");
    fs::permissions(dir_ / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    expect((dir_ / "locked" / "out").string(), "cannot be written");
    fs::permissions(dir_ / "locked", fs::perms::owner_all);
  }
  // A folder where identify writes a file: refused, not replaced halfway.
  fs::create_directories(out_ / "table1.md");
  expect(out_.string(), "'table1.md', which is not a file");
  EXPECT_TRUE(fs::is_directory(out_ / "table1.md"));
  std::ifstream in(file);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "mine");
}

// The entries of `dir` whose names start with `prefix`.
std::vector<std::string> EntriesStartingWith(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

// Every file under `dir`, by relative path, with its bytes.
std::map<std::string, std::string> FilesUnder(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    files[fs::relative(entry.path(), dir).string()].assign(std::istreambuf_iterator<char>(in), {});
  }
  return files;
}

// Rows 10 and 11: a run killed while running or while writing leaves --out as it was and
// nothing beside it, and exits with 128 + the signal.
TEST_F(ProgramsTest, AnInterruptedRunLeavesNothingBehind) {
  // The previous results, with a file and a folder of another program's.
  fs::create_directories(out_ / "hind");
  std::ofstream(out_ / "hind" / "table2.md") << "hind";
  std::ofstream(out_ / "table1.json") << "identify's";
  std::ofstream(out_ / "table2.md") << "old";
  const std::map<std::string, std::string> before = FilesUnder(out_);
  // Long enough to be caught at work: the ideal plant, one mode, 40000 steps to write (4000
  // in the sanitizer build, which runs about ten times slower).
#ifdef __SANITIZE_ADDRESS__
  const std::string steps = "4000";
#else
  const std::string steps = "40000";
#endif
  const std::string command =
      "cd '" LEGLAB_SOURCE_DIR "' && exec " + kTrack +
      " --config experiments/configs/controller_direct.yaml --set plant=model --set "
      "'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}' --set "
      "steps=" +
      steps + " --out '" + out_.string() + "' >/dev/null 2>/dev/null";
  for (const int signal : {SIGINT, SIGTERM, SIGHUP}) {
    for (const bool while_writing : {false, true}) {
      pid_t pid = 0;
      const char* argv[] = {"/bin/sh", "-c", command.c_str(), nullptr};
      ASSERT_EQ(::posix_spawn(&pid, "/bin/sh", nullptr, nullptr, const_cast<char**>(argv), environ),
                0);
      // Wait (no time limit of ours: ctest's timeout stops a hang) for the staging folder, and
      // when asked for a file in it.
      bool caught = false;
      while (!caught) {
        for (const std::string& name : EntriesStartingWith(dir_, ".out.staging-")) {
          caught = !while_writing || !EntriesStartingWith(dir_ / name, "").empty();
        }
        if (::waitpid(pid, nullptr, WNOHANG) == pid) FAIL() << "the run ended before the signal";
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      ::kill(pid, signal);
      int status = 0;
      ASSERT_EQ(::waitpid(pid, &status, 0), pid);
      EXPECT_TRUE(WIFEXITED(status)) << signal;
      EXPECT_EQ(WEXITSTATUS(status), 128 + signal);
      EXPECT_EQ(FilesUnder(out_), before) << signal << (while_writing ? " while writing" : "");
      std::vector<std::string> beside;
      for (const auto& e : fs::directory_iterator(dir_)) {
        beside.push_back(e.path().filename().string());
      }
      EXPECT_EQ(beside, std::vector<std::string>{"out"}) << signal;
    }
  }
}

// Row 11: a finished run replaces the files it wrote at once and keeps the rest, even a file
// named like its outputs that it did not write this time (it may be the user's own).
TEST_F(ProgramsTest, ACommitReplacesTheOldResultsWhole) {
  fs::create_directories(out_ / "hind");
  std::ofstream(out_ / "hind" / "x.csv") << "hind";
  std::ofstream(out_ / "step_knee_77.csv") << "stale";
  std::ofstream(out_ / "fig1.png") << "figure";
  const Result r = RunCommand(kIdentify + " --config experiments/configs/identify.yaml --out '" +
                              out_.string() + "' --set identify.record_cycles=2");
  ASSERT_EQ(r.status, 0) << r.stderr_text;
  EXPECT_TRUE(fs::exists(out_ / "step_knee_77.csv"));  // not written by this run: kept
  EXPECT_TRUE(fs::exists(out_ / "step_knee_110.csv"));
  EXPECT_TRUE(fs::exists(out_ / "table1.json"));
  EXPECT_TRUE(fs::exists(out_ / "fig1.png"));
  EXPECT_TRUE(fs::exists(out_ / "hind" / "x.csv"));
  EXPECT_EQ(EntriesStartingWith(dir_, ".out"), std::vector<std::string>{});
}

// Two runs into one --out: while another run holds it (here this test, through an OutputDir),
// a program refuses at once with status 2 and one line naming --out and the holder, and writes
// nothing; the folder then holds the first run's result only. Once that run has committed, the
// program runs.
TEST_F(ProgramsTest, ASecondRunIntoTheSameOutIsRefused) {
  const std::string track =
      kTrack +
      " --config experiments/configs/controller_direct.yaml --set plant=model --set "
      "'model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}' --set "
      "steps=100 --out '" +
      out_.string() + "'";
  {
    leglab::OutputDir first(out_, {"table2."});
    std::ofstream(first.Path("table2.md")) << "first";
    const Result r = RunCommand(track);
    EXPECT_EQ(r.status, 2) << r.stderr_text;
    EXPECT_EQ(r.stderr_text, "track: error: --out '" + out_.string() +
                                 "' is being written by another run (process " +
                                 std::to_string(::getpid()) +
                                 "): wait for it to finish or choose another folder\n");
    EXPECT_FALSE(fs::exists(out_));
    first.Commit();
  }
  EXPECT_EQ(FilesUnder(out_), (std::map<std::string, std::string>{{"table2.md", "first"}}));
  const Result r = RunCommand(track);
  EXPECT_EQ(r.status, 0) << r.stderr_text;
  EXPECT_NE(FilesUnder(out_).at("table2.md"), "first");
  EXPECT_EQ(EntriesStartingWith(dir_, ".out"), std::vector<std::string>{});
}

}  // namespace

namespace {

// The smaller findings of a hostile-input review: each refusal names its real cause in one
// short line.
TEST_F(ProgramsTest, RefusalsNameTheirRealCauseInOneShortLine) {
  const std::string identify = kIdentify + " --config experiments/configs/identify.yaml";
  ExpectBadInput(kIdentify, "--config experiments/configs", "is a folder, not a file");
  ExpectBadInput(kIdentify, "--config experiments/configs/identify.yaml --threads 0",
                 "not in range 1 to 4096");
  ExpectBadInput(kTrack,
                 "--config experiments/configs/track.yaml --set 'plant_changes=[{at_step: 1, "
                 "set: {servo: {delay_ms: 56}, servo.delay_ms: 48}}]'",
                 "plant_changes[0].set.servo.delay_ms is given twice");
  // Staging in the temporary folder (no parent yet) when TMPDIR names none.
  const fs::path deep = dir_ / "a" / "b";
  Result r = RunCommand("TMPDIR=/nonexistent " + identify + " --out '" + deep.string() + "'");
  EXPECT_EQ(r.status, 2) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("TMPDIR='/nonexistent'"), std::string::npos) << r.stderr_text;
  // A byte-order mark is shown, and a message that would echo a huge value is cut short.
  const std::string big(100000, 'x');
  std::ofstream(dir_ / "bom.yaml") << "\xEF\xBB\xBFrobot: " << big << "\n";
  r = RunCommand(kIdentify + " --config '" + (dir_ / "bom.yaml").string() + "' --out '" +
                 out_.string() + "'");
  EXPECT_EQ(r.status, 2) << r.stderr_text.substr(0, 400);
  EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1);
  EXPECT_LE(r.stderr_text.size(), 400u) << r.stderr_text.substr(0, 400);
  // The tables on a full disk: a failure of the run, not a success.
  r = RunCommand(identify + " --set identify.record_cycles=1 --out '" + out_.string() + "'",
                 "/dev/full");
  EXPECT_EQ(r.status, 1) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("cannot write to standard output"), std::string::npos);
}

}  // namespace
