// The single-leg test stand against hand-worked statics and physical bounds: the
// carriage resting on its stop, the foot carrying the supported weight, no interpenetration at
// rest, no energy gained in a passive drop, bad stand values rejected, and the air leg unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/core/plant.h"
#include "leglab/sim/leg_sim.h"

namespace leglab::sim {
namespace {

const std::string kUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";

// The leg's moving masses as robots/ers210a/leg.urdf gives them (rotator housing, upper leg,
// lower leg with paw), kg, and g: the supported weight is worked from these, not from the sim.
constexpr double kLegMassKg = 0.05 + 0.073 + 0.073;
constexpr double kG = 9.81;
// The shoulder's height in the body frame (URDF rotator origin z) and the walk's ground.
constexpr double kShoulderZMm = 0.0;

SimConfig StandConfigFor(double load_kg = 0.375) {
  SimConfig config;
  config.urdf_path = kUrdf;
  config.sensor.noise_deg = 0.0;
  config.stand.enabled = true;
  config.stand.load_kg = load_kg;
  config.stand.stop_below_shoulder_mm = 5.0;
  config.stand.friction = 1.0;
  config.stand.contact_stiffness_n_per_m = 20000.0;
  config.stand.contact_damping_n_s_per_m = 100.0;
  config.stand.foot_radius_mm = 13.96;
  config.stand.ground_below_shoulder_mm = 100.0;
  return config;
}

// Height of the floor plane in the body frame at carriage height 0, mm.
double FloorZMm(const SimConfig& c) {
  return kShoulderZMm - c.stand.ground_below_shoulder_mm - c.stand.foot_radius_mm;
}

// How far the foot sphere reaches into the floor, mm (negative: a gap), from the foot's
// centre in the body frame and the carriage height.
double PenetrationMm(const LegSim& sim) {
  const double foot_world_z = sim.FootPositionMm()[2] + sim.Telemetry().carriage_z_mm;
  return FloorZMm(sim.config()) + sim.config().stand.foot_radius_mm - foot_world_z;
}

// The floor's force on the foot (N, body axes) and the sled's x (mm), averaged over the next
// `ticks` ticks of `sim`.
struct MeanTelemetry {
  std::array<double, 3> force_n{};
  double sled_x_mm = 0.0;
};
MeanTelemetry TickAndAverage(LegSim& sim, int ticks) {
  MeanTelemetry mean;
  for (int t = 0; t < ticks; ++t) {
    sim.Tick();
    for (int k = 0; k < 3; ++k) mean.force_n[k] += sim.Telemetry().contact_force_n[k] / ticks;
    mean.sled_x_mm += sim.Telemetry().sled_x_mm / ticks;
  }
  return mean;
}

TEST(StandTest, CarriageRestsOnTheStopWithTheFootInTheAir) {
  const SimConfig config = StandConfigFor();
  LegSim sim(config);
  // Knee at 90 deg: the foot is about 45 mm below the shoulder, far above the floor (114 mm).
  sim.SetJointAnglesDeg({0.0, 0.0, 90.0});
  for (int t = 0; t < 125; ++t) sim.Tick();  // 1 s
  const PlantTelemetry& telemetry = sim.Telemetry();
  EXPECT_EQ(telemetry.contact_force_n[0], 0.0);
  EXPECT_EQ(telemetry.contact_force_n[1], 0.0);
  EXPECT_EQ(telemetry.contact_force_n[2], 0.0);
  EXPECT_NEAR(telemetry.carriage_z_mm, -config.stand.stop_below_shoulder_mm, 0.05);
  EXPECT_LT(PenetrationMm(sim), -20.0);
  EXPECT_EQ(telemetry.slip_mm, 0.0);
}

class StandStaticLoadTest : public ::testing::TestWithParam<double> {};

TEST_P(StandStaticLoadTest, FloorCarriesTheSupportedWeight) {
  const double load_kg = GetParam();
  const SimConfig config = StandConfigFor(load_kg);
  LegSim sim(config);
  // Knee at 30 deg: at carriage height 0 the foot centre would be 111.7 mm below the shoulder
  // (64 - 18.88 sin 30 + 66 cos 30), 11.7 mm into the walk's ground: the foot stands on the
  // floor with the carriage lifted about 11.7 mm, off its stop.
  sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
  for (int t = 0; t < 250; ++t) sim.Tick();  // 2 s to settle
  const auto [fx, fy, fz] = TickAndAverage(sim, 25).force_n;
  // Statics: the carriage is off the stop, the slider carries no vertical force, so the floor
  // carries the load and the leg.
  const double weight_n = (load_kg + kLegMassKg) * kG;
  RecordProperty("fz_n", std::to_string(fz));
  RecordProperty("weight_n", std::to_string(weight_n));
  RecordProperty("penetration_mm", std::to_string(PenetrationMm(sim)));
  RecordProperty("carriage_z_mm", std::to_string(sim.Telemetry().carriage_z_mm));
  EXPECT_NEAR(fz, weight_n, 0.02 * weight_n);
  EXPECT_LT(std::abs(fx), 0.02 * weight_n);
  EXPECT_LT(std::abs(fy), 0.02 * weight_n);
  EXPECT_GT(sim.Telemetry().carriage_z_mm, -config.stand.stop_below_shoulder_mm + 1.0);
  // At rest the ball of the foot sinks into the floor by the spring's deflection, W / k, and
  // never more than 1 mm.
  const double penetration_mm = PenetrationMm(sim);
  EXPECT_LT(penetration_mm, 1.0);
  EXPECT_NEAR(penetration_mm, 1000.0 * weight_n / config.stand.contact_stiffness_n_per_m, 0.1);
  // Standing still, the foot does not slide (rolling is not counted).
  EXPECT_LT(sim.Telemetry().slip_mm, 0.5);
}

INSTANTIATE_TEST_SUITE_P(Loads, StandStaticLoadTest, ::testing::Values(0.375, 0.1, 0.8));

TEST(StandTest, AStillFootOnTheRunningBeltSlidesAtTheBeltSpeedAgainstCoulombFriction) {
  SimConfig config = StandConfigFor();
  config.stand.friction = 0.5;
  config.stand.belt_speed_mm_per_s = 100.0;  // backward, along -x
  LegSim sim(config);
  sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
  for (int t = 0; t < 125; ++t) sim.Tick();  // 1 s to settle
  const double slip_before = sim.Telemetry().slip_mm;
  const auto [fx, fy, fz] = TickAndAverage(sim, 125).force_n;
  // The servos hold the foot still, so the belt slides under it: Coulomb friction mu N drags
  // it backward, and the slip grows by the belt's speed times the time, 100 mm in 1 s.
  const double weight_n = (config.stand.load_kg + kLegMassKg) * kG;
  EXPECT_NEAR(fz, weight_n, 0.02 * weight_n);
  EXPECT_NEAR(fx, -config.stand.friction * fz, 0.02 * config.stand.friction * fz);
  EXPECT_NEAR(sim.Telemetry().slip_mm - slip_before, 100.0, 2.0);
}

struct DropCase {
  const char* name;
  LegAngles pose_deg;
};

class StandDropTest : public ::testing::TestWithParam<DropCase> {};

TEST_P(StandDropTest, PassiveDropGainsNoEnergy) {
  LegSim sim(StandConfigFor());
  // The motors go limp: the leg folds or straightens under gravity, the foot strikes the
  // floor, the carriage falls onto its stop.
  sim.SetJointAnglesDeg(GetParam().pose_deg);
  sim.SetMotorsEnabled(false);
  const double initial = sim.MechanicalEnergyJ();
  double peak_kinetic = 0.0;
  double peak_force = 0.0;
  double lowest_carriage_mm = sim.Telemetry().carriage_z_mm;
  for (int t = 0; t < 250; ++t) {  // 2 s
    sim.Tick();
    peak_kinetic = std::max(peak_kinetic, sim.world().KineticEnergyJ());
    peak_force = std::max(peak_force, sim.Telemetry().contact_force_n[2]);
    lowest_carriage_mm = std::min(lowest_carriage_mm, sim.Telemetry().carriage_z_mm);
    // The spring of the contact stores energy the sum leaves out; it only ever lowers it.
    ASSERT_LE(sim.MechanicalEnergyJ() - initial, 0.01 * peak_kinetic) << "tick " << t;
  }
  EXPECT_GT(peak_force, 0.1);  // the foot did hit (or stood on) the floor
  EXPECT_GT(peak_kinetic, 1e-3);
  EXPECT_LT(sim.MechanicalEnergyJ(), initial);
  // The stop holds the carriage (its softness lets it sink a little under impact).
  EXPECT_GT(lowest_carriage_mm, -sim.config().stand.stop_below_shoulder_mm - 1.0);
}

INSTANTIATE_TEST_SUITE_P(Drops, StandDropTest,
                         ::testing::Values(
                             // Knee flexed, foot in the air, carriage on its stop: the leg swings
                             // down onto the floor.
                             DropCase{"LegOntoTheFloor", {20.0, 0.0, 100.0}},
                             // Standing, the carriage 11.4 mm up: the leg folds and the carriage
                             // drops 16 mm onto its stop.
                             DropCase{"CarriageOntoTheStop", {0.0, 0.0, 30.0}}),
                         [](const ::testing::TestParamInfo<DropCase>& drop) {
                           return std::string(drop.param.name);
                         });

TEST(StandTest, SameConfigSameBits) {
  auto run = [] {
    LegSim sim(StandConfigFor());
    sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
    std::vector<double> out;
    for (int t = 0; t < 100; ++t) {
      sim.SetRequestsDeg({10.0 * std::sin(t * 0.1), 5.0, 30.0 + 20.0 * std::sin(t * 0.07)});
      sim.Tick();
      const PlantTelemetry& m = sim.Telemetry();
      out.insert(out.end(), {m.contact_force_n[0], m.contact_force_n[2], m.carriage_z_mm, m.slip_mm,
                             sim.TrueDeg()[2]});
    }
    return out;
  };
  EXPECT_EQ(run(), run());
}

TEST(StandTest, WithoutAStandTheTelemetryIsZero) {
  SimConfig config = StandConfigFor();
  config.stand.enabled = false;
  LegSim sim(config);
  sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
  for (int t = 0; t < 10; ++t) sim.Tick();
  EXPECT_FALSE(sim.world().has_stand());
  const PlantTelemetry& m = sim.Telemetry();
  EXPECT_EQ(m.contact_force_n[2], 0.0);
  EXPECT_EQ(m.carriage_z_mm, 0.0);
  EXPECT_EQ(m.slip_mm, 0.0);
}

TEST(StandTest, BadStandValuesNameTheKey) {
  auto error_of = [](auto change) {
    SimConfig config = StandConfigFor();
    change(config.stand);
    try {
      ValidateSimConfig(config);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of([](StandConfig& s) { s.load_kg = -0.1; }).find("stand.load_kg"),
            std::string::npos);
  // A carriage of next to no mass: refused, not left to fail inside ODE's step.
  EXPECT_NE(error_of([](StandConfig& s) { s.load_kg = 1e-300; }).find("stand.load_kg"),
            std::string::npos);
  EXPECT_EQ(error_of([](StandConfig& s) { s.load_kg = 0.01; }), "");
  EXPECT_NE(error_of([](StandConfig& s) { s.friction = -0.5; }).find("stand.friction"),
            std::string::npos);
  EXPECT_NE(error_of([](StandConfig& s) {
              s.stop_below_shoulder_mm = -2.0;
            }).find("stand.stop_below_shoulder_mm"),
            std::string::npos);
  EXPECT_EQ(error_of([](StandConfig& s) { s.friction = 0.0; }), "");
  // Off, the stand's values are not looked at.
  SimConfig off = StandConfigFor();
  off.stand.enabled = false;
  off.stand.load_kg = -1.0;
  EXPECT_NO_THROW(ValidateSimConfig(off));
}

// The sled (stand.sled_*): the rail on a cross slide held by a spring-damper along x and y. The
// body's horizontal mass is the load's and the leg's (the slides' own is neglected).
SimConfig SledConfigFor(double stiffness_n_per_m, double damping_n_s_per_m) {
  SimConfig config = StandConfigFor();
  config.stand.sled_stiffness_n_per_m = stiffness_n_per_m;
  config.stand.sled_damping_n_s_per_m = damping_n_s_per_m;
  return config;
}

double HorizontalMassKg(const SimConfig& config) { return config.stand.load_kg + kLegMassKg; }

TEST(StandSledTest, TheBeltDeflectsTheSledByFrictionOverStiffness) {
  // The foot held still on the running belt (as above): the belt drags it backward with
  // Coulomb friction mu N, and the body gives until the sled's spring carries that force:
  // x = -mu N / k, with N the supported weight (the rail still carries nothing vertical).
  // mu 0.5, N = 0.571 x 9.81 = 5.60 N, k = 200 N/m: x = -14.0 mm.
  SimConfig config = SledConfigFor(200.0, 20.0);
  config.stand.friction = 0.5;
  config.stand.belt_speed_mm_per_s = 100.0;
  LegSim sim(config);
  sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
  for (int t = 0; t < 250; ++t) sim.Tick();  // 2 s: the sled settles (damping ratio 1.7)
  const MeanTelemetry mean = TickAndAverage(sim, 125);
  const auto [fx, fy, fz] = mean.force_n;
  const double x = mean.sled_x_mm;
  const double weight_n = (config.stand.load_kg + kLegMassKg) * kG;
  const double expected_mm = -1000.0 * config.stand.friction * weight_n / 200.0;
  RecordProperty("sled_x_mm", std::to_string(x));
  EXPECT_NEAR(fz, weight_n, 0.02 * weight_n);
  EXPECT_NEAR(fx, -config.stand.friction * weight_n, 0.02 * config.stand.friction * weight_n);
  EXPECT_NEAR(x, expected_mm, 0.02 * std::abs(expected_mm));
}

TEST(StandSledTest, StandingStillTheSledRestsAtItsSpringsRest) {
  // On a still floor nothing pushes the body sideways: the floor carries the weight, the
  // spring nothing.
  LegSim sim(SledConfigFor(200.0, 20.0));
  sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
  for (int t = 0; t < 250; ++t) sim.Tick();
  const double weight_n = (sim.config().stand.load_kg + kLegMassKg) * kG;
  EXPECT_NEAR(sim.Telemetry().contact_force_n[2], weight_n, 0.02 * weight_n);
  EXPECT_LT(std::abs(sim.Telemetry().sled_x_mm), 0.05);
  EXPECT_LT(std::abs(sim.Telemetry().sled_y_mm), 0.05);
  EXPECT_LT(sim.Telemetry().slip_mm, 0.5);
}

struct SwingCase {
  const char* name;
  LegAngles request_deg;  // from {0, 0, 90}
  int axis;               // 0: the sled's x, 1: its y
};

class StandSledSwingTest : public ::testing::TestWithParam<SwingCase> {};

TEST_P(StandSledSwingTest, TheBodyOscillatesOnTheSledWithPeriodTwoPiRootMOverK) {
  // The foot in the air (knee at 90 deg, the carriage on its stop), no damping: one joint swings
  // the leg 30 deg and holds it; the reaction sets the body oscillating on the sled, a mass
  // m = load + leg (held rigid by its servos) on the spring k, along either axis:
  // T = 2 pi sqrt(m / k) = 2 pi sqrt(0.571 / 200) = 0.336 s. Timed from upward zero crossings
  // of the position about its mean, interpolated between ticks, over the periods after the
  // swing.
  const SimConfig config = SledConfigFor(200.0, 0.0);
  LegSim sim(config);
  sim.SetJointAnglesDeg({0.0, 0.0, 90.0});
  sim.SetRequestsDeg(GetParam().request_deg);
  for (int t = 0; t < 63; ++t) sim.Tick();  // 0.5 s: the swing is over
  std::vector<double> x;
  for (int t = 0; t < 250; ++t) {  // 2 s, about 6 periods
    sim.Tick();
    x.push_back(GetParam().axis == 0 ? sim.Telemetry().sled_x_mm : sim.Telemetry().sled_y_mm);
  }
  double mean = 0.0;
  for (const double v : x) mean += v / static_cast<double>(x.size());
  std::vector<double> crossings_s;
  for (size_t i = 1; i < x.size(); ++i) {
    const double a = x[i - 1] - mean;
    const double b = x[i] - mean;
    if (a < 0.0 && b >= 0.0)
      crossings_s.push_back(kTickMs / 1000.0 * (static_cast<double>(i - 1) + a / (a - b)));
  }
  ASSERT_GE(crossings_s.size(), 4U);
  const double period_s =
      (crossings_s.back() - crossings_s.front()) / static_cast<double>(crossings_s.size() - 1);
  const double expected_s = 2.0 * std::numbers::pi * std::sqrt(HorizontalMassKg(config) / 200.0);
  RecordProperty("period_s", std::to_string(period_s));
  EXPECT_NEAR(period_s, expected_s, 0.01 * expected_s);
  // It does swing: the reaction of a 30 deg swing moves the body millimetres.
  EXPECT_GT(*std::max_element(x.begin(), x.end()) - *std::min_element(x.begin(), x.end()), 0.5);
}

INSTANTIATE_TEST_SUITE_P(Swings, StandSledSwingTest,
                         ::testing::Values(
                             // The rotator swings the leg forward: the body moves along x.
                             SwingCase{"RotatorAlongX", {30.0, 0.0, 90.0}, 0},
                             // The abductor swings it outward: the body moves along y.
                             SwingCase{"AbductorAlongY", {0.0, 30.0, 90.0}, 1}),
                         [](const ::testing::TestParamInfo<SwingCase>& swing) {
                           return std::string(swing.param.name);
                         });

TEST(StandSledTest, PassiveDropOnTheSledGainsNoEnergy) {
  // As StandDropTest, with the body free to move along x and y on an undamped spring: the limp leg
  // swings down onto the floor, throwing the body sideways; the sum (the spring's energy
  // included) never grows.
  LegSim sim(SledConfigFor(200.0, 0.0));
  sim.SetJointAnglesDeg({20.0, 0.0, 100.0});
  sim.SetMotorsEnabled(false);
  const double initial = sim.MechanicalEnergyJ();
  double peak_kinetic = 0.0;
  double sled_travel_mm = 0.0;
  for (int t = 0; t < 250; ++t) {  // 2 s
    sim.Tick();
    peak_kinetic = std::max(peak_kinetic, sim.world().KineticEnergyJ());
    sled_travel_mm = std::max(sled_travel_mm, std::abs(sim.Telemetry().sled_x_mm));
    ASSERT_LE(sim.MechanicalEnergyJ() - initial, 0.01 * peak_kinetic) << "tick " << t;
  }
  EXPECT_GT(peak_kinetic, 1e-3);
  EXPECT_GT(sled_travel_mm, 0.1);  // the sled did move
  EXPECT_LT(sim.MechanicalEnergyJ(), initial);
}

TEST(StandSledTest, WithoutStiffnessThereIsNoSledAndTheSameBits) {
  // Stiffness 0 is the rigid rail: the same world as a StandConfig that never names the sled,
  // whatever the damping says, bit for bit.
  auto run = [](const SimConfig& config) {
    LegSim sim(config);
    sim.SetJointAnglesDeg({0.0, 0.0, 30.0});
    std::vector<double> out;
    for (int t = 0; t < 100; ++t) {
      sim.SetRequestsDeg({10.0 * std::sin(t * 0.1), 5.0, 30.0 + 20.0 * std::sin(t * 0.07)});
      sim.Tick();
      const PlantTelemetry& m = sim.Telemetry();
      out.insert(out.end(), {m.contact_force_n[0], m.contact_force_n[2], m.carriage_z_mm, m.slip_mm,
                             m.sled_x_mm, sim.TrueDeg()[0], sim.TrueDeg()[2]});
    }
    return out;
  };
  const std::vector<double> rigid = run(StandConfigFor());
  EXPECT_EQ(rigid, run(SledConfigFor(0.0, 50.0)));
  for (size_t i = 4; i < rigid.size(); i += 7) EXPECT_EQ(rigid[i], 0.0);  // the sled's x + y
}

TEST(StandSledTest, BadSledValuesNameTheKey) {
  auto error_of = [](double k, double c) {
    try {
      ValidateSimConfig(SledConfigFor(k, c));
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of(-1.0, 0.0).find("stand.sled_stiffness_n_per_m"), std::string::npos);
  EXPECT_NE(error_of(100.0, -1.0).find("stand.sled_damping_n_s_per_m"), std::string::npos);
  EXPECT_EQ(error_of(0.0, 0.0), "");
}

}  // namespace
}  // namespace leglab::sim
