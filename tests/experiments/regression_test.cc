// CI regression of the paper's tables: identify and track on the default configuration (the
// shipped configs and robot.yaml), short runs, against pinned values.
//
// Pins are seed 1's results; each tolerance is three times the spread of that value over seeds
// 1-5 (with a small floor), so a change of the sensor noise passes and a change of the plant,
// the model or a controller that moves a norm by a few times the noise does not. Changing a
// pin is a deliberate commit that says why.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/model/paper.h"
#include "leglab/sim/sim_config.h"

namespace leglab::experiments {
namespace {

const std::string kConfigs = std::string(LEGLAB_SOURCE_DIR) + "/experiments/configs/";

// Table 1 as `identify` computes it, in-process.
Table1 Identify(const std::string& config_file, const std::vector<std::string>& overrides = {}) {
  const ExperimentConfig config = LoadExperimentConfig(kConfigs + config_file, overrides);
  return ComputeTable1(IdentifyLeg(config, LoadRobot(config.sim.urdf_path)), config.identify);
}

// The paper's Table 1 and the tolerances the plant must meet (the simulated plant's target).
TEST(Regression, IdentifyFindsTable1OnTheDefaultRobot) {
  const Table1 t = Identify("identify.yaml");
  const JointModelParams& paper = paper::kTable1;
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = t.joints[j].params;
    EXPECT_NEAR(p.v_max_deg_per_tick, paper.v_max_deg_per_tick, 0.25) << kLegJointNames[j];
    EXPECT_NEAR(p.theta0_deg, paper.theta0_deg, 1.5) << kLegJointNames[j];
    EXPECT_EQ(p.lag_ticks, paper.lag_ticks) << kLegJointNames[j];
    EXPECT_NEAR(p.accel_ticks, paper.accel_ticks, 1) << kLegJointNames[j];
    EXPECT_LT(t.joints[j].rms_residual_deg, 0.5) << kLegJointNames[j];
  }
  // Pinned (seed 1): l and a exactly, the continuous parameters to well inside the spread a
  // seed change gives (0.01 deg/tick, 0.1 deg).
  const struct {
    double v_max, theta0;
  } pins[kLegJoints] = {{2.50, 5.65}, {2.52, 8.34}, {2.50, 5.64}};
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = t.joints[j].params;
    EXPECT_NEAR(p.v_max_deg_per_tick, pins[j].v_max, 0.03) << kLegJointNames[j];
    EXPECT_NEAR(p.theta0_deg, pins[j].theta0, 0.3) << kLegJointNames[j];
    EXPECT_EQ(p.accel_ticks, 6) << kLegJointNames[j];
  }
}

// The fit, made about 20 times cheaper, keeps its optimum: on the shipped config,
// both legs (bit for bit the same Table 1), the same (l, a) and v_max, theta_0 and the residual
// of the previous fit (Nelder-Mead throughout, main at baec711), all digits, to well within
// that optimiser's own convergence on this kinked objective (about 1e-8). The fit of every
// recorded tick (identify.average_cycles false), whose objective that was.
TEST(Regression, IdentifyFindsThePreviousFitsOptimum) {
  const struct {
    double v_max, theta0, rms;
  } previous[kLegJoints] = {{2.5002719543219065, 5.651132229163377, 0.36962764763388967},
                            {2.5168968496451387, 8.3235428376165, 0.29000048028836395},
                            {2.499979703479546, 5.649753492996907, 0.3769958026818238}};
  for (const std::string robot : {"ers210a", "ers210a_hind"}) {
    const Table1 t = Identify("identify.yaml", {"robot=" + robot, "identify.average_cycles=false"});
    for (int j = 0; j < kLegJoints; ++j) {
      const JointModelParams& p = t.joints[j].params;
      EXPECT_EQ(p.lag_ticks, 4) << robot << " " << kLegJointNames[j];
      EXPECT_EQ(p.accel_ticks, 6) << robot << " " << kLegJointNames[j];
      EXPECT_NEAR(p.v_max_deg_per_tick, previous[j].v_max, 1e-5 * previous[j].v_max)
          << robot << " " << kLegJointNames[j];
      EXPECT_NEAR(p.theta0_deg, previous[j].theta0, 1e-5 * previous[j].theta0)
          << robot << " " << kLegJointNames[j];
      EXPECT_NEAR(t.joints[j].rms_residual_deg, previous[j].rms, 1e-9 * previous[j].rms)
          << robot << " " << kLegJointNames[j];
    }
  }
}

// The shipped fit of the step tests' averaged cycles (identify.average_cycles) against
// the fit of every recorded tick on the same recordings: the same (l, a), v_max and theta_0
// well inside what a change of seed moves them (0.01 deg/tick, 0.1 deg: the pins above), and
// the residual over every recorded tick within 0.005 deg (the averaged fit scores from the
// cycle's start, the other from its warm-up on).
TEST(Regression, IdentifyAveragedAgreesWithTheFitOfEveryTick) {
  for (const char* plant : {"seed=1", "seed=4", "servo.delay_ms=48"}) {
    const Table1 averaged = Identify("identify.yaml", {plant});
    const Table1 every = Identify("identify.yaml", {plant, "identify.average_cycles=false"});
    for (int j = 0; j < kLegJoints; ++j) {
      const JointModelParams& a = averaged.joints[j].params;
      const JointModelParams& e = every.joints[j].params;
      EXPECT_EQ(a.lag_ticks, e.lag_ticks) << plant << " " << kLegJointNames[j];
      EXPECT_EQ(a.accel_ticks, e.accel_ticks) << plant << " " << kLegJointNames[j];
      EXPECT_NEAR(a.v_max_deg_per_tick, e.v_max_deg_per_tick, 0.003)
          << plant << " " << kLegJointNames[j];
      EXPECT_NEAR(a.theta0_deg, e.theta0_deg, 0.03) << plant << " " << kLegJointNames[j];
      EXPECT_NEAR(averaged.joints[j].rms_residual_deg, every.joints[j].rms_residual_deg, 0.005)
          << plant << " " << kLegJointNames[j];
    }
  }
}

// Another plant gives that plant's model, not the paper's: one more tick of delay is one more
// tick of lag (l = delay / 8 - 1 under the timing convention in leg_sim.h).
TEST(Regression, IdentifyFindsAnotherPlantsLag) {
  const Table1 t = Identify("identify.yaml", {"servo.delay_ms=48"});
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = t.joints[j].params;
    EXPECT_EQ(p.lag_ticks, 5) << kLegJointNames[j];
    EXPECT_NEAR(p.accel_ticks, 6, 1) << kLegJointNames[j];
    EXPECT_NEAR(p.v_max_deg_per_tick, 2.5, 0.25) << kLegJointNames[j];
  }
}

// ---- The second engine -------------------------------------------------------------------

// Table 1 on DART (sim.engine: dart) is ODE's: l and a the same, and v_max and theta_0 no
// further from ODE's seed-1 values than ODE's own values spread over seeds 1-3 (the sensor
// noise's doing), which is what an engine that does not matter must give.
TEST(EngineRegression, Table1OnDartIsOdesWithinTheSeedSpread) {
  if (!sim::BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  const Table1 dart = Identify("identify.yaml", {"sim.engine=dart"});
  std::array<Table1, 3> ode{Identify("identify.yaml"), Identify("identify.yaml", {"seed=2"}),
                            Identify("identify.yaml", {"seed=3"})};
  for (int j = 0; j < kLegJoints; ++j) {
    const auto spread = [&](auto field) {
      double low = field(ode[0].joints[j].params), high = low;
      for (const Table1& t : ode) {
        low = std::min(low, field(t.joints[j].params));
        high = std::max(high, field(t.joints[j].params));
      }
      return high - low;
    };
    const auto v_max = [](const JointModelParams& p) { return p.v_max_deg_per_tick; };
    const auto theta0 = [](const JointModelParams& p) { return p.theta0_deg; };
    const JointModelParams& on_dart = dart.joints[j].params;
    const JointModelParams& on_ode = ode[0].joints[j].params;
    EXPECT_EQ(on_dart.lag_ticks, on_ode.lag_ticks) << kLegJointNames[j];
    EXPECT_EQ(on_dart.accel_ticks, on_ode.accel_ticks) << kLegJointNames[j];
    EXPECT_LE(std::abs(v_max(on_dart) - v_max(on_ode)), spread(v_max)) << kLegJointNames[j];
    EXPECT_LE(std::abs(theta0(on_dart) - theta0(on_ode)), spread(theta0)) << kLegJointNames[j];
  }
}

// Table 2's finding holds on both engines: model-based at least halves the direct foot error,
// and its ratio to direct on DART is within 20 % of ODE's.
TEST(EngineRegression, Table2sOrderingHoldsOnBothEngines) {
  if (!sim::BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  std::array<double, 2> ratio{};
  for (const bool on_dart : {false, true}) {
    std::vector<std::string> overrides = {"steps=4", "warmup_steps=2",
                                          "controller.modes=[direct, model_based]"};
    if (on_dart) overrides.push_back("sim.engine=dart");
    const Table2 table =
        ComputeTable2(RunTrackExperiment(LoadExperimentConfig(kConfigs + "track.yaml", overrides)));
    const FootRow* direct = table.FindFoot("direct");
    const FootRow* model_based = table.FindFoot("model_based");
    ASSERT_NE(direct, nullptr);
    ASSERT_NE(model_based, nullptr);
    ratio[on_dart ? 1 : 0] = model_based->l2_cm.mean / direct->l2_cm.mean;
    EXPECT_LE(ratio[on_dart ? 1 : 0], 0.5) << (on_dart ? "dart" : "ode");
  }
  EXPECT_NEAR(ratio[1], ratio[0], 0.2 * ratio[0]);
}

// Shorter than the reproduction (2 warm-up and 4 measured steps): the norms are per step, so
// they match the 20-step means to within the seed spread.
class TrackRegression : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    table_.emplace(ComputeTable2(RunTrackExperiment(
        LoadExperimentConfig(kConfigs + "track.yaml", {"steps=4", "warmup_steps=2"}))));
  }
  static void TearDownTestSuite() { table_.reset(); }
  static double Mean(const char* joint, const char* row) {
    const Table2Row* found = table_->Find(row);
    EXPECT_NE(found, nullptr) << row;
    for (int j = 0; j < kLegJoints; ++j) {
      if (kLegJointNames[j] == joint) return found ? found->joints[j].mean : NAN;
    }
    ADD_FAILURE() << joint;
    return NAN;
  }
  static double Foot(const char* mode, const char* norm) {
    const FootRow* found = table_->FindFoot(mode);
    EXPECT_NE(found, nullptr) << mode;
    if (!found) return NAN;
    return std::string(norm) == "L2" ? found->l2_cm.mean : found->linf_cm.mean;
  }
  static std::optional<Table2> table_;
};
std::optional<Table2> TrackRegression::table_;

TEST_F(TrackRegression, EveryTable2MeanMatchesItsPin) {
  // Pin (seed 1) and tolerance: three times the spread of that mean over seeds 1-5, at least
  // 0.02 deg, and never looser than the earlier rule of max(0.05 deg, 3 %) for L2 rows and
  // max(0.3 deg, 8 %) for L-infinity rows.
  const struct {
    const char* joint;
    const char* row;
    double pin, tolerance;
  } pins[] = {
      {"rotator", "L2(Des,Dir)", 11.412, 0.020},
      {"rotator", "Linf(Des,Dir)", 24.841, 0.288},
      {"rotator", "L2(Des,TS)", 1.075, 0.020},
      {"rotator", "Linf(Des,TS)", 5.472, 0.288},
      {"rotator", "L2(Des,MB)", 1.509, 0.046},
      {"rotator", "Linf(Des,MB)", 3.924, 0.201},
      {"rotator", "L2(Pwl,MB)", 1.250, 0.050},
      {"rotator", "Linf(Pwl,MB)", 3.060, 0.300},
      {"abductor", "L2(Des,Dir)", 3.830, 0.023},
      {"abductor", "Linf(Des,Dir)", 7.585, 0.293},
      {"abductor", "L2(Des,TS)", 0.254, 0.020},
      {"abductor", "Linf(Des,TS)", 0.706, 0.080},
      {"abductor", "L2(Des,MB)", 1.008, 0.020},
      {"abductor", "Linf(Des,MB)", 2.407, 0.300},
      {"abductor", "L2(Pwl,MB)", 1.004, 0.020},
      {"abductor", "Linf(Pwl,MB)", 2.263, 0.300},
      {"knee", "L2(Des,Dir)", 15.479, 0.043},
      {"knee", "Linf(Des,Dir)", 38.953, 0.755},
      {"knee", "L2(Des,TS)", 4.243, 0.048},
      {"knee", "Linf(Des,TS)", 18.953, 0.755},
      {"knee", "L2(Des,MB)", 3.460, 0.059},
      {"knee", "Linf(Des,MB)", 11.748, 0.776},
      {"knee", "L2(Pwl,MB)", 1.496, 0.050},
      {"knee", "Linf(Pwl,MB)", 2.912, 0.300},
      // The floor, optimal and ilc rows, by the same rule of three times the seed
      // spread, at least 0.02 deg. ILC's rows are those of the foot objective track.yaml ships
      // (ilc.objective: foot, joint_weight 2), still learning in this short run; optimal's those of
      // track.yaml's optimal (objective foot, joint_weight 2, model walk, request_smoothing 0.3).
      {"rotator", "L2(Des,Floor)", 0.671, 0.020},
      {"rotator", "Linf(Des,Floor)", 3.882, 0.020},
      {"rotator", "L2(Des,Opt)", 1.105, 0.022},
      {"rotator", "Linf(Des,Opt)", 5.338, 0.294},
      {"rotator", "L2(Des,ILC)", 0.898, 0.231},
      {"rotator", "Linf(Des,ILC)", 4.665, 1.148},
      {"abductor", "L2(Des,Floor)", 0.000, 0.020},
      {"abductor", "Linf(Des,Floor)", 0.000, 0.020},
      {"abductor", "L2(Des,Opt)", 0.183, 0.038},
      {"abductor", "Linf(Des,Opt)", 0.518, 0.114},
      {"abductor", "L2(Des,ILC)", 0.231, 0.119},
      {"abductor", "Linf(Des,ILC)", 0.513, 0.932},
      {"knee", "L2(Des,Floor)", 3.064, 0.020},
      {"knee", "Linf(Des,Floor)", 14.057, 0.020},
      {"knee", "L2(Des,Opt)", 3.155, 0.062},
      {"knee", "Linf(Des,Opt)", 13.729, 0.648},
      {"knee", "L2(Des,ILC)", 3.197, 0.173},
      {"knee", "Linf(Des,ILC)", 14.404, 2.511},
  };
  for (const auto& p : pins) {
    EXPECT_NEAR(Mean(p.joint, p.row), p.pin, p.tolerance) << p.joint << " " << p.row;
  }
  // Foot, cm: three times the seed spread, at least 0.005 (L2) and 0.01 (L-infinity).
  const struct {
    const char* mode;
    double l2, l2_tolerance, linf, linf_tolerance;
  } foot[] = {
      {"direct", 1.407, 0.005, 2.301, 0.018},      {"time_shift", 0.373, 0.005, 1.283, 0.103},
      {"model_based", 0.360, 0.008, 0.915, 0.073}, {"floor", 0.296, 0.005, 0.964, 0.010},
      {"optimal", 0.252, 0.008, 0.718, 0.089},     {"ilc", 0.285, 0.016, 0.907, 0.369},
  };
  for (const auto& f : foot) {
    EXPECT_NEAR(Foot(f.mode, "L2"), f.l2, f.l2_tolerance) << f.mode;
    EXPECT_NEAR(Foot(f.mode, "Linf"), f.linf, f.linf_tolerance) << f.mode;
  }
  const FootRow* shift = table_->FindFoot("time_shift");
  ASSERT_NE(shift, nullptr);
  EXPECT_EQ(shift->parameters, (std::vector<std::pair<std::string_view, long>>{{"k", 8}}))
      << "8 for every seed";
}

// The paper's result in shape (bounds independent of the pins).
TEST_F(TrackRegression, ModelBasedHalvesTheDirectErrors) {
  for (const char* joint : {"rotator", "abductor", "knee"}) {
    EXPECT_LE(Mean(joint, "L2(Des,MB)"), 0.5 * Mean(joint, "L2(Des,Dir)")) << joint;
    EXPECT_LE(Mean(joint, "L2(Pwl,MB)"), 3.5) << joint;
  }
  EXPECT_LE(Foot("model_based", "L2"), 0.5 * Foot("direct", "L2"));
  // The best shift is searched over every k, and k = 0 is the direct method.
  EXPECT_LE(Foot("time_shift", "L2"), Foot("direct", "L2"));
}

// Table 2 in the paper's regime: track_paper_regime.yaml, the walk fit_walk fitted
// to the paper's direct row, with the three modes of the paper's tables, 2 warm-up and 4
// measured steps. Pins are seed 1's; tolerances three times the spread over seeds 1-5, at least
// 0.02 deg, 0.005 cm (foot L2) and 0.01 cm (foot L-infinity).
class PaperRegimeRegression : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    table_.emplace(ComputeTable2(RunTrackExperiment(LoadExperimentConfig(
        kConfigs + "track_paper_regime.yaml",
        {"steps=4", "warmup_steps=2", "controller.modes=[direct, time_shift, model_based]"}))));
  }
  static void TearDownTestSuite() { table_.reset(); }
  static std::optional<Table2> table_;
};
std::optional<Table2> PaperRegimeRegression::table_;

TEST_F(PaperRegimeRegression, EveryMeanMatchesItsPin) {
  const struct {
    int joint;
    const char* row;
    double pin, tolerance;
  } pins[] = {
      {kRotator, "L2(Des,Dir)", 21.657, 0.028},   {kRotator, "Linf(Des,Dir)", 70.451, 0.218},
      {kRotator, "L2(Des,TS)", 10.273, 0.041},    {kRotator, "L2(Des,MB)", 8.507, 0.029},
      {kRotator, "Linf(Des,MB)", 29.133, 0.223},  {kRotator, "L2(Pwl,MB)", 1.038, 0.037},
      {kAbductor, "L2(Des,Dir)", 16.280, 0.029},  {kAbductor, "Linf(Des,Dir)", 46.994, 0.350},
      {kAbductor, "L2(Des,TS)", 5.733, 0.025},    {kAbductor, "L2(Des,MB)", 5.409, 0.025},
      {kAbductor, "Linf(Des,MB)", 23.642, 0.369}, {kAbductor, "L2(Pwl,MB)", 0.940, 0.020},
      {kKnee, "L2(Des,Dir)", 15.045, 0.040},      {kKnee, "Linf(Des,Dir)", 38.382, 0.755},
      {kKnee, "L2(Des,TS)", 3.994, 0.045},        {kKnee, "L2(Des,MB)", 3.531, 0.050},
      {kKnee, "Linf(Des,MB)", 11.128, 0.751},     {kKnee, "L2(Pwl,MB)", 0.883, 0.060},
  };
  for (const auto& p : pins) {
    const Table2Row* row = table_->Find(p.row);
    ASSERT_NE(row, nullptr) << p.row;
    EXPECT_NEAR(row->joints[p.joint].mean, p.pin, p.tolerance)
        << kLegJointNames[p.joint] << " " << p.row;
  }
  const struct {
    const char* mode;
    double l2, l2_tolerance, linf, linf_tolerance;
  } foot[] = {
      {"direct", 2.313, 0.005, 4.937, 0.038},
      {"time_shift", 0.832, 0.005, 1.827, 0.033},
      {"model_based", 0.777, 0.005, 2.237, 0.046},
  };
  for (const auto& f : foot) {
    const FootRow* row = table_->FindFoot(f.mode);
    ASSERT_NE(row, nullptr) << f.mode;
    EXPECT_NEAR(row->l2_cm.mean, f.l2, f.l2_tolerance) << f.mode;
    EXPECT_NEAR(row->linf_cm.mean, f.linf, f.linf_tolerance) << f.mode;
  }
  const FootRow* shift = table_->FindFoot("time_shift");
  ASSERT_NE(shift, nullptr);
  EXPECT_EQ(shift->parameters, (std::vector<std::pair<std::string_view, long>>{{"k", 12}}))
      << "12 for every seed";
}

// The walk on the single-leg test stand: track_stand.yaml, every mode, the matched
// swing and the slow lift-off it ships (desired.locus.swing_end_speed_fraction 1,
// liftoff_ramp_mm 8 over liftoff_ramp_ticks 5), 2 warm-up and 4 measured steps.
// Pins are seed 1's; tolerances three times the spread over seeds 1-5, at least 0.05 mm of
// slip per stance, 0.005 of the stance's vertical force over the carried weight and 0.005 cm
// of foot L2. (Direct and time shift are the same walk shifted, and feed-forward: the sensor
// noise leaves them unmoved.)
class StandRegression : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    table_.emplace(ComputeTable2(RunTrackExperiment(
        LoadExperimentConfig(kConfigs + "track_stand.yaml", {"steps=4", "warmup_steps=2"}))));
  }
  static void TearDownTestSuite() { table_.reset(); }
  static const StandRow* Row(const char* mode) {
    for (const StandRow& row : table_->stand->modes) {
      if (row.mode == mode) return &row;
    }
    ADD_FAILURE() << mode;
    return nullptr;
  }
  static std::optional<Table2> table_;
};
std::optional<Table2> StandRegression::table_;

TEST_F(StandRegression, SlipForceAndFootMatchTheirPins) {
  ASSERT_TRUE(table_->stand.has_value());
  const double weight = table_->stand->carried_weight_n;
  const struct {
    const char* mode;
    double slip, slip_tolerance, fz_over_weight, fz_tolerance, l2, l2_tolerance;
  } pins[] = {
      {"direct", 1.080, 0.050, 1.067, 0.005, 1.512, 0.005},
      {"time_shift", 1.080, 0.050, 1.067, 0.005, 0.302, 0.005},
      {"model_based", 1.218, 0.050, 1.073, 0.005, 0.365, 0.006},
      {"optimal", 0.527, 0.053, 0.954, 0.008, 0.249, 0.005},
      {"ilc", 1.273, 0.158, 0.977, 0.017, 0.294, 0.007},
      {"adaptive", 1.102, 0.871, 1.062, 0.033, 0.250, 0.039},
  };
  for (const auto& p : pins) {
    const StandRow* row = Row(p.mode);
    ASSERT_NE(row, nullptr);
    EXPECT_NEAR(row->slip_stat_mm.mean, p.slip, p.slip_tolerance) << p.mode;
    EXPECT_NEAR(row->stance_fz_n.mean / weight, p.fz_over_weight, p.fz_tolerance) << p.mode;
    const FootRow* foot = table_->FindFoot(p.mode);
    ASSERT_NE(foot, nullptr) << p.mode;
    EXPECT_NEAR(foot->l2_cm.mean, p.l2, p.l2_tolerance) << p.mode;
  }
}

// The stand's targets that the shipped stand meets, as bounds independent of the pins: the
// stance carries the weight within 10 % for direct and model-based (and, with the slow
// lift-off, for every mode), the foot slips less than 2 mm per stance for every mode (optimal
// and ILC with their requests smoothed), and model-based keeps the foot at most 0.6 x direct's
// L2 on the stand.
TEST_F(StandRegression, TheStanceCarriesTheWeightAndModelBasedBeatsDirect) {
  ASSERT_TRUE(table_->stand.has_value());
  const double weight = table_->stand->carried_weight_n;
  for (const char* mode : {"direct", "model_based"}) {
    const StandRow* row = Row(mode);
    ASSERT_NE(row, nullptr);
    EXPECT_NEAR(row->stance_fz_n.mean / weight, 1.0, 0.10) << mode;
  }
  for (const StandRow& row : table_->stand->modes) {
    EXPECT_NEAR(row.stance_fz_n.mean / weight, 1.0, 0.10) << row.mode;
  }
  EXPECT_EQ(table_->stand->modes.size(), 6U);  // track_stand.yaml's every mode
  for (const StandRow& row : table_->stand->modes) {
    EXPECT_LT(row.slip_stat_mm.mean, 2.0) << row.mode;
  }
  const FootRow* direct = table_->FindFoot("direct");
  const FootRow* model_based = table_->FindFoot("model_based");
  ASSERT_NE(direct, nullptr);
  ASSERT_NE(model_based, nullptr);
  EXPECT_LE(model_based->l2_cm.mean, 0.6 * direct->l2_cm.mean);
}

// Walks nobody tuned for: a sine and a triangle wave per joint through desired.csv,
// at the paper's step time and at half of it (rotator 65 + 20 w(p), abductor 21 + 8 w(p + 1),
// knee 45 + 30 w(p + 2) deg, p = 2 pi t / T; docs/results/beyond.md's table), and a trapezoid (the
// triangle times 1.6, clipped to +-1) at the paper's step time, one of docs/results/beyond.md's
// held-out walks. On each, ILC (track.yaml's foot objective) must put the foot nearer its path than
// the paper's method and the best time shift do, over the shipped run (5 warm-up and 20 measured
// steps: on the slow sine ILC is still gaining after 4). So must optimal (track.yaml's: foot
// objective with move suppression, model fitted to the walk); on the slow triangle and the
// trapezoid only since its sweeps lower the suppression too (0.093 and 0.118 cm against the
// time shift's 0.102 and 0.126; before, 0.112 and 0.136: requests chattering at the model's
// averaging period from the corners on, docs/results/beyond.md, "The slow triangle").
double Triangle(double phase) {
  const double x = phase / (2.0 * std::numbers::pi) - std::floor(phase / (2.0 * std::numbers::pi));
  return x < 0.25 ? 4.0 * x : (x < 0.75 ? 2.0 - 4.0 * x : 4.0 * x - 4.0);
}

double Sine(double phase) { return std::sin(phase); }

double Trapezoid(double phase) { return std::clamp(1.6 * Triangle(phase), -1.0, 1.0); }

TEST(UntunedWalks, IlcAndOptimalBeatModelBasedAndTheBestTimeShiftAtTheFoot) {
  // Per process: two test runs at once (say a release and a sanitizer build) must not share it.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("leglab_untuned_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  struct Walk {
    const char* name;
    double (*wave)(double);
    int period;
  };
  for (const Walk& walk :
       {Walk{"sine", Sine, 88}, Walk{"triangle", Triangle, 88}, Walk{"sine", Sine, 44},
        Walk{"triangle", Triangle, 44}, Walk{"trapezoid", Trapezoid, 88}}) {
    const std::filesystem::path csv =
        dir / (std::string(walk.name) + "_" + std::to_string(walk.period) + ".csv");
    {
      std::ofstream out(csv);
      out << "tick,rotator_deg,abductor_deg,knee_deg\n";
      out.precision(17);
      for (int t = 0; t < walk.period; ++t) {
        const double p = 2.0 * std::numbers::pi * t / walk.period;
        out << t << "," << 65.0 + 20.0 * walk.wave(p) << "," << 21.0 + 8.0 * walk.wave(p + 1.0)
            << "," << 45.0 + 30.0 * walk.wave(p + 2.0) << "\n";
      }
    }
    const Table2 table = ComputeTable2(RunTrackExperiment(LoadExperimentConfig(
        kConfigs + "track.yaml",
        {"desired.csv=" + csv.string(), "track.t_step_ticks=" + std::to_string(walk.period),
         "controller.modes=[time_shift, model_based, optimal, ilc]"})));
    auto foot = [&](const char* mode) {
      const FootRow* row = table.FindFoot(mode);
      EXPECT_NE(row, nullptr) << mode;
      return row ? row->l2_cm.mean : NAN;
    };
    const std::string name = csv.filename().string();
    EXPECT_LT(foot("ilc"), foot("model_based")) << name;
    EXPECT_LT(foot("ilc"), foot("time_shift")) << name;
    EXPECT_LT(foot("optimal"), foot("model_based")) << name;
    EXPECT_LT(foot("optimal"), foot("time_shift")) << name;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace leglab::experiments
