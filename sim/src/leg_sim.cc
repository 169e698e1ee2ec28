#include "leglab/sim/leg_sim.h"
#include "leglab/core/units.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

namespace leglab::sim {
namespace {

// The config is validated before anything is built from it.
const SimConfig& Validated(const SimConfig& config) {
  ValidateSimConfig(config);
  return config;
}

JointServo MakeServo(const SimConfig& config, const LegWorld& world, int joint) {
  const JointInfo& info = world.joint(joint);
  return JointServo(config.servo, info.lower_rad, info.upper_rad);
}

}  // namespace

SimError::SimError(long tick, std::string problem)
    : std::runtime_error(
          "leglab::sim: the simulation broke down during control tick " + std::to_string(tick) +
          " (t = " + std::to_string(static_cast<double>(tick) * kTickMs) + " ms): " + problem),
      tick_(tick),
      problem_(std::move(problem)) {}

LegSim::LegSim(const SimConfig& config)
    : config_(Validated(config)),
      world_(config_.urdf_path, config_.stand, config_.engine),
      servos_{MakeServo(config_, world_, 0), MakeServo(config_, world_, 1),
              MakeServo(config_, world_, 2)},
      sensor_(config_.sensor.noise_deg, config_.seed),
      steps_per_tick_(PhysicsStepsPerTick(config_.physics_dt_ms)),
      physics_dt_s_(config_.physics_dt_ms / 1000.0) {
  static_assert(kLegJoints == 3, "servos_ is initialised for three joints");
  for (int j = 0; j < kLegJoints; ++j) {
    max_torque_nm_[j] = std::min(config_.servo.max_torque_nm, world_.joint(j).effort_nm);
  }
  SetJointAnglesDeg(LegAngles{});
}

LegSim::~LegSim() = default;
LegSim::LegSim(LegSim&&) noexcept = default;
LegSim& LegSim::operator=(LegSim&&) noexcept = default;

LegAngles LegSim::ToDeg(const LegAngles& rad) {
  LegAngles deg{};
  for (int j = 0; j < kLegJoints; ++j) {
    deg[j] = RadToDeg(rad[j]);
  }
  return deg;
}

void LegSim::SetRequestsDeg(const LegAngles& request_deg) {
  for (int j = 0; j < kLegJoints; ++j) {
    if (!std::isfinite(request_deg[j])) {
      throw std::invalid_argument("request for joint '" + std::string(kLegJointNames[j]) +
                                  "' must be finite, got " + std::to_string(request_deg[j]));
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    request_rad_[j] = DegToRad(request_deg[j]);
  }
}

void LegSim::Tick() {
  // The firmware runs once per frame; the velocity motors hold its speeds through the frame's
  // physics steps.
  const LegAngles angles = world_.AnglesRad();
  const LegAngles rates = world_.RatesRadPerS();
  for (int j = 0; j < kLegJoints; ++j) {
    servos_[j].PushRequest(request_rad_[j]);
    world_.SetMotor(j, servos_[j].FrameSpeedRadPerS(angles[j], rates[j]),
                    motors_enabled_ ? max_torque_nm_[j] : 0.0);
  }
  if (!world_.has_stand()) {
    for (int step = 0; step < steps_per_tick_; ++step) world_.Step(physics_dt_s_);
  } else {
    // The floor's force reported for the tick is its mean over the tick's physics steps.
    std::array<double, 3> force_sum{};
    for (int step = 0; step < steps_per_tick_; ++step) {
      world_.Step(physics_dt_s_);
      for (int i = 0; i < 3; ++i) force_sum[i] += world_.stand_state().contact_force_n[i];
    }
    for (int i = 0; i < 3; ++i) tick_force_n_[i] = force_sum[i] / steps_per_tick_;
  }
  if (std::string problem = world_.StateProblem(); !problem.empty()) {
    throw SimError(tick_, std::move(problem));
  }
  ++tick_;
  SampleReading();
}

const PlantReading& LegSim::Tick(const LegAngles& request_deg) {
  SetRequestsDeg(request_deg);
  Tick();
  return reading_;
}

void LegSim::ChangeSettings(std::span<const PlantSetting> settings) {
  SimConfig changed = config_;
  for (const PlantSetting& setting : settings) SetSimSetting(changed, setting.key, setting.value);
  ValidateSimConfig(changed);
  config_ = std::move(changed);
  for (int j = 0; j < kLegJoints; ++j) {
    servos_[j].Reconfigure(config_.servo);
    max_torque_nm_[j] = std::min(config_.servo.max_torque_nm, world_.joint(j).effort_nm);
  }
  sensor_.set_noise_deg(config_.sensor.noise_deg);
}

void LegSim::SampleReading() {
  const LegAngles angles_rad = world_.AnglesRad();
  LegAngles commanded_rad{};
  for (int j = 0; j < kLegJoints; ++j) {
    commanded_rad[j] = servos_[j].latest_request_rad();
  }
  reading_.measured_deg = ToDeg(sensor_.Measure(angles_rad));
  reading_.true_deg = ToDeg(angles_rad);
  reading_.applied_deg = ToDeg(commanded_rad);
  if (world_.has_stand()) {
    // The world's instruments after the tick's last physics step, with the force averaged
    // over the tick and the slip counted from the latest reset.
    reading_.telemetry = world_.stand_state();
    reading_.telemetry.contact_force_n = tick_force_n_;
    reading_.telemetry.slip_mm -= slip_at_reset_mm_;
  }
}

void LegSim::SetJointAnglesDeg(const LegAngles& q_deg) {
  LegAngles q_rad{};
  for (int j = 0; j < kLegJoints; ++j) {
    const JointInfo& info = world_.joint(j);
    q_rad[j] = DegToRad(q_deg[j]);
    if (!std::isfinite(q_rad[j]) || q_rad[j] < info.lower_rad - 1e-12 ||
        q_rad[j] > info.upper_rad + 1e-12) {
      throw std::invalid_argument("joint '" + info.name + "' angle must lie within its limits [" +
                                  std::to_string(RadToDeg(info.lower_rad)) + ", " +
                                  std::to_string(RadToDeg(info.upper_rad)) + "] deg, got " +
                                  std::to_string(q_deg[j]));
    }
    q_rad[j] = std::clamp(q_rad[j], info.lower_rad, info.upper_rad);
  }
  world_.SetConfigurationRad(q_rad);
  for (int j = 0; j < kLegJoints; ++j) {
    servos_[j].Hold(q_rad[j]);
  }
  tick_force_n_ = {};
  slip_at_reset_mm_ = world_.stand_state().slip_mm;
  request_rad_ = q_rad;
  SampleReading();
}

}  // namespace leglab::sim
