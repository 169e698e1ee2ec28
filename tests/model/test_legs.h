#pragma once

// Leg geometries typed from ../shared/ers210a.md (CMPack'02 ERS-210 vectors, software limits),
// as test data for the model's kinematics: independent of the robots' URDFs, which
// tests/experiments/robot_test.cc checks against them.
#include "leglab/core/units.h"
#include "leglab/model/kinematics.h"

namespace leglab::testing {

inline LegGeometry WithErs210aLimits(LegGeometry g) {
  g.limits[kRotator] = {DegToRad(-117.0), DegToRad(117.0)};
  g.limits[kAbductor] = {DegToRad(-11.0), DegToRad(89.0)};
  g.limits[kKnee] = {DegToRad(-27.0), DegToRad(147.0)};
  return g;
}

/// The left front leg: rotator about -y, abductor about +x, knee about +y.
inline LegGeometry FrontLeftLeg() {
  LegGeometry g;
  g.shoulder_mm = {59.5, 59.2, 0.0};
  g.upper_leg_mm = {12.8, 0.5, -64.0};
  g.lower_leg_mm = {-18.88, 0.0, -66.0};
  g.axes = {-Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()};
  return WithErs210aLimits(g);
}

/// The left hind leg: x mirrored, so the axes about y flip (rotator +y, knee -y).
inline LegGeometry HindLeftLeg() {
  LegGeometry g;
  g.shoulder_mm = {-59.5, 59.2, 0.0};
  g.upper_leg_mm = {-12.8, 0.5, -64.0};
  g.lower_leg_mm = {29.36, 0.0, -70.88};
  g.axes = {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY()};
  return WithErs210aLimits(g);
}

}  // namespace leglab::testing
