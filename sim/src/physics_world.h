#pragma once

// The seam between LegWorld and a physics engine: the rigid-body world of one leg, built by
// one engine's implementation. Private to leglab::sim: no public header names an engine type.

#include <array>
#include <memory>
#include <string>
#include <string_view>

#include "leglab/core/leg.h"
#include "leglab/core/plant.h"
#include "leglab/sim/leg_description.h"
#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// One leg's rigid-body world in one engine, as LegWorld documents each operation: joint angles
/// and rates in the URDF's sign and zero, a velocity motor with a torque limit per joint,
/// mechanical stops LegWorld::kStopMarginRad beyond the URDF limits, gravity along -z, the root
/// link fixed at the world origin (or riding the stand's carriage).
class PhysicsWorld {
 public:
  virtual ~PhysicsWorld() = default;
  PhysicsWorld() = default;
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  virtual LegAngles AnglesRad() const = 0;
  virtual LegAngles RatesRadPerS() const = 0;
  virtual void SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) = 0;
  virtual void Step(double dt_s) = 0;
  virtual void SetConfigurationRad(const LegAngles& q_rad) = 0;
  virtual const PlantTelemetry& stand_state() const = 0;
  virtual bool has_stand() const = 0;
  /// Origin of link `link` (an index into LegDescription::links) in the body frame, mm.
  virtual std::array<double, 3> LinkOriginMm(int link) const = 0;
  virtual double MechanicalEnergyJ() const = 0;
  virtual double KineticEnergyJ() const = 0;
  virtual std::string StateProblem() const = 0;
};

/// ODE's world of `leg` (maximal coordinates: a body per moving link, hinges between them), with
/// the stand when `stand.enabled`. `leg` is checked (LegWorld) and outlives the world.
std::unique_ptr<PhysicsWorld> MakeOdeWorld(const LegDescription& leg, const StandConfig& stand);

/// Why the stand is refused on DART (MakeDartWorld, ValidateSimConfig), one line.
inline constexpr std::string_view kDartHasNoStand =
    "stand: sim.engine dart has no stand (its contact is hard, with one process-wide softness, "
    "where the stand's is a spring-damper per world); use sim.engine: ode";

/// Why sim.engine: dart is refused by a build without DART (LEGLAB_WITH_DART off; MakeDartWorld,
/// ValidateSimConfig), one line.
inline constexpr std::string_view kNoDart =
    "sim.engine: dart, but this build of leglab has no DART (configured with "
    "LEGLAB_WITH_DART=OFF or without DART 6.12 installed); use sim.engine: ode";

/// DART's world of `leg` (reduced coordinates: one skeleton whose revolute joints cannot open).
/// Throws std::invalid_argument when `stand.enabled` (the stand is ODE's alone; see
/// docs/design/dart.md), and kNoDart in a build without DART (no_dart_leg_world.cc). `leg` is
/// checked (LegWorld) and outlives the world.
std::unique_ptr<PhysicsWorld> MakeDartWorld(const LegDescription& leg, const StandConfig& stand);

}  // namespace leglab::sim
