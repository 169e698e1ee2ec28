#pragma once

#include <string>

#include "leglab/model/kinematics.h"

namespace leglab::experiments {

/// A robot as the experiments see it: its URDF, and the kinematics read from that URDF (the
/// one source of truth for the leg's geometry; robot.yaml holds the servo and sensor values).
struct Robot {
  std::string name;       ///< the URDF's <robot name>
  std::string urdf_path;  ///< the URDF it was read from
  LegGeometry geometry;   ///< segment vectors, joint axes and limits at q = 0
  double leg_mass_kg =
      0.0;  ///< the moving links' masses (what a stand's floor carries besides its load)
};

/// Reads the leg at `urdf_path` (through sim::LoadLegDescription) and derives its geometry:
/// the shoulder is where the rotator and abductor axes meet, the upper leg runs to the knee,
/// the lower leg to the `foot` link, the axes and limits are the URDF joints'.
/// Throws InputError naming the file and the item when the URDF is missing or malformed, or
/// when the leg is not of the form the model's kinematics solves (LegGeometry: rotator and
/// knee about +-y, abductor about +-x, rotator and abductor axes meeting).
Robot LoadRobot(const std::string& urdf_path);

}  // namespace leglab::experiments
