#include "leglab/experiments/config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>

namespace leglab::experiments {
namespace {

namespace fs = std::filesystem;

// A scratch config file in a fresh folder.
class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("leglab_config_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& text, const std::string& name = "exp.yaml") {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }

  // The message of the InputError that loading throws, or "" if none.
  std::string ErrorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
    try {
      LoadExperimentConfig(Write(text), overrides);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

// The names of the modes a config runs, in order.
std::vector<std::string> Modes(const ExperimentConfig& c) {
  std::vector<std::string> names;
  for (const ControllerSpec& spec : c.controllers) names.emplace_back(ModeOf(spec).name);
  return names;
}

const std::string kRobot =
    std::string("robot: ") + LEGLAB_SOURCE_DIR + "/robots/ers210a/robot.yaml\n";

// A declared range as messages and docs/configuration.md write it: whole numbers written out,
// others with their shortest round-trip digits in printf's %g notation (fixed from 1e-4 up).
TEST(RangeText, WritesNumbersAsPeopleDo) {
  EXPECT_EQ(RangeText({.min = 1e-4, .max = 100, .unit = "kg"}), "[0.0001, 100] kg");
  EXPECT_EQ(RangeText({.min = 1e-6, .max = 10, .unit = "s"}), "[1e-06, 10] s");
  EXPECT_EQ(RangeText({.min = 0, .max = 1e6, .min_open = true}), "(0, 1000000]");
  EXPECT_EQ(FormatNumber(0.1 + 0.2, NumberStyle::kReadable), "0.30000000000000004");
  EXPECT_EQ(FormatNumber(-2.5e-5, NumberStyle::kReadable), "-2.5e-05");
  EXPECT_EQ(FormatNumber(1e300, NumberStyle::kReadable), "1e+300");
  EXPECT_EQ(FormatNumber(std::nan(""), NumberStyle::kReadable), "nan");
  EXPECT_EQ(FormatNumber(0.0001, NumberStyle::kShortest), "1e-04");  // the files' form stays
}

TEST_F(ConfigTest, RobotYamlIsMergedBeneathTheExperiment) {
  const ExperimentConfig c = LoadExperimentConfig(Write(kRobot + "servo:\n  gain_per_s: 30\n"));
  EXPECT_EQ(c.sim.servo.gain_per_s, 30.0);      // the experiment wins
  EXPECT_GT(c.sim.servo.max_speed_deg_s, 0.0);  // the robot's value stays
  EXPECT_TRUE(fs::exists(c.sim.urdf_path));     // resolved beside robot.yaml
  EXPECT_EQ(fs::path(c.sim.urdf_path).filename(), "leg.urdf");
  EXPECT_FALSE(c.model.has_value());
  EXPECT_EQ(Modes(c), (std::vector<std::string>{"direct", "time_shift", "model_based", "optimal",
                                                "ilc", "adaptive"}));  // every registered mode
}

// An integer out of its range is reported as written: 2^63 - 1 is not rounded to 2^63 on its
// way through a double.
TEST_F(ConfigTest, AnIntegerOutOfRangeIsReportedAsWritten) {
  const std::string error = ErrorOf("robot: ers210a\n", {"seed=9223372036854775807"});
  EXPECT_NE(error.find("got 9223372036854775807"), std::string::npos) << error;
  EXPECT_NE(ErrorOf("robot: ers210a\n", {"steps=1000001"}).find("got 1000001"), std::string::npos);
}

TEST_F(ConfigTest, SetOverridesComeLastAndTakeYamlValues) {
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot + "servo:\n  gain_per_s: 30\ncontroller:\n  mode: time_shift\n"),
      {"servo.gain_per_s=31.5", "controller.modes=[direct]", "seed=7", "controller.cm=closed",
       "servo.gain_per_s=33"});
  EXPECT_EQ(c.sim.servo.gain_per_s, 33.0);  // the last --set wins
  EXPECT_EQ(Modes(c), std::vector<std::string>{"direct"});
  EXPECT_EQ(c.sim.seed, 7u);
}

TEST_F(ConfigTest, ANullOrEmptyValueIsRefusedNamingTheKeyNeverTakenAsTheDefault) {
  const std::string expected = "config: servo.delay_ms must be a value, not null or empty";
  for (const std::string set : {"servo.delay_ms=null", "servo.delay_ms=", "servo.delay_ms=~"}) {
    EXPECT_EQ(ErrorOf(kRobot, {set}).rfind(expected, 0), 0u) << set;
  }
  EXPECT_EQ(ErrorOf(kRobot + "servo:\n  delay_ms:\n").rfind(expected, 0), 0u);
  EXPECT_EQ(ErrorOf(kRobot + "servo:\n  delay_ms: null\n").rfind(expected, 0), 0u);
  // A structured key too; a key left out still takes its default.
  EXPECT_EQ(ErrorOf(kRobot, {"logs.train="}).rfind("config: logs.train must be a value", 0), 0u);
  EXPECT_EQ(ErrorOf(kRobot, {"servo.gain_per_s=30"}), "");
}

TEST_F(ConfigTest, EachModeKeepsItsOwnOptions) {
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot), {"controller.modes=[time_shift, model_based]", "controller.cm=closed",
                      "controller.shift_ticks=9", "controller.pwl_segments=12"});
  ASSERT_EQ(c.controllers.size(), 2u);
  EXPECT_EQ(std::get<TimeShiftController::Spec>(c.controllers[0]).shift_ticks, 9);
  EXPECT_EQ(std::get<ModelBasedController::Spec>(c.controllers[1]).cm, CmMethod::kClosed);
  EXPECT_EQ(std::get<ModelBasedController::Spec>(c.controllers[1]).model, ModelSource::kStepTests);
  EXPECT_EQ(c.pwl_segments, 12);
  const ExperimentConfig o = LoadExperimentConfig(
      Write(kRobot), {"controller.modes=[model_based, optimal]", "controller.model=walk",
                      "optimal.objective=foot", "optimal.joint_weight=0.5", "optimal.model=walk"});
  ASSERT_EQ(o.controllers.size(), 2u);
  EXPECT_EQ(std::get<ModelBasedController::Spec>(o.controllers[0]).model, ModelSource::kWalk);
  const auto& optimal = std::get<OptimalController::Spec>(o.controllers[1]);
  EXPECT_EQ(optimal.objective, Objective::kFoot);
  EXPECT_EQ(optimal.joint_weight, 0.5);
  EXPECT_EQ(optimal.model, ModelSource::kWalk);
  EXPECT_TRUE(UsesWalkModels(o.controllers[0]));
  EXPECT_TRUE(UsesWalkModels(o.controllers[1]));
  EXPECT_FALSE(UsesWalkModels(c.controllers[1]));
}

TEST_F(ConfigTest, PlantIsTheSimOrTheModel) {
  EXPECT_EQ(LoadExperimentConfig(Write(kRobot)).plant, PlantKind::kSim);
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot), {"plant=model", "plant_model.lag_ticks=5", "plant_model.theta0_deg=6"});
  EXPECT_EQ(c.plant, PlantKind::kModel);
  // Unset keys keep the paper's Table 1.
  EXPECT_EQ(c.plant_model, (JointModelParams{2.5, 6.0, 5, 6}));
  EXPECT_NE(ErrorOf(kRobot, {"plant=hardware"}).find("plant"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_model.accel_ticks=0"}).find("plant_model.accel_ticks"),
            std::string::npos);
}

TEST_F(ConfigTest, ALoneModePicksTheModeToRunAndModesWins) {
  EXPECT_EQ(Modes(LoadExperimentConfig(Write(kRobot), {"controller.mode=model_based"})),
            std::vector<std::string>{"model_based"});
  EXPECT_EQ(Modes(LoadExperimentConfig(
                Write(kRobot), {"controller.mode=direct", "controller.modes=[time_shift]"})),
            std::vector<std::string>{"time_shift"});
}

TEST_F(ConfigTest, AKeyThatIsNotAScalarIsBadInput) {
  EXPECT_NE(ErrorOf(kRobot + "? [a, b]\n: 3\n").find("malformed"), std::string::npos);
}

TEST_F(ConfigTest, ModelKeysGiveTheModel) {
  const ExperimentConfig c = LoadExperimentConfig(Write(
      kRobot + "model: {v_max_deg_per_tick: 2.4, theta0_deg: 6, lag_ticks: 3, accel_ticks: 5}\n"));
  ASSERT_TRUE(c.model.has_value());
  EXPECT_EQ(*c.model, (JointModelParams{2.4, 6.0, 3, 5}));
}

TEST_F(ConfigTest, ErrorsNameTheKey) {
  EXPECT_EQ(ErrorOf(kRobot + "servo:\n  delya_ms: 3\n"), "config: unknown key 'servo.delya_ms'");
  EXPECT_EQ(ErrorOf(kRobot + "bogus: 1\n"), "config: unknown key 'bogus'");
  EXPECT_EQ(ErrorOf(kRobot + "servo:\n  gain_per_s: fast\n"),
            "config: servo.gain_per_s: expected a number, got 'fast'");
  EXPECT_NE(ErrorOf(kRobot, {"servo.delay_ms=30"}).find("servo.delay_ms"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"controller.mode=pid"}).find("controller.mode"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"controller.modes=[direct, pid]"}).find("controller.modes"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"controller.cm=approximate"}).find("controller.cm"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"controller.model=paper"}).find("controller.model"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"optimal.objective=hand"}).find("optimal.objective"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"optimal.joint_weight=101"}).find("optimal.joint_weight"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"optimal.model=paper"}).find("optimal.model"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot + "model: {v_max_deg_per_tick: 2.4}\n").find("model.theta0_deg"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"sensor.noise_deg=-1"}).find("sensor.noise_deg"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"steps=0"}).find("steps"), std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"nonsense"}).find("key=value"), std::string::npos);
}

TEST_F(ConfigTest, PlantChangesAreReadInOrderDottedOrNested) {
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot + "plant_changes:\n"
                     "  - {at_step: 3, set: {servo.max_speed_deg_s: 250, servo.delay_ms: 56}}\n"
                     "  - {at_step: 7, set: {sensor: {noise_deg: 0.3}}}\n"));
  ASSERT_EQ(c.plant_changes.size(), 2u);
  EXPECT_EQ(c.plant_changes[0].at_step, 3);
  ASSERT_EQ(c.plant_changes[0].set.size(), 2u);
  EXPECT_EQ(c.plant_changes[0].set[0].key, "servo.max_speed_deg_s");
  EXPECT_EQ(c.plant_changes[0].set[0].value, 250.0);
  EXPECT_EQ(c.plant_changes[0].set[1].key, "servo.delay_ms");
  EXPECT_EQ(c.plant_changes[1].set[0].key, "sensor.noise_deg");
  EXPECT_EQ(c.plant_changes[1].set[0].value, 0.3);
  // The plant as the changes leave it; the config itself keeps the plant it starts with.
  EXPECT_EQ(c.sim.servo.delay_ms, 40.0);
  const ExperimentConfig after = ConfigAfterChanges(c, 1);
  EXPECT_EQ(after.sim.servo.delay_ms, 56.0);
  EXPECT_EQ(after.sim.servo.max_speed_deg_s, 250.0);
  EXPECT_EQ(after.sim.sensor.noise_deg, 0.1);
  EXPECT_TRUE(after.plant_changes.empty());
  EXPECT_EQ(ConfigAfterChanges(c, 2).sim.sensor.noise_deg, 0.3);
  // The model plant changes its model.
  const ExperimentConfig m =
      LoadExperimentConfig(Write(kRobot + "plant: model\nplant_changes: [{at_step: 0, set: "
                                          "{plant_model.lag_ticks: 6}}]\n"));
  EXPECT_EQ(ConfigAfterChanges(m, 1).plant_model.lag_ticks, 6);
}

TEST_F(ConfigTest, PlantChangeErrorsNameTheKeyAsWritten) {
  const std::string change = "plant_changes=[{at_step: 2, set: {servo.delay_ms: 30}}]";
  EXPECT_EQ(ErrorOf(kRobot, {change}),
            "config: plant_changes[0].set.servo.delay_ms must be a non-negative multiple of 8 "
            "ms, got 30");
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 2, set: {servo.colour: 1}}]"})
                .find("plant_changes[0].set.servo.colour cannot change"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 2, set: {seed: 3}}]"})
                .find("plant_changes[0].set.seed"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 2, set: {servo.damping: soft}}]"})
                .find("plant_changes[0].set.servo.damping: expected a number"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 20, set: {servo.damping: 1}}]"})
                .find("plant_changes[0].at_step"),
            std::string::npos);  // steps = 20: step 20 never runs
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 5, set: {servo.damping: 1}}, "
                             "{at_step: 5, set: {servo.damping: 2}}]"})
                .find("plant_changes[1].at_step"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{set: {servo.damping: 1}}]"})
                .find("plant_changes[0].at_step"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 1, set: {}}]"}).find("plant_changes[0].set"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes=[{at_step: 1, sett: {servo.damping: 1}}]"})
                .find("plant_changes[0].sett"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kRobot, {"plant_changes={at_step: 1}"}).find("plant_changes must be a list"),
            std::string::npos);
  // Validated against the plant the earlier changes left: 16 ms more twice is fine, but a
  // smoothing of 4 ms is not whatever came before.
  EXPECT_EQ(ErrorOf(kRobot, {"plant_changes=[{at_step: 1, set: {servo.delay_ms: 56}}, "
                             "{at_step: 2, set: {servo.delay_ms: 72}}]"}),
            "");
  EXPECT_NE(
      ErrorOf(kRobot, {"plant=model", "plant_changes=[{at_step: 1, set: {servo.delay_ms: 56}}]"})
          .find("plant_changes[0].set.servo.delay_ms cannot change on the model plant"),
      std::string::npos);
}

TEST_F(ConfigTest, MissingOrMalformedFilesAreNamed) {
  try {
    LoadExperimentConfig((dir_ / "absent.yaml").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.yaml"), std::string::npos) << e.what();
  }
  EXPECT_NE(ErrorOf("servo: [unclosed\n").find("malformed"), std::string::npos);
  EXPECT_NE(ErrorOf("robot: nosuchrobot\n").find("nosuchrobot"), std::string::npos);
  Write("urdf: missing.urdf\n", "robot.yaml");
  EXPECT_NE(ErrorOf("robot: robot.yaml\n").find("missing.urdf"), std::string::npos);
}

TEST_F(ConfigTest, ExtendsMergesTheBaseFileBeneath) {
  Write(kRobot + "servo: {gain_per_s: 30, smoothing_ms: 24}\ncontroller: {modes: [direct]}\n",
        "base.yaml");
  const ExperimentConfig c =
      LoadExperimentConfig(Write("extends: base.yaml\nservo: {gain_per_s: 31}\n"));
  EXPECT_EQ(c.sim.servo.gain_per_s, 31.0);    // this file wins
  EXPECT_EQ(c.sim.servo.smoothing_ms, 24.0);  // the base's value stays
  EXPECT_EQ(Modes(c), std::vector<std::string>{"direct"});
  Write("extends: loop.yaml\n", "loop.yaml");
  EXPECT_NE(ErrorOf("extends: loop.yaml\n").find("cycle"), std::string::npos);
}

// A numeric key's declared range, as the loader must enforce it.
struct DeclaredRange {
  std::string key;
  std::string text;  // "[0, 400] ms", as messages and docs/configuration.md write it
  double min, max;
  bool min_open, max_open;
};

std::vector<DeclaredRange> NumericKeys() {
  std::vector<DeclaredRange> ranges;
  for (const KeyRow& row : ExperimentKeys({})) {
    if (row.type != "number" && row.type != "integer" && row.type.rfind("list of", 0) != 0) {
      continue;
    }
    if (row.type == "list of {at_step, set}" || row.type == "list of modes" ||
        row.type == "list of files or folders") {
      continue;
    }
    ranges.push_back({row.key, RangeText(row.doc), row.doc.min, row.doc.max, row.doc.min_open,
                      row.doc.max_open});
  }
  return ranges;
}

// YAML text of `v`: an integer as digits (so integer keys read it), else 17 digits.
std::string YamlNumber(double v) {
  if (v == std::round(v) && std::abs(v) < 9.22e18) {
    return std::to_string(static_cast<long long>(v));
  }
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", v);
  return buffer;
}

// `key=value`, a list value for the list keys.
std::string Assign(const std::string& key, const std::string& x) {
  if (key == "identify.theta_test_deg") return key + "=[" + x + "]";
  if (key == "identify.hold_deg") return key + "=[" + x + ", 0, 0]";
  if (key == "identify.lag_range_ticks" || key == "identify.accel_range_ticks") {
    return key + "=[" + x + ", " + x + "]";
  }
  return key + "=" + x;
}

// Every numeric key has a finite range, and the loader holds every value to it: just outside
// each end is rejected naming the key and the range, at (or just inside an open) end accepted.
TEST(ConfigRanges, EveryNumericKeyHasARangeTheLoaderEnforces) {
  const std::vector<DeclaredRange> declared = NumericKeys();
  EXPECT_GE(declared.size(), 60u);
  for (const DeclaredRange& r : declared) {
    EXPECT_TRUE(std::isfinite(r.min) && std::isfinite(r.max)) << r.key;
  }
  const std::string track = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/track.yaml";
  // One mode, so that the largest steps stay inside the run's size limits; what some keys need
  // beside them to be in range at all.
  const std::vector<std::string> base = {"controller.modes=[direct]"};
  for (const DeclaredRange& r : declared) {
    std::vector<std::string> overrides = base;
    if (r.key == "controller.pwl_segments") overrides.emplace_back("track.t_step_ticks=1000");
    if (r.key == "track.t_step_ticks") overrides.emplace_back("controller.pwl_segments=1");
    if (r.key == "identify.t_step_ticks" || r.key == "identify.record_cycles") {
      // One (l, a) candidate and one step height: the fit's work stays within its own limit.
      for (const char* o : {"identify.lag_range_ticks=[4, 4]", "identify.accel_range_ticks=[6, 6]",
                            "identify.theta_test_deg=[40]"}) {
        overrides.emplace_back(o);
      }
    }
    if (r.key == "desired.locus.liftoff_ramp_mm") {
      // A ramp needs its ticks, and its line must stay under the arc's top: 50 mm over 40 of
      // the 44 flight ticks reaches 50 (1 + a) / (2 a) = 52.5 mm there, under 100.
      overrides.emplace_back("desired.locus.liftoff_ramp_ticks=40");
      overrides.emplace_back("desired.locus.height_mm=100");
    }
    if (r.key == "servo.max_speed_deg_s") {
      // The top of its range, 3600 deg/s, needs a physics step of at most 2000 / 3600 ms.
      overrides.emplace_back("sim.physics_dt_ms=0.5");
    }
    if (r.key.rfind("model.", 0) == 0) {  // model.* needs all four keys
      overrides.emplace_back(
          "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}");
    }
    auto error_of = [&](const std::string& v) {
      std::vector<std::string> o = overrides;
      o.push_back(Assign(r.key, v));
      try {
        LoadExperimentConfig(track, o);
      } catch (const InputError& e) {
        return std::string(e.what());
      }
      return std::string();
    };
    const double below_delta = std::max(1.0, 1e-3 * std::abs(r.min));
    const double above_delta = std::max(1.0, 1e-3 * std::abs(r.max));
    const double inside = 1e-3 * std::max(1.0, r.max - r.min);
    const std::string expected = r.key + " must be in " + r.text;
    // Just outside each end: rejected, naming the key and its documented range.
    for (const double out :
         {r.min_open ? r.min : r.min - below_delta, r.max_open ? r.max : r.max + above_delta}) {
      const std::string error = error_of(YamlNumber(out));
      EXPECT_NE(error.find(expected), std::string::npos)
          << r.key << "=" << YamlNumber(out) << ": " << error;
    }
    for (const char* non_finite : {".nan", ".inf", "-.inf"}) {
      EXPECT_NE(error_of(non_finite).find(r.key), std::string::npos) << r.key << non_finite;
    }
    // At (or just inside an open) end: accepted.
    for (const double in :
         {r.min_open ? r.min + inside : r.min, r.max_open ? r.max - inside : r.max}) {
      EXPECT_EQ(error_of(YamlNumber(in)), "") << r.key << "=" << YamlNumber(in);
    }
  }
}

TEST_F(ConfigTest, ShippedConfigsLoad) {
  const std::string dir = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
  for (const char* name : {"identify.yaml", "track.yaml", "controller_direct.yaml",
                           "controller_time_shift.yaml", "controller_model_based.yaml"}) {
    EXPECT_NO_THROW(LoadExperimentConfig(dir + name)) << name;
  }
  EXPECT_EQ(Modes(LoadExperimentConfig(dir + "controller_model_based.yaml")),
            std::vector<std::string>{"model_based"});
}

// A change of the running servo changes that setting and nothing else: the stand the plant
// was built with stays, its belt still following the walk.
TEST_F(ConfigTest, AChangeOfTheServoKeepsTheStand) {
  const std::string dir = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
  const ExperimentConfig c = LoadExperimentConfig(
      dir + "track_stand.yaml",
      {"plant_changes=[{at_step: 0, set: {servo.delay_ms: 56, sensor.noise_deg: 0.2}}]"});
  const ExperimentConfig after = ConfigAfterChanges(c, 1);
  EXPECT_EQ(after.sim.servo.delay_ms, 56.0);
  EXPECT_EQ(after.sim.sensor.noise_deg, 0.2);
  EXPECT_TRUE(after.sim.stand.enabled);
  EXPECT_EQ(after.sim.stand.belt_speed_mm_per_s, c.sim.stand.belt_speed_mm_per_s);
  EXPECT_EQ(after.sim.stand.sled_stiffness_n_per_m, c.sim.stand.sled_stiffness_n_per_m);
  sim::SimConfig direct = c.sim;
  sim::SetSimSetting(direct, "servo.gain_per_s", 50.0);
  EXPECT_EQ(direct.servo.gain_per_s, 50.0);
  EXPECT_TRUE(direct.stand.enabled);
  EXPECT_EQ(direct.stand.belt_follows_walk, c.sim.stand.belt_follows_walk);
  EXPECT_THROW(sim::SetSimSetting(direct, "stand.load_kg", 1.0), std::invalid_argument);
}

TEST_F(ConfigTest, TheStandIsBuiltOnlyFromAStandSection) {
  const std::string dir = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
  // The air leg: no stand, whatever its defaults say.
  EXPECT_FALSE(LoadExperimentConfig(dir + "track.yaml").sim.stand.enabled);
  for (const char* name :
       {"track_stand.yaml", "identify_stand.yaml", "identify_stand_loaded.yaml"}) {
    const ExperimentConfig config = LoadExperimentConfig(dir + name);
    EXPECT_TRUE(config.sim.stand.enabled) << name;
    // A quarter of the ERS-210A's 1.5 kg; the floor at the walk's ground.
    EXPECT_EQ(config.sim.stand.load_kg, 0.375) << name;
    EXPECT_EQ(config.sim.stand.ground_below_shoulder_mm, 100.0) << name;
    // The front leg's URDF, not a copy.
    EXPECT_EQ(
        std::filesystem::canonical(config.sim.urdf_path),
        std::filesystem::canonical(std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf"))
        << name;
  }
  // The belt runs at the walk's stance speed: 48.93 mm in 44 ticks of 8 ms, unless told.
  EXPECT_NEAR(LoadExperimentConfig(dir + "track_stand.yaml").sim.stand.belt_speed_mm_per_s,
              48.93 / (44 * 0.008), 1e-9);
  EXPECT_EQ(LoadExperimentConfig(dir + "identify_stand_loaded.yaml").sim.stand.belt_speed_mm_per_s,
            0.0);
  // The floor follows the walk's ground.
  EXPECT_EQ(
      LoadExperimentConfig(dir + "track_stand.yaml", {"desired.locus.ground_below_shoulder_mm=105"})
          .sim.stand.ground_below_shoulder_mm,
      105.0);
}

}  // namespace
}  // namespace leglab::experiments
