// `plan` run as a user runs it: a hand-written log_fit.json, a desired CSV or a shipped log,
// its outputs, and every bad input refused with one line, status 2 and nothing written.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "program_test_support.h"

namespace {

namespace fs = std::filesystem;

constexpr const char* kLogFit = R"({"models": {
  "paper": {"sts3250": {"tick_s": 0.005, "v_max_deg_per_tick": 2.0, "theta0_deg": 8.0,
                        "lag_ticks": 1, "accel_ticks": 3}},
  "extended": {"sts3250": {"tick_s": 0.005, "gain_per_deg_kp": 0.003, "v_max_deg_s": 400.0,
                           "stall_torque_nm": 3.0, "friction_duty": 0.01,
                           "friction_load_ratio": 0.2, "velocity_lag_s": 0.02, "lag_ticks": 1,
                           "unknown_field": 1}}},
  "logs": []})";

using leglab::testing::ReadText;
using Result = leglab::testing::ProgramResult;

class PlanProgramTest : public leglab::testing::ScratchDirTest {
 protected:
  PlanProgramTest() : ScratchDirTest("leglab_plan_") {}
  void SetUp() override {
    ScratchDirTest::SetUp();
    Write("log_fit.json", kLogFit);
    // 1 s of a 30 deg sine at 1 Hz, sampled every 10 ms: 201 ticks of 5 ms.
    std::string csv = "time_s,desired_deg\n";
    for (int i = 0; i <= 100; ++i) {
      const double t = 0.01 * i;
      csv += std::to_string(t) + "," + std::to_string(30.0 * std::sin(2 * M_PI * t)) + "\n";
    }
    Write("desired.csv", csv);
  }
  fs::path Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }

  // Runs plan with `args` from the source tree.
  Result Run(const std::string& args) const {
    return RunFromSourceTree("'" LEGLAB_PLAN_BIN "' " + args);
  }

  std::string Model() const { return "--model '" + (dir_ / "log_fit.json").string() + "'"; }
  std::string Desired() const { return "--desired '" + (dir_ / "desired.csv").string() + "'"; }
  std::string Out() const { return "--out '" + (dir_ / "out").string() + "'"; }
};

TEST_F(PlanProgramTest, ADesiredCsvGivesRequestsWithinTheLimits) {
  for (const std::string method : {"model_based", "optimal"}) {
    for (const std::string rung : {"extended", "paper"}) {
      SCOPED_TRACE(rung + " " + method);
      const Result r = Run(Model() + " " + Desired() + " " + Out() + " --kp 40 --rung " + rung +
                           " --method " + method + " --min-deg -25 --max-deg 25");
      ASSERT_EQ(r.status, 0) << r.stderr_text;
      EXPECT_NE(r.stdout_text.find("201 ticks"), std::string::npos) << r.stdout_text;
      std::ifstream csv(dir_ / "out" / "requests.csv");
      std::string line;
      std::getline(csv, line);
      EXPECT_EQ(line, "time_s,desired_deg,request_deg,predicted_deg,beyond_servo");
      const double max_step = (rung == "paper" ? 2.0 : 400.0 * 0.005) + 1e-9;
      double previous = 0.0;
      int rows = 0;
      while (std::getline(csv, line)) {
        std::vector<double> cells;
        std::stringstream s(line);
        for (std::string cell; std::getline(s, cell, ',');) cells.push_back(std::stod(cell));
        ASSERT_EQ(cells.size(), 5u);
        EXPECT_NEAR(cells[0], 0.005 * rows, 1e-12);
        EXPECT_GE(cells[2], -25.0);
        EXPECT_LE(cells[2], 25.0);
        EXPECT_LE(std::abs(cells[2] - previous), max_step) << "row " << rows;
        previous = cells[2];
        ++rows;
      }
      EXPECT_EQ(rows, 201);
      const auto plan = nlohmann::json::parse(ReadText(dir_ / "out" / "plan.json"));
      EXPECT_EQ(plan["ticks"], 201);
      EXPECT_EQ(plan["rung"], rung);
      EXPECT_GT(plan["beyond_servo_ticks"].get<int>(), 0);  // 30 deg is beyond 25
      EXPECT_LE(plan["predicted_mae_deg"]["planned"].get<double>(),
                plan["predicted_mae_deg"]["direct"].get<double>());
    }
  }
}

TEST_F(PlanProgramTest, AShippedLogIsADesiredMotion) {
  const Result r = Run(Model() + " " + Out() +
                       " --desired "
                       "data/servo_logs/feetech-sts3250/sin_sin_kp32_2024-10-26_12h23m27.json");
  ASSERT_EQ(r.status, 0) << r.stderr_text;
  const auto plan = nlohmann::json::parse(ReadText(dir_ / "out" / "plan.json"));
  EXPECT_EQ(plan["motor"], "sts3250");
  EXPECT_EQ(plan["drive"]["kp"], 32.0);
  EXPECT_GT(plan["ticks"].get<int>(), 1000);
  EXPECT_LE(plan["predicted_mae_deg"]["planned"].get<double>(),
            plan["predicted_mae_deg"]["direct"].get<double>());
}

TEST_F(PlanProgramTest, BadInputIsOneLineStatus2AndNothingWritten) {
  Write("bad.json", "{\"models\": ");
  Write("no_field.json", R"({"models": {"extended": {"sts3250": {"tick_s": 0.005}}}})");
  Write("two.json", R"({"models": {"extended": {"a": {}, "b": {}}}})");
  Write("out_of_range.json",
        std::string(kLogFit).replace(std::string(kLogFit).find("\"velocity_lag_s\": 0.02"), 22,
                                     "\"velocity_lag_s\": 0.0"));
  // Numbers that would have made NaN requests before they were bounded: each its field named.
  const auto replaced = [](std::string text, const std::string& from, const std::string& to) {
    return text.replace(text.find(from), from.size(), to);
  };
  Write("huge.json", replaced(kLogFit, "\"v_max_deg_s\": 400.0", "\"v_max_deg_s\": 1e400"));
  Write("tiny_stall.json",
        replaced(kLogFit, "\"stall_torque_nm\": 3.0", "\"stall_torque_nm\": 5e-324"));
  Write("tiny_theta.json", replaced(kLogFit, "\"theta0_deg\": 8.0", "\"theta0_deg\": 5e-324"));
  Write("tiny_tick.json",
        replaced(kLogFit, "\"tick_s\": 0.005, \"gain", "\"tick_s\": 5e-324, \"gain"));
  Write("far.csv", "time_s,desired_deg\n0,1\n0.01,1e308\n");
  Write("bad_header.csv", "time,desired_deg\n0,1\n1,2\n");
  Write("bad_cell.csv", "time_s,desired_deg\n0,1\n1,+2\n");
  Write("backwards.csv", "time_s,desired_deg\n0,1\n1,2\n0.5,3\n");
  {
    // A BAM log whose kp is 0.
    std::string bam = ReadText(
        LEGLAB_SOURCE_DIR "/data/servo_logs/feetech-sts3250/sin_sin_kp32_2024-10-26_12h23m27.json");
    bam.replace(bam.find("\"kp\": 32"), std::string("\"kp\": 32").size(), "\"kp\": 0");
    Write("kp0.json", bam);
  }
  const std::string models = "--model '" + dir_.string() + "/";
  const std::string desired = " --desired '" + dir_.string() + "/";
  const std::string ok = " " + Desired() + " " + Out() + " --kp 40";
  const std::string log =
      " --desired data/servo_logs/feetech-sts3250/sin_sin_kp32_2024-10-26_12h23m27.json " + Out();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {models + "missing.json'" + ok, "missing.json"},
      {models + "bad.json'" + ok, "not valid JSON"},
      {models + "no_field.json'" + ok, "models.extended.sts3250.gain_per_deg_kp is missing"},
      {models + "two.json'" + ok, "choose one with --motor (a, b)"},
      {Model() + ok + " --motor xl330", "no motor 'xl330' (it has: sts3250)"},
      {models + "no_field.json'" + ok + " --rung paper", "models.paper is missing"},
      {models + "out_of_range.json'" + ok, "velocity_lag_s must be in (0, inf) s, got 0"},
      {Model() + " " + Out() + " --kp 40" + desired + "bad_header.csv'", "header"},
      {Model() + " " + Out() + " --kp 40" + desired + "bad_cell.csv'", "row 2, desired_deg"},
      {Model() + " " + Out() + " --kp 40" + desired + "backwards.csv'", "row 3, time_s"},
      {Model() + " " + Out() + " --kp 40" + desired + "none.csv'", "none.csv"},
      {Model() + " " + Desired() + " " + Out(), "--kp is required"},
      {Model() + log + " --kp 40", "leave them out"},
      {Model() + ok + " --min-deg 10 --max-deg 10", "--min-deg 10 must be below --max-deg 10"},
      {Model() + ok + " --min-deg -1e6", "--min-deg must be in [-100000, 100000]"},
      {Model() + ok + " --mass-kg nan", "--mass-kg"},
      {Model() + ok + " --min-deg 5", "outside --min-deg/--max-deg"},
      {Model() + ok + " --rung neither", "--rung"},
      {Model() + ok + " --method best", "--method"},
      {models + "huge.json'" + ok, "not valid JSON"},
      {models + "tiny_stall.json'" + ok + " --mass-kg 0.1 --length-m 0.1",
       "mass_kg x 9.81 x length_m / stall_torque_nm"},
      {models + "tiny_theta.json'" + ok + " --rung paper", "v_max_deg_per_tick / theta0_deg"},
      {models + "tiny_tick.json'" + ok, "models.extended.sts3250.tick_s must be in [1e-06, 10] s"},
      {Model() + ok + " --mass-kg 1e300 --length-m 1e300", "--mass-kg must be in [0, 1000]"},
      {Model() + " " + Desired() + " " + Out() + " --kp 1e300", "--kp must be in (0, 1000000]"},
      {Model() + " " + Out() + " --kp 40" + desired + "far.csv'",
       "desired angle 1 must be in [-100000, 100000] deg"},
      // An empty value is not 0 or the default.
      {Model() + ok + " --min-deg ''", "--min-deg: an empty value"},
      {Model() + ok + " --mass-kg ''", "--mass-kg: an empty value"},
      {Model() + ok + " --online --preview-ticks ''", "--preview-ticks: an empty value"},
      // The online optimal planner's effort: with it only, each in its declared range.
      {Model() + ok + " --budget-ms 5", "--budget-ms goes with --online --method optimal"},
      {Model() + ok + " --online --hold-ticks 5", "--hold-ticks goes with --online --method"},
      {Model() + ok + " --online --method optimal --hold-ticks -1",
       "--hold-ticks must be in [0, 100000] ticks"},
      {Model() + ok + " --online --method optimal --iterations-per-tick 0",
       "--iterations-per-tick must be in [1, 1000]"},
      {Model() + ok + " --online --method optimal --budget-ms 1e9", "--budget-ms must be in"},
      {Model() + " " + Out() + desired + "kp0.json'", "kp0.json': the log's kp must be in"},
  };
  for (const auto& [args, named] : cases) {
    SCOPED_TRACE(args);
    const Result r = Run(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.stderr_text.rfind("plan: error: ", 0), 0u) << r.stderr_text;
    EXPECT_NE(r.stderr_text.find(named), std::string::npos) << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
}

}  // namespace
