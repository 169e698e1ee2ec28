#include "leglab/sim/leg_sim.h"
#include "leglab/core/plant.h"
#include "leglab/core/units.h"
#include "temp_urdf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace leglab::sim {
namespace {

const std::string kUrdf = std::string(LEGLAB_SOURCE_DIR) + "/robots/ers210a/leg.urdf";

SimConfig Config(double delay_ms = 32.0, double noise_deg = 0.0) {
  SimConfig config;
  config.urdf_path = kUrdf;
  config.servo.delay_ms = delay_ms;
  config.sensor.noise_deg = noise_deg;
  return config;
}

// ---- Step response -------------------------------------------------------------------

class StepDelayTest : public ::testing::TestWithParam<double> {};

TEST_P(StepDelayTest, JointStartsMovingExactlyAfterTheDelay) {
  const double delay_ms = GetParam();
  const int delay_ticks = static_cast<int>(delay_ms / kTickMs);
  LegSim sim(Config(delay_ms));
  sim.SetJointAnglesDeg({0.0, 10.0, 30.0});
  // Let the leg settle under gravity while holding.
  for (int t = 0; t < 20; ++t) {
    sim.Tick();
  }
  const double before = sim.MeasuredDeg()[0];

  sim.SetRequestsDeg({40.0, 10.0, 30.0});  // the step, at tick t0
  for (int k = 0; k <= delay_ticks; ++k) {
    sim.Tick();  // tick t0 + k
    const double moved = sim.MeasuredDeg()[0] - before;
    if (k < delay_ticks) {
      // Still holding: at most settling creep (measurement is quantised to 1 urad = 6e-5 deg).
      EXPECT_LT(std::abs(moved), 1e-3) << "tick t0+" << k;
    } else {
      EXPECT_GT(moved, 0.05) << "tick t0+" << k;  // the first tick of motion
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Delays, StepDelayTest, ::testing::Values(0.0, 8.0, 32.0, 40.0));

TEST(LegSimTest, SpeedNeverExceedsTheTopSpeed) {
  LegSim sim(Config(32.0));
  sim.SetJointAnglesDeg({-55.0, 0.0, 100.0});
  const double top_deg_per_tick = sim.config().servo.max_speed_deg_s * kTickMs / 1000.0;  // 2.5
  // 110 deg steps back and forth on every joint's range.
  const LegAngles a{-55.0, 0.0, 100.0};
  const LegAngles b{55.0, 80.0, -20.0};
  double fastest = 0.0;
  LegAngles previous = sim.TrueDeg();
  for (int t = 0; t < 300; ++t) {
    sim.SetRequestsDeg((t / 75) % 2 == 0 ? b : a);
    sim.Tick();
    const LegAngles now = sim.TrueDeg();
    for (int j = 0; j < kLegJoints; ++j) {
      const double speed = std::abs(now[j] - previous[j]);
      fastest = std::max(fastest, speed);
      // ODE's velocity motor holds the servo speed to round-off; allow 0.2 %.
      EXPECT_LE(speed, top_deg_per_tick * 1.002) << kLegJointNames[j] << " tick " << t;
    }
    previous = now;
  }
  EXPECT_GT(fastest, top_deg_per_tick * 0.99);  // and it does reach top speed
}

TEST(LegSimTest, RequestsOutsideTheLimitsAreClamped) {
  LegSim sim(Config(0.0));
  sim.SetRequestsDeg({500.0, -90.0, 200.0});
  EXPECT_EQ(sim.CommandedDeg(), (LegAngles{0.0, 0.0, 0.0}));  // taken at the next Tick
  double highest_knee = -1e9;
  for (int t = 0; t < 150; ++t) {
    sim.Tick();
    highest_knee = std::max(highest_knee, sim.TrueDeg()[2]);
  }
  const LegAngles commanded = sim.CommandedDeg();
  // The URDF gives the limits in radians to 10 decimals.
  EXPECT_NEAR(commanded[0], 117.0, 1e-6);
  EXPECT_NEAR(commanded[1], -11.0, 1e-6);
  EXPECT_NEAR(commanded[2], 147.0, 1e-6);
  const LegAngles reached = sim.TrueDeg();
  EXPECT_NEAR(reached[0], 117.0, 0.2);
  EXPECT_NEAR(reached[1], -11.0, 0.2);
  EXPECT_NEAR(reached[2], 147.0, 0.2);
  // Overshoot past the software limit stays short of the mechanical stop 3 deg beyond.
  EXPECT_LT(highest_knee, 150.0);
}

TEST(LegSimTest, NonFiniteRequestNamesTheJoint) {
  LegSim sim(Config());
  try {
    sim.SetRequestsDeg({0.0, std::nan(""), 0.0});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'abductor'"), std::string::npos) << error.what();
  }
}

TEST(LegSimTest, TeleportOutsideTheLimitsNamesTheJoint) {
  LegSim sim(Config());
  try {
    sim.SetJointAnglesDeg({0.0, 0.0, 160.0});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'knee'"), std::string::npos) << error.what();
  }
}

TEST(LegSimTest, TeleportHoldsStill) {
  LegSim sim(Config());
  sim.SetJointAnglesDeg({30.0, 40.0, 90.0});
  EXPECT_EQ(sim.CommandedDeg()[2], sim.TrueDeg()[2]);
  for (int t = 0; t < 50; ++t) {
    sim.Tick();
  }
  const LegAngles held = sim.TrueDeg();
  EXPECT_NEAR(held[0], 30.0, 0.05);
  EXPECT_NEAR(held[1], 40.0, 0.05);
  EXPECT_NEAR(held[2], 90.0, 0.05);
  EXPECT_EQ(sim.tick(), 50);
}

TEST(LegSimTest, MotorsOffLetTheLegSwingAndOnHoldsIt) {
  LegSim sim(Config());
  sim.SetJointAnglesDeg({60.0, 0.0, 0.0});
  sim.SetMotorsEnabled(false);
  const double initial = sim.MechanicalEnergyJ();
  double lowest_rotator = 60.0;
  double peak_kinetic = 0.0;
  for (int t = 0; t < 125; ++t) {  // 1 s
    sim.Tick();
    lowest_rotator = std::min(lowest_rotator, sim.TrueDeg()[0]);
    peak_kinetic = std::max(peak_kinetic, sim.world().KineticEnergyJ());
    // A passive pendulum (hitting the knee stop on the way): energy never grows beyond
    // integration wobble (see leg_world_test.cc).
    ASSERT_LE(sim.MechanicalEnergyJ() - initial, 0.01 * peak_kinetic) << "tick " << t;
  }
  EXPECT_LT(lowest_rotator, 0.0);  // the unpowered leg swung down and through under gravity
  sim.SetMotorsEnabled(true);
  sim.SetRequestsDeg({0.0, 0.0, 0.0});
  for (int t = 0; t < 100; ++t) {
    sim.Tick();
  }
  EXPECT_NEAR(sim.TrueDeg()[0], 0.0, 0.1);
}

// ---- Determinism ---------------------------------------------------------------------

struct Trace {
  std::vector<double> measured;
  std::vector<double> truth;
};

Trace RunWithSeed(std::uint64_t seed) {
  SimConfig config = Config(40.0, 0.1);
  config.seed = seed;
  LegSim sim(config);
  Trace trace;
  for (int t = 0; t < 150; ++t) {
    const double phase = 2.0 * 3.141592653589793 * t / 88.0;
    sim.SetRequestsDeg({30.0 * std::sin(phase), 20.0 + 15.0 * std::cos(phase),
                        60.0 + 40.0 * std::sin(2.0 * phase)});
    sim.Tick();
    for (double v : sim.MeasuredDeg()) {
      trace.measured.push_back(v);
    }
    for (double v : sim.TrueDeg()) {
      trace.truth.push_back(v);
    }
  }
  return trace;
}

bool BitIdentical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(LegSimTest, SameSeedGivesBitIdenticalTraces) {
  const Trace first = RunWithSeed(5);
  const Trace second = RunWithSeed(5);
  EXPECT_TRUE(BitIdentical(first.measured, second.measured));
  EXPECT_TRUE(BitIdentical(first.truth, second.truth));
}

TEST(LegSimTest, OtherSeedChangesOnlyTheNoise) {
  const Trace first = RunWithSeed(5);
  const Trace other = RunWithSeed(6);
  EXPECT_FALSE(BitIdentical(first.measured, other.measured));
  // The firmware acts on the true angle, so the physics does not see the sensor noise.
  EXPECT_TRUE(BitIdentical(first.truth, other.truth));
}

// Experiments may run one plant per thread: separate LegSims must not share state.
TEST(LegSimTest, PlantsOnParallelThreadsMatchSerialRuns) {
  const Trace serial = RunWithSeed(11);
  std::vector<Trace> parallel(3);
  {
    std::vector<std::thread> threads;
    threads.reserve(parallel.size());
    for (Trace& trace : parallel) {
      threads.emplace_back([&trace] { trace = RunWithSeed(11); });
    }
    for (std::thread& thread : threads) {
      thread.join();
    }
  }
  for (const Trace& trace : parallel) {
    EXPECT_TRUE(BitIdentical(trace.measured, serial.measured));
    EXPECT_TRUE(BitIdentical(trace.truth, serial.truth));
  }
}

// ---- As a leglab::Plant -----------------------------------------------------------------

LegAngles Wave(int t) {
  const double phase = 2.0 * 3.141592653589793 * t / 88.0;
  return {30.0 * std::sin(phase), 20.0 + 15.0 * std::cos(phase),
          60.0 + 40.0 * std::sin(2.0 * phase)};
}

bool SameBits(const LegAngles& a, const LegAngles& b) {
  for (int j = 0; j < kLegJoints; ++j) {
    if (std::bit_cast<std::uint64_t>(a[j]) != std::bit_cast<std::uint64_t>(b[j])) {
      return false;
    }
  }
  return true;
}

LegAngles ToDegrees(const LegAngles& rad) {
  return {RadToDeg(rad[0]), RadToDeg(rad[1]), RadToDeg(rad[2])};
}

// Two plants with the same seed: one driven by the LegSim calls, one through Plant&. Every
// reading has the same bits; the true angles are also ODE's hinge angles read directly.
TEST(LegSimPlantTest, PlantCallsGiveTheSameBitsAsTheLegSimCalls) {
  SimConfig config = Config(40.0, 0.1);
  config.seed = 3;
  LegSim old_calls(config);
  LegSim plant_sim(config);
  Plant& plant = plant_sim;
  const LegAngles pose{10.0, 20.0, 40.0};
  old_calls.SetJointAnglesDeg(pose);
  plant.Reset(pose);
  EXPECT_TRUE(SameBits(plant.Read().measured_deg, old_calls.MeasuredDeg()));
  for (int t = 0; t < 200; ++t) {
    old_calls.SetRequestsDeg(Wave(t));
    old_calls.Tick();
    const PlantReading& reading = plant.Tick(Wave(t));
    ASSERT_TRUE(SameBits(reading.measured_deg, old_calls.MeasuredDeg())) << "tick " << t;
    ASSERT_TRUE(SameBits(reading.true_deg, old_calls.TrueDeg())) << "tick " << t;
    ASSERT_TRUE(SameBits(reading.applied_deg, old_calls.CommandedDeg())) << "tick " << t;
    ASSERT_TRUE(SameBits(reading.true_deg, ToDegrees(plant_sim.world().AnglesRad())))
        << "tick " << t;
    ASSERT_EQ(&plant.Read(), &reading);  // the latest reading, kept by the plant
  }
  EXPECT_EQ(plant_sim.tick(), 200);
}

TEST(LegSimPlantTest, AppliedIsTheClampedRequest) {
  LegSim sim(Config(0.0));
  Plant& plant = sim;
  const PlantReading& beyond = plant.Tick({500.0, -90.0, 200.0});
  // The limits: rotator -117..117, abductor -11..89, knee -27..147 deg (radians to 10
  // decimals in the URDF).
  EXPECT_NEAR(beyond.applied_deg[0], 117.0, 1e-6);
  EXPECT_NEAR(beyond.applied_deg[1], -11.0, 1e-6);
  EXPECT_NEAR(beyond.applied_deg[2], 147.0, 1e-6);
  const LegAngles within{-30.0, 45.0, -20.0};
  const PlantReading& inside = plant.Tick(within);
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_NEAR(inside.applied_deg[j], within[j], 1e-12) << kLegJointNames[j];
  }
}

TEST(LegSimPlantTest, ReadingIsValidAfterConstructionAndReset) {
  LegSim sim(Config(32.0, 0.1));
  const Plant& plant = sim;
  EXPECT_EQ(plant.name(), "sim");
  EXPECT_EQ(plant.Read().true_deg, (LegAngles{0.0, 0.0, 0.0}));
  EXPECT_EQ(plant.Read().applied_deg, (LegAngles{0.0, 0.0, 0.0}));
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_LT(std::abs(plant.Read().measured_deg[j]), 1.0);  // 10 sigma of the noise
  }
  sim.Tick(LegAngles{20.0, 20.0, 20.0});
  const LegAngles pose{-40.0, 60.0, 120.0};
  sim.Reset(pose);
  EXPECT_EQ(sim.tick(), 1);  // Reset does not advance time
  for (int j = 0; j < kLegJoints; ++j) {
    EXPECT_NEAR(plant.Read().true_deg[j], pose[j], 1e-9) << kLegJointNames[j];
    EXPECT_NEAR(plant.Read().applied_deg[j], pose[j], 1e-12) << kLegJointNames[j];
    EXPECT_NEAR(plant.Read().measured_deg[j], pose[j], 1.0) << kLegJointNames[j];
  }
}

TEST(LegSimPlantTest, BadRequestAndPoseNameTheJoint) {
  LegSim sim(Config());
  Plant& plant = sim;
  try {
    plant.Tick({0.0, 0.0, std::nan("")});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'knee'"), std::string::npos) << error.what();
  }
  try {
    plant.Reset({-120.0, 0.0, 0.0});
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("'rotator'"), std::string::npos) << error.what();
  }
  EXPECT_EQ(sim.tick(), 0);
}

// ---- Errors --------------------------------------------------------------------------

TEST(LegSimTest, BadConfigValueNamesTheKey) {
  SimConfig config = Config();
  config.servo.delay_ms = 30.0;
  try {
    LegSim sim(config);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "servo.delay_ms must be a non-negative multiple of 8 ms, got 30");
  }
}

TEST(LegSimTest, MissingUrdfNamesTheFile) {
  SimConfig config = Config();
  config.urdf_path = "no/such/leg.urdf";
  try {
    LegSim sim(config);
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no/such/leg.urdf"), std::string::npos);
  }
}

TEST(LegSimTest, ExplodingStateThrowsSimErrorNamingTheTick) {
  // A servo asked for absurd speeds tears the integration apart.
  SimConfig config = Config(0.0);
  config.servo.max_speed_deg_s = 1e12;
  config.servo.gain_per_s = 1e12;
  config.servo.smoothing_ms = 0.0;
  LegSim sim(config);
  sim.SetRequestsDeg({100.0, 80.0, 140.0});
  try {
    for (int t = 0; t < 10; ++t) {
      sim.Tick();
    }
    FAIL() << "no error";
  } catch (const SimError& error) {
    EXPECT_NE(std::string(error.what()).find("control tick 0"), std::string::npos) << error.what();
  }
}

// ---- What only DART can ------------------------------------------------------------

// Full-range square waves on every joint from rest at one end, `ticks` long: the joints at the
// servo's top speed most of the time. Returns the first breakdown's message, or "" with every
// reading finite and each true angle inside its stops (the URDF limits, kStopMarginRad, and a
// degree for the stops' give).
std::string RunSquareWaves(LegSim& sim, int ticks) {
  try {
    sim.SetJointAnglesDeg({-110.0, -10.0, -25.0});
    for (int t = 0; t < ticks; ++t) {
      const bool up = (t / 25) % 2 == 0;
      sim.Tick(up ? LegAngles{110.0, 85.0, 140.0} : LegAngles{-110.0, -10.0, -25.0});
      for (int j = 0; j < kLegJoints; ++j) {
        const JointInfo& joint = sim.world().joint(j);
        const double margin_deg = RadToDeg(LegWorld::kStopMarginRad) + 1.0;
        const double angle = sim.TrueDeg()[j];
        if (!std::isfinite(sim.MeasuredDeg()[j]) ||
            !(angle >= RadToDeg(joint.lower_rad) - margin_deg &&
              angle <= RadToDeg(joint.upper_rad) + margin_deg)) {
          return "tick " + std::to_string(t) + ": joint '" + joint.name + "' at " +
                 std::to_string(angle) + " deg";
        }
      }
    }
  } catch (const SimError& error) {
    return error.what();
  }
  return "";
}

// 3600 deg/s at a 1 ms physics step (3.6 deg a step, gain 1000): past the bound the config
// loader holds ODE to, and ODE's knee comes apart; DART's joints cannot open.
TEST(LegSimDartTest, RunsTheTopSpeedOdeMustRefuse) {
  SimConfig config = Config(0.0);
  config.servo.max_speed_deg_s = 3600.0;
  config.servo.gain_per_s = 1000.0;
  config.servo.smoothing_ms = 0.0;
  try {
    CheckTurnPerPhysicsStep(config);
    ADD_FAILURE() << "ODE accepted 3.6 deg a step";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("(sim.engine: dart takes it)"), std::string::npos)
        << error.what();
  }
  LegSim ode(config);
  EXPECT_NE(RunSquareWaves(ode, 400).find("came apart"), std::string::npos);

  if (!BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  config.engine = PhysicsEngine::kDart;
  EXPECT_NO_THROW(CheckTurnPerPhysicsStep(config));
  LegSim dart(config);
  EXPECT_EQ(RunSquareWaves(dart, 400), "");
  // The rotator alone, the others held: it turns at the top speed, 3600 deg/s = 28.8 deg a tick
  // (with every joint whipping at once, the others' reactions exceed its torque limit).
  dart.SetJointAnglesDeg({-110.0, 0.0, 0.0});
  double fastest_deg_per_tick = 0.0;
  double last = dart.TrueDeg()[kRotator];
  for (int t = 0; t < 8; ++t) {
    dart.Tick(LegAngles{110.0, 0.0, 0.0});
    fastest_deg_per_tick = std::max(fastest_deg_per_tick, dart.TrueDeg()[kRotator] - last);
    last = dart.TrueDeg()[kRotator];
  }
  EXPECT_NEAR(fastest_deg_per_tick, 3600.0 * kTickMs / 1000.0, 0.1);
}

// A shin twice as long (its centre of mass and the foot twice as far from the knee) at 2000
// deg/s, inside ODE's bound: on DART it runs sound.
TEST(LegSimDartTest, RunsALegWithTwiceTheShin) {
  if (!BuiltWithDart()) GTEST_SKIP() << "this build has no DART (LEGLAB_WITH_DART=OFF)";
  const testing::TempUrdf long_shin(
      kUrdf, testing::Edits{{R"(xyz="-0.011001 0 -0.038457")", R"(xyz="-0.022002 0 -0.076914")"},
                            {R"(xyz="-0.01888 0 -0.066")", R"(xyz="-0.03776 0 -0.132")"}});
  SimConfig config = Config(0.0);
  config.urdf_path = long_shin.path();
  config.servo.max_speed_deg_s = 2000.0;
  config.servo.gain_per_s = 1000.0;
  config.engine = PhysicsEngine::kDart;
  LegSim dart(config);
  EXPECT_EQ(RunSquareWaves(dart, 400), "");
}

TEST(LegSimTest, MovedSimKeepsRunning) {
  LegSim sim(Config());
  sim.Tick();
  LegSim moved = std::move(sim);
  moved.Tick();
  EXPECT_EQ(moved.tick(), 2);
}

// ---- Settings changed during a run -----------------------------------------------------

// Two identical sims, one changed at tick `change_tick`: everything is the same bit for bit
// before it. Noise from 0.1 to 0.5 deg: the same draws, five times as large from the next tick
// on, the motion untouched (the sensor does not act on the leg).
TEST(LegSimChangeTest, NoiseChangesFromTheNextTickOnAndTheDrawsCarryOn) {
  LegSim a(Config(40.0, 0.1)), b(Config(40.0, 0.1));
  constexpr int kChangeTick = 30;
  for (int t = 0; t < 60; ++t) {
    if (t == kChangeTick) {
      const PlantSetting noise{"sensor.noise_deg", 0.5};
      b.ChangeSettings(std::span(&noise, 1));
    }
    const LegAngles request{30.0 * std::sin(0.1 * t), 20.0, 40.0};
    const PlantReading ra = a.Tick(request), rb = b.Tick(request);
    for (int j = 0; j < kLegJoints; ++j) {
      EXPECT_EQ(ra.true_deg[j], rb.true_deg[j]) << t;
      const double noise_a = ra.measured_deg[j] - ra.true_deg[j];
      const double noise_b = rb.measured_deg[j] - rb.true_deg[j];
      if (t < kChangeTick) {
        EXPECT_EQ(noise_a, noise_b) << t;
      } else {
        // Quantised to 1 urad (5.7e-5 deg) before and after scaling.
        EXPECT_NEAR(noise_b, 5.0 * noise_a, 4e-4) << t;
      }
    }
  }
}

// The top speed halved while the joint runs at it: without smoothing the motor holds the new
// cap from the very next tick, 156.25 deg/s = 1.25 deg a tick, and not a tick before.
TEST(LegSimChangeTest, TopSpeedChangesAtTheNextTick) {
  SimConfig config = Config(0.0, 0.0);
  config.servo.smoothing_ms = 0.0;
  LegSim a(config), b(config);
  constexpr int kChangeTick = 10;
  LegAngles previous = a.TrueDeg();
  for (int t = 0; t < 20; ++t) {
    if (t == kChangeTick) {
      const PlantSetting slower{"servo.max_speed_deg_s", 156.25};
      b.ChangeSettings(std::span(&slower, 1));
    }
    const PlantReading ra = a.Tick({100.0, 0.0, 0.0});
    const PlantReading rb = b.Tick({100.0, 0.0, 0.0});
    if (t < kChangeTick) {
      EXPECT_EQ(ra.true_deg[0], rb.true_deg[0]) << t;
    } else {
      EXPECT_NEAR(rb.true_deg[0] - previous[0], 1.25, 0.03) << t;
      EXPECT_GT(ra.true_deg[0] - rb.true_deg[0], 0.5 * (t - kChangeTick + 1)) << t;
    }
    previous = rb.true_deg;
  }
}

// A longer delay set after a step was requested delays that step too: queued requests are
// acted on in order. 40 -> 56 ms one tick after the request: the joint starts 7 ticks after
// the request instead of 5.
TEST(LegSimChangeTest, DelayGrownWhileARequestIsQueuedDelaysIt) {
  LegSim sim(Config(40.0, 0.0));
  sim.SetJointAnglesDeg({0.0, 10.0, 30.0});
  for (int t = 0; t < 20; ++t) sim.Tick();
  const double before = sim.TrueDeg()[0];
  sim.Tick({40.0, 10.0, 30.0});  // tick t0: the step
  const PlantSetting longer{"servo.delay_ms", 56.0};
  sim.ChangeSettings(std::span(&longer, 1));
  for (int k = 1; k <= 7; ++k) {
    sim.Tick({40.0, 10.0, 30.0});
    const double moved = sim.TrueDeg()[0] - before;
    if (k < 7) {
      EXPECT_LT(std::abs(moved), 1e-3) << "tick t0+" << k;
    } else {
      EXPECT_GT(moved, 0.05) << "tick t0+" << k;
    }
  }
}

TEST(LegSimChangeTest, BadChangesNameTheKeyAndChangeNothing) {
  LegSim sim(Config(40.0, 0.1));
  const std::vector<PlantSetting> bad_value = {{"servo.max_speed_deg_s", 200.0},
                                               {"servo.delay_ms", 30.0}};
  try {
    sim.ChangeSettings(bad_value);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("servo.delay_ms"), std::string::npos) << e.what();
  }
  EXPECT_EQ(sim.config().servo.max_speed_deg_s, 312.5);
  const std::vector<PlantSetting> bad_key = {{"servo.colour", 1.0}};
  EXPECT_THROW(sim.ChangeSettings(bad_key), std::invalid_argument);
  const std::vector<PlantSetting> urdf = {{"sim.physics_dt_ms", 0.5}};
  EXPECT_THROW(sim.ChangeSettings(urdf), std::invalid_argument);
}

}  // namespace
}  // namespace leglab::sim
