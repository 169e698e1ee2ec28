#include "leglab/sim/sim_config.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include "physics_world.h"

namespace leglab::sim {
namespace {

[[noreturn]] void Reject(std::string_view key, std::string_view expectation, double got) {
  throw std::invalid_argument(std::string(key) + " must be " + std::string(expectation) + ", got " +
                              FormatNumber(got));
}

// True when value / unit is a whole number, up to rounding of decimal inputs such as 0.1.
bool IsWholeMultiple(double value, double unit) {
  const double ratio = value / unit;
  return std::abs(ratio - std::round(ratio)) <= 1e-9 * std::max(1.0, std::abs(ratio));
}

void RequirePositive(std::string_view key, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    Reject(key, "a finite number > 0", value);
  }
}

// A servo time that is a whole number of the firmware's 8 ms frames.
std::string_view WholeFrames(double ms) {
  return IsWholeMultiple(ms, kTickMs) ? "" : "a non-negative multiple of 8 ms";
}
std::string_view WholeFirmwareFrames(double ms) {
  return IsWholeMultiple(ms, kTickMs) ? ""
                                      : "a non-negative multiple of 8 ms (the firmware's frame)";
}

// A physics step that divides the 8 ms tick.
std::string_view DividesTick(double ms) {
  return IsWholeMultiple(kTickMs, ms) ? ""
                                      : "> 0 and divide the 8 ms tick into a whole number of steps";
}

// The servo firmware's keys (servo.*).
void VisitServoKeys(KeyVisitor& v, ServoConfig& s) {
  v.Key("delay_ms", s.delay_ms,
        {.min = 0,
         .max = 400,
         .unit = "ms",
         .description = "how long the firmware holds a request back; a multiple of 8 ms, up "
                        "to 50 ticks (beyond the identification's lag range)",
         .rule = WholeFrames});
  v.Key("max_speed_deg_s", s.max_speed_deg_s,
        {.min = 30,
         .max = 3600,
         .unit = "deg/s",
         .description = "top joint speed, from 0.24 deg a tick to 10 turns a second; on ODE "
                        "at most 2000 / sim.physics_dt_ms (a joint turns at most 2 deg a "
                        "physics step, or the simulated leg comes apart)"});
  v.Key("gain_per_s", s.gain_per_s,
        {.min = 1,
         .max = 1000,
         .unit = "1/s",
         .description = "the speed law's gain: commanded speed = gain (target - angle) - "
                        "damping rate, capped at the top speed"});
  v.Key("damping", s.damping,
        {.min = 0,
         .max = 10,
         .description = "the speed law's velocity feedback (the D of the PD loop); beyond 10 "
                        "the joint stalls far from its target"});
  v.Key("smoothing_ms", s.smoothing_ms,
        {.min = 0,
         .max = 400,
         .unit = "ms",
         .description = "moving average of the commanded speed (the motor cannot change speed "
                        "at once); a multiple of 8 ms, 0 or 8: none",
         .rule = WholeFirmwareFrames});
  v.Key("max_torque_nm", s.max_torque_nm,
        {.min = 0.1,
         .max = 100,
         .unit = "N m",
         .description = "most torque the motor may use; capped per joint by the URDF's effort "
                        "limit"});
}

// The test stand's keys (stand.*).
void VisitStandKeys(KeyVisitor& v, StandConfig& s) {
  // At least 10 g: a carriage of next to no mass (1e-300 kg) is a body ODE cannot integrate (its
  // step fails an internal assertion), and no stand is built lighter than its slider.
  v.Key("load_kg", s.load_kg,
        {.min = kMinStandLoadKg,
         .max = 10,
         .unit = "kg",
         .description = "mass the carriage carries besides the leg (a quarter of an ERS-210A); "
                        "a stand: section builds the single-leg test stand"});
  v.Key("stop_below_shoulder_mm", s.stop_below_shoulder_mm,
        {.min = 0,
         .max = 50,
         .unit = "mm",
         .description = "how far below its walking height the rail's lower stop holds the "
                        "shoulder"});
  v.Key(
      "friction", s.friction,
      {.min = 0, .max = 5, .description = "Coulomb coefficient of foot on floor; 0 frictionless"});
  v.Key("contact_stiffness_n_per_m", s.contact_stiffness_n_per_m,
        {.min = 100,
         .max = 1e6,
         .unit = "N/m",
         .description = "foot-floor contact stiffness k, from a sponge to a hard floor (ERP = "
                        "h k / (h k + c), CFM = 1 / (h k + c))"});
  v.Key("contact_damping_n_s_per_m", s.contact_damping_n_s_per_m,
        {.min = 0, .max = 1000, .unit = "N s/m", .description = "foot-floor contact damping c"});
  v.Key("foot_radius_mm", s.foot_radius_mm,
        {.min = 0,
         .max = 50,
         .min_open = true,
         .unit = "mm",
         .description = "radius of the contact sphere at the foot (the ball of the foot)"});
  // Only what the config gives changes these: a visitor that reads no config (KeyAssigner
  // setting a running plant's servo) leaves the stand as it was built.
  if (v.Given("belt_speed_mm_per_s")) s.belt_follows_walk = false;
  v.Key("belt_speed_mm_per_s", s.belt_speed_mm_per_s,
        {.min = -2000,
         .max = 2000,
         .unit = "mm/s",
         .description = "the treadmill's speed backward; not given: the walk's stance speed, "
                        "length_mm / (ground_fraction x t_step x 8 ms)"});
  v.Key("sled_stiffness_n_per_m", s.sled_stiffness_n_per_m,
        {.min = 0,
         .max = 1e5,
         .unit = "N/m",
         .description = "the spring of the horizontal sled under the rail; 0: no sled, the "
                        "rigid rail, the default, as a stand is built without one "
                        "(track_stand.yaml ships 200)"});
  v.Key("sled_damping_n_s_per_m", s.sled_damping_n_s_per_m,
        {.min = 0,
         .max = 1000,
         .unit = "N s/m",
         .description = "the sled's damper (track_stand.yaml ships 16)"});
}

}  // namespace

void VisitKeys(KeyVisitor& v, SimConfig& config) {
  v.Key("urdf", config.urdf_path,
        {.description = "the leg's URDF, relative to the robot file (required in a robot file)"});
  v.Section("sim", [&] {
    v.Key("engine", config.engine, kPhysicsEngineNames,
          {.description = "the physics engine: ode (maximal coordinates; the stand) or dart "
                          "(joint coordinates, where a joint cannot come apart; the leg in the "
                          "air only)"});
    v.Key("physics_dt_ms", config.physics_dt_ms,
          {.min = 0.1,
           .max = kMaxPhysicsDtMs,
           .unit = "ms",
           .description = "the physics step; divides the 8 ms tick (below 0.1 ms a run takes "
                          "minutes for nothing ODE needs; above 2 ms the leg on the stand "
                          "comes apart); on ODE servo.max_speed_deg_s x physics_dt_ms <= 2000 "
                          "(a joint turns at most 2 deg a step)",
           .rule = DividesTick});
  });
  v.Section("servo", [&] { VisitServoKeys(v, config.servo); });
  v.Section("sensor", [&] {
    v.Key("noise_deg", config.sensor.noise_deg,
          {.min = 0,
           .max = 2,
           .unit = "deg",
           .description = "standard deviation of the Gaussian noise on each measured angle (20 "
                          "times the Aibo's at most: beyond it the fit of l and a is noise)"});
  });
  if (v.Given("stand")) config.stand.enabled = true;
  v.Section("stand", [&] { VisitStandKeys(v, config.stand); });
  v.Key("seed", config.seed,
        {.min = 0,
         .max = 9.2e18,
         .description = "seed of every random draw: the same seed gives the same bits"});
}

namespace {

// The stand's values, when it is built.
void ValidateStand(const StandConfig& stand) {
  if (!std::isfinite(stand.load_kg) || stand.load_kg < kMinStandLoadKg) {
    Reject("stand.load_kg", "a finite number >= 0.01 kg", stand.load_kg);
  }
  if (!std::isfinite(stand.stop_below_shoulder_mm) || stand.stop_below_shoulder_mm < 0.0) {
    Reject("stand.stop_below_shoulder_mm",
           "a finite number >= 0 (a stop at or below the shoulder's walking height)",
           stand.stop_below_shoulder_mm);
  }
  if (!std::isfinite(stand.friction) || stand.friction < 0.0) {
    Reject("stand.friction", "a finite number >= 0", stand.friction);
  }
  RequirePositive("stand.contact_stiffness_n_per_m", stand.contact_stiffness_n_per_m);
  if (!std::isfinite(stand.contact_damping_n_s_per_m) || stand.contact_damping_n_s_per_m < 0.0) {
    Reject("stand.contact_damping_n_s_per_m", "a finite number >= 0",
           stand.contact_damping_n_s_per_m);
  }
  RequirePositive("stand.foot_radius_mm", stand.foot_radius_mm);
  if (!std::isfinite(stand.sled_stiffness_n_per_m) || stand.sled_stiffness_n_per_m < 0.0) {
    Reject("stand.sled_stiffness_n_per_m", "a finite number >= 0 (0: no sled, a rigid rail)",
           stand.sled_stiffness_n_per_m);
  }
  if (!std::isfinite(stand.sled_damping_n_s_per_m) || stand.sled_damping_n_s_per_m < 0.0) {
    Reject("stand.sled_damping_n_s_per_m", "a finite number >= 0", stand.sled_damping_n_s_per_m);
  }
  if (!std::isfinite(stand.belt_speed_mm_per_s)) {
    Reject("stand.belt_speed_mm_per_s", "finite", stand.belt_speed_mm_per_s);
  }
  if (!std::isfinite(stand.ground_below_shoulder_mm) ||
      stand.ground_below_shoulder_mm <= stand.foot_radius_mm) {
    Reject("stand ground (desired.locus.ground_below_shoulder_mm)",
           "finite and more than the foot radius below the shoulder",
           stand.ground_below_shoulder_mm);
  }
}

}  // namespace

void ValidateSimConfig(const SimConfig& config) {
  if (config.urdf_path.empty()) {
    throw std::invalid_argument("urdf must name a URDF file, got an empty path");
  }
  if (config.engine == PhysicsEngine::kDart && !BuiltWithDart()) {
    throw std::invalid_argument(std::string(kNoDart));
  }
  const double dt = config.physics_dt_ms;
  if (!std::isfinite(dt) || dt <= 0.0 || dt > kTickMs || !IsWholeMultiple(kTickMs, dt)) {
    Reject("sim.physics_dt_ms", "> 0 and divide the 8 ms tick into a whole number of steps", dt);
  }
  const ServoConfig& servo = config.servo;
  if (!std::isfinite(servo.delay_ms) || servo.delay_ms < 0.0 ||
      !IsWholeMultiple(servo.delay_ms, kTickMs)) {
    Reject("servo.delay_ms", "a non-negative multiple of 8 ms", servo.delay_ms);
  }
  RequirePositive("servo.max_speed_deg_s", servo.max_speed_deg_s);
  RequirePositive("servo.gain_per_s", servo.gain_per_s);
  if (!std::isfinite(servo.damping) || servo.damping < 0.0) {
    Reject("servo.damping", "a finite number >= 0", servo.damping);
  }
  if (!std::isfinite(servo.smoothing_ms) || servo.smoothing_ms < 0.0 ||
      !IsWholeMultiple(servo.smoothing_ms, kTickMs)) {
    Reject("servo.smoothing_ms", "a non-negative multiple of 8 ms (the firmware's frame)",
           servo.smoothing_ms);
  }
  RequirePositive("servo.max_torque_nm", servo.max_torque_nm);
  if (!std::isfinite(config.sensor.noise_deg) || config.sensor.noise_deg < 0.0) {
    Reject("sensor.noise_deg", "a finite number >= 0", config.sensor.noise_deg);
  }
  if (config.stand.enabled) ValidateStand(config.stand);
  if (config.stand.enabled && config.engine == PhysicsEngine::kDart) {
    throw std::invalid_argument(std::string(kDartHasNoStand));
  }
}

void CheckTurnPerPhysicsStep(const SimConfig& config) {
  const ServoConfig& servo = config.servo;
  const double dt = config.physics_dt_ms;
  // The product, not the quotient: the boundary pairs (2000 deg/s at 1 ms) compare exactly.
  if (config.engine == PhysicsEngine::kOde &&
      servo.max_speed_deg_s * dt > 1000.0 * kMaxTurnPerPhysicsStepDeg) {
    throw std::invalid_argument(
        "servo.max_speed_deg_s " + FormatNumber(servo.max_speed_deg_s) +
        " with sim.physics_dt_ms " + FormatNumber(dt) + " turns a joint " +
        FormatNumber(servo.max_speed_deg_s * dt / 1000.0) + " deg in one physics step; at most " +
        FormatNumber(kMaxTurnPerPhysicsStepDeg) +
        " deg holds ODE's leg together: servo.max_speed_deg_s x sim.physics_dt_ms must be at "
        "most " +
        FormatNumber(1000.0 * kMaxTurnPerPhysicsStepDeg) + " (sim.engine: dart takes it)");
  }
}

namespace {

// The servo firmware and the sensor change while the leg runs; the physics and the stand are
// built once.
bool IsChangeable(std::string_view key) {
  return key.starts_with("servo.") || key.starts_with("sensor.");
}

}  // namespace

std::vector<std::string> ChangeableSimSettings() {
  std::vector<std::string> names;
  for (const KeyRow& row :
       ListKeys(SimConfig{}, [](KeyVisitor&v, SimConfig&c) { VisitKeys(v, c); })) {
    if (IsChangeable(row.key)) names.push_back(row.key);
  }
  return names;
}

void SetSimSetting(SimConfig& config, std::string_view key, double value) {
  // The key's declared range and rule, as the config loader checks them: a running plant's
  // setting is held to what its config may say (KeyAssigner sets without checking).
  for (const KeyRow& row :
       ListKeys(SimConfig{}, [](KeyVisitor&v, SimConfig&c) { VisitKeys(v, c); })) {
    if (row.key != key || !IsChangeable(key)) continue;
    if (const std::string problem = KeyValueProblem(value, row.doc); !problem.empty()) {
      throw std::invalid_argument(std::string(key) + " must be " + problem + ", got " +
                                  FormatNumber(value, NumberStyle::kReadable));
    }
  }
  KeyAssigner assigner(std::string(key), value);
  if (IsChangeable(key)) VisitKeys(assigner, config);
  if (assigner.assigned()) return;
  std::string valid;
  for (const std::string& name : ChangeableSimSettings()) {
    valid += (valid.empty() ? "" : ", ") + name;
  }
  throw std::invalid_argument(std::string(key) + " cannot change during a run (can: " + valid +
                              ")");
}

int PhysicsStepsPerTick(double physics_dt_ms) {
  return static_cast<int>(std::lround(kTickMs / physics_dt_ms));
}

}  // namespace leglab::sim
