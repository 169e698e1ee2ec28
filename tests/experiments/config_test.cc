#include "leglab/experiments/config.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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

TEST_F(ConfigTest, SetOverridesComeLastAndTakeYamlValues) {
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot + "servo:\n  gain_per_s: 30\ncontroller:\n  mode: time_shift\n"),
      {"servo.gain_per_s=31.5", "controller.modes=[direct]", "seed=7", "controller.cm=closed",
       "servo.gain_per_s=33"});
  EXPECT_EQ(c.sim.servo.gain_per_s, 33.0);  // the last --set wins
  EXPECT_EQ(Modes(c), std::vector<std::string>{"direct"});
  EXPECT_EQ(c.sim.seed, 7u);
}

TEST_F(ConfigTest, EachModeKeepsItsOwnOptions) {
  const ExperimentConfig c = LoadExperimentConfig(
      Write(kRobot), {"controller.modes=[time_shift, model_based]", "controller.cm=closed",
                      "controller.shift_ticks=9", "controller.pwl_segments=12"});
  ASSERT_EQ(c.controllers.size(), 2u);
  EXPECT_EQ(std::get<TimeShiftController::Spec>(c.controllers[0]).shift_ticks, 9);
  EXPECT_EQ(std::get<ModelBasedController::Spec>(c.controllers[1]).cm, CmMethod::kClosed);
  EXPECT_EQ(c.pwl_segments, 12);
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

TEST_F(ConfigTest, ShippedConfigsLoad) {
  const std::string dir = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";
  for (const char* name : {"identify.yaml", "track.yaml", "controller_direct.yaml",
                           "controller_time_shift.yaml", "controller_model_based.yaml"}) {
    EXPECT_NO_THROW(LoadExperimentConfig(dir + name)) << name;
  }
  EXPECT_EQ(Modes(LoadExperimentConfig(dir + "controller_model_based.yaml")),
            std::vector<std::string>{"model_based"});
}

}  // namespace
}  // namespace leglab::experiments
