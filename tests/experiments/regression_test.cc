// CI regression of the paper's tables: identify and track on the default configuration (the
// shipped configs and robot.yaml), short runs, against pinned values.
//
// Pins are seed 1's results; each tolerance is three times the spread of that value over seeds
// 1-5 (with a small floor), so a change of the sensor noise passes and a change of the plant,
// the model or a controller that moves a norm by a few times the noise does not. Changing a
// pin is a deliberate commit that says why.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;

nlohmann::json RunAndRead(const std::string& program, const std::string& config,
                          const std::string& extra, const std::string& file) {
  const fs::path out = fs::temp_directory_path() / ("leglab_regression_" + file);
  fs::remove_all(out);
  const std::string command = "cd '" LEGLAB_SOURCE_DIR "' && " + program + " --config " + config +
                              " --out '" + out.string() + "' " + extra + " >/dev/null";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
  std::ifstream in(out / file);
  nlohmann::json j = nlohmann::json::parse(in);
  fs::remove_all(out);
  return j;
}

// The paper's Table 1 and the tolerances the plant must meet (the sim issue).
TEST(Regression, IdentifyFindsTable1OnTheDefaultRobot) {
  const nlohmann::json t =
      RunAndRead(LEGLAB_IDENTIFY_BIN, "experiments/configs/identify.yaml", "", "table1.json");
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    const nlohmann::json& p = t["joints"][joint];
    EXPECT_NEAR(p["v_max_deg_per_tick"].get<double>(), 2.5, 0.25) << joint;
    EXPECT_NEAR(p["theta0_deg"].get<double>(), 7.0, 1.5) << joint;
    EXPECT_EQ(p["lag_ticks"].get<int>(), 4) << joint;
    EXPECT_NEAR(p["accel_ticks"].get<int>(), 6, 1) << joint;
    EXPECT_LT(p["fit_rms_deg"].get<double>(), 0.5) << joint;
  }
  // Pinned (seed 1): l and a exactly, the continuous parameters to well inside the spread a
  // seed change gives (0.01 deg/tick, 0.1 deg).
  const struct {
    const char* joint;
    double v_max, theta0;
  } pins[] = {{"rotator", 2.50, 5.65}, {"abductor", 2.52, 8.34}, {"knee", 2.50, 5.64}};
  for (const auto& pin : pins) {
    const nlohmann::json& p = t["joints"][pin.joint];
    EXPECT_NEAR(p["v_max_deg_per_tick"].get<double>(), pin.v_max, 0.03) << pin.joint;
    EXPECT_NEAR(p["theta0_deg"].get<double>(), pin.theta0, 0.3) << pin.joint;
    EXPECT_EQ(p["accel_ticks"].get<int>(), 6) << pin.joint;
  }
}

// Another plant gives that plant's model, not the paper's: one more tick of delay is one more
// tick of lag (l = delay / 8 - 1 under the timing convention in leg_sim.h).
TEST(Regression, IdentifyFindsAnotherPlantsLag) {
  const nlohmann::json t = RunAndRead(LEGLAB_IDENTIFY_BIN, "experiments/configs/identify.yaml",
                                      "--set servo.delay_ms=48", "table1.json");
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    EXPECT_EQ(t["joints"][joint]["lag_ticks"].get<int>(), 5) << joint;
    EXPECT_NEAR(t["joints"][joint]["accel_ticks"].get<int>(), 6, 1) << joint;
    EXPECT_NEAR(t["joints"][joint]["v_max_deg_per_tick"].get<double>(), 2.5, 0.25) << joint;
  }
}

// Shorter than the reproduction (2 warm-up and 4 measured steps): the norms are per step, so
// they match the 20-step means to within the seed spread.
class TrackRegression : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    table_ = new nlohmann::json(RunAndRead(LEGLAB_TRACK_BIN, "experiments/configs/track.yaml",
                                           "--set steps=4 --set warmup_steps=2", "table2.json"));
  }
  static void TearDownTestSuite() { delete table_; }
  static double Mean(const char* joint, const char* row) {
    return (*table_)["joints"][joint][row]["mean"].get<double>();
  }
  static double Foot(const char* mode, const char* norm) {
    return (*table_)["foot_cm"][mode][norm]["mean"].get<double>();
  }
  static nlohmann::json* table_;
};
nlohmann::json* TrackRegression::table_ = nullptr;

TEST_F(TrackRegression, EveryTable2MeanMatchesItsPin) {
  // Pin (seed 1) and tolerance: three times the spread of that mean over seeds 1-5, at least
  // 0.02 deg, and never looser than the earlier rule of max(0.05 deg, 3 %) for L2 rows and
  // max(0.3 deg, 8 %) for L-infinity rows.
  const struct {
    const char* joint;
    const char* row;
    double pin, tolerance;
  } pins[] = {
      {"rotator", "L2(Des,Dir)", 11.412, 0.020}, {"rotator", "Linf(Des,Dir)", 24.841, 0.288},
      {"rotator", "L2(Des,TS)", 1.075, 0.020},   {"rotator", "Linf(Des,TS)", 5.472, 0.288},
      {"rotator", "L2(Des,MB)", 1.509, 0.046},   {"rotator", "Linf(Des,MB)", 3.924, 0.201},
      {"rotator", "L2(Pwl,MB)", 1.250, 0.050},   {"rotator", "Linf(Pwl,MB)", 3.060, 0.300},
      {"abductor", "L2(Des,Dir)", 3.830, 0.023}, {"abductor", "Linf(Des,Dir)", 7.585, 0.293},
      {"abductor", "L2(Des,TS)", 0.254, 0.020},  {"abductor", "Linf(Des,TS)", 0.706, 0.080},
      {"abductor", "L2(Des,MB)", 1.008, 0.020},  {"abductor", "Linf(Des,MB)", 2.407, 0.300},
      {"abductor", "L2(Pwl,MB)", 1.004, 0.020},  {"abductor", "Linf(Pwl,MB)", 2.263, 0.300},
      {"knee", "L2(Des,Dir)", 15.479, 0.043},    {"knee", "Linf(Des,Dir)", 38.953, 0.755},
      {"knee", "L2(Des,TS)", 4.243, 0.048},      {"knee", "Linf(Des,TS)", 18.953, 0.755},
      {"knee", "L2(Des,MB)", 3.460, 0.059},      {"knee", "Linf(Des,MB)", 11.748, 0.776},
      {"knee", "L2(Pwl,MB)", 1.496, 0.050},      {"knee", "Linf(Pwl,MB)", 2.912, 0.300},
  };
  for (const auto& p : pins) {
    EXPECT_NEAR(Mean(p.joint, p.row), p.pin, p.tolerance) << p.joint << " " << p.row;
  }
  // Foot, cm: three times the seed spread, at least 0.005 (L2) and 0.01 (L-infinity).
  const struct {
    const char* mode;
    double l2, l2_tolerance, linf, linf_tolerance;
  } foot[] = {
      {"direct", 1.407, 0.005, 2.301, 0.018},
      {"time_shift", 0.373, 0.005, 1.283, 0.103},
      {"model_based", 0.360, 0.008, 0.915, 0.073},
  };
  for (const auto& f : foot) {
    EXPECT_NEAR(Foot(f.mode, "L2"), f.l2, f.l2_tolerance) << f.mode;
    EXPECT_NEAR(Foot(f.mode, "Linf"), f.linf, f.linf_tolerance) << f.mode;
  }
  EXPECT_EQ((*table_)["foot_cm"]["time_shift"]["k"].get<int>(), 8);  // 8 for every seed
}

// The paper's result in shape (the track issue's bounds, independent of the pins).
TEST_F(TrackRegression, ModelBasedHalvesTheDirectErrors) {
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    EXPECT_LE(Mean(joint, "L2(Des,MB)"), 0.5 * Mean(joint, "L2(Des,Dir)")) << joint;
    EXPECT_LE(Mean(joint, "L2(Pwl,MB)"), 3.5) << joint;
  }
  EXPECT_LE(Foot("model_based", "L2"), 0.5 * Foot("direct", "L2"));
  // The best shift is searched over every k, and k = 0 is the direct method.
  EXPECT_LE(Foot("time_shift", "L2"), Foot("direct", "L2"));
}

}  // namespace
