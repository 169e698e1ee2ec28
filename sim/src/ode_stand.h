#pragma once

// The single-leg test stand's ODE objects (StandConfig): the carriage on its rail (or on the
// sled), the floor and the ball of the foot in a collision space, and the joint group that holds
// one physics step's contacts. Private to leglab::sim: LegWorld owns one when the stand is
// enabled; what it measures is core's PlantTelemetry (leglab/core/plant.h).

#include <ode/ode.h>

#include <Eigen/Core>
#include <array>
#include <string>

#include "leglab/core/plant.h"
#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// The test stand in an ODE world. Built after the leg's bodies and before its hinges (a hinge
/// of the root link hangs on `carriage`); its bodies and joints belong to the world, its space,
/// geoms and contact group to the Stand, which must be destroyed before the world.
struct Stand {
  static constexpr int kMaxContacts = 4;  // a sphere on a plane gives one

  /// Builds the carriage (mass config.load_kg, at the world origin, at rest) on its rail or, with
  /// config.sled_stiffness_n_per_m > 0, on the sled; the floor plane
  /// config.ground_below_shoulder_mm below the ball of the foot's centre at the walking height
  /// (`shoulder_z_m`, the shoulder's height in the world, m); and the ball of the foot
  /// (config.foot_radius_mm) on `foot_body`, its centre `foot_offset_m` from the body's centre of
  /// mass in the body's axes, m. `config` is expected valid (ValidateSimConfig).
  Stand(dWorldID world, const StandConfig& config, double shoulder_z_m, dBodyID foot_body,
        const Eigen::Vector3d& foot_offset_m);
  Stand(const Stand&) = delete;
  Stand& operator=(const Stand&) = delete;
  ~Stand();

  /// One physics step of `world` (dWorldStep, `dt_s` seconds) with the stand: the foot's
  /// contacts with the floor and the sled's rows are joined for this step only, then the
  /// step's measurements are taken into `state`.
  void Step(dWorldID world, double dt_s);

  /// Puts the carriage at rest on its stop, or, when the foot would then be in the floor, as
  /// high as makes the ball of the foot just touch it; `foot_z_m` is the ball's centre's world
  /// height with the carriage at height 0, m. Resets the step's measurements (not the slip).
  /// Returns the carriage's height, m: the lift to place the leg's bodies with.
  double PlaceCarriage(double foot_z_m);

  double CarriageZM() const { return dBodyGetPosition(carriage)[2]; }
  // The sled's (and so the carriage's) position along x and y from its spring's rest, m; 0
  // without a sled.
  double SledXM() const { return has_sled() ? dBodyGetPosition(carriage)[0] : 0.0; }
  double SledYM() const { return has_sled() ? dBodyGetPosition(carriage)[1] : 0.0; }
  bool has_sled() const { return sled != nullptr; }

  /// The carriage's kinetic energy, J (it only slides: translation alone).
  double CarriageKineticEnergyJ() const;
  /// The carriage's (its load's) gravitational potential energy, J (zero at world z = 0), for a
  /// gravitational acceleration `gravity_m_per_s2` along -z.
  double CarriagePotentialEnergyJ(double gravity_m_per_s2) const;
  /// The energy stored in the sled's spring, J (zero without a sled).
  double SledSpringEnergyJ() const;

  /// Empty when the carriage's state is finite; otherwise what is not.
  std::string StateProblem() const;

  StandConfig config;
  dBodyID carriage = nullptr;
  dJointID rail = nullptr;
  // With the sled (StandConfig::sled_stiffness_n_per_m > 0) the carriage has no slider: an
  // angular motor holds its rotation (3 rows), a linear motor along x and y carries the sled's
  // spring-damper (2 rows), and the rail's stop is a one-row contact made while the carriage
  // is on it: as many constraint rows as the slider and its stop, so the stand costs no more.
  dJointID upright = nullptr;
  dJointID sled = nullptr;
  dSpaceID space = nullptr;
  dGeomID floor = nullptr;
  dGeomID foot = nullptr;
  dJointGroupID contacts = nullptr;
  std::array<dJointFeedback, kMaxContacts> feedback{};
  std::array<dContactGeom, kMaxContacts> geoms{};
  int contact_count = 0;
  double floor_z_m = 0.0;  // the floor plane's height in the world frame
  PlantTelemetry state;

 private:
  void BuildCarriage(dWorldID world);
  void BuildSled(dWorldID world);
  void BuildRail(dWorldID world);
  void BuildFloorAndFoot(double shoulder_z_m, dBodyID foot_body,
                         const Eigen::Vector3d& foot_offset_m);
  void CollideAndJoin(dWorldID world, double dt_s);
  void JoinSled(dWorldID world, double dt_s);
  void MeasureContacts(double dt_s);
};

}  // namespace leglab::sim
