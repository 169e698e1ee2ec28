#include "leglab/experiments/robot.h"

#include <array>
#include <cmath>
#include <exception>
#include <stdexcept>

#include "leglab/experiments/config.h"
#include "leglab/sim/leg_description.h"

namespace leglab::experiments {
namespace {

// Millimetres from metres, rounded to the nanometre: a URDF's lengths are decimal metres, so
// 0.0595 m is exactly 59.5 mm rather than 59.500000000000007.
Eigen::Vector3d Mm(const std::array<double, 3>& m) {
  Eigen::Vector3d mm;
  for (int i = 0; i < 3; ++i) mm[i] = std::round(m[i] * 1e9) / 1e6;
  return mm;
}

Eigen::Vector3d Rounded(const Eigen::Vector3d& mm) { return (mm * 1e6).array().round() / 1e6; }

}  // namespace

Robot LoadRobot(const std::string& urdf_path) {
  sim::LegDescription leg;
  try {
    leg = sim::LoadLegDescription(urdf_path);
  } catch (const std::exception& e) {
    throw InputError(std::string("robot: ") + e.what());
  }
  Robot robot{leg.robot_name, urdf_path, {}};
  for (const sim::BodyDescription& body : leg.bodies) robot.leg_mass_kg += body.mass_kg;
  LegGeometry& g = robot.geometry;
  const Eigen::Vector3d rotator = Mm(leg.joints[kRotator].position_m);
  const Eigen::Vector3d abductor = Mm(leg.joints[kAbductor].position_m);
  const Eigen::Vector3d knee = Mm(leg.joints[kKnee].position_m);
  if ((rotator - abductor).norm() > 1e-6) {
    throw InputError("robot '" + urdf_path +
                     "': the rotator and abductor axes must meet at the shoulder (their joint "
                     "origins are " +
                     std::to_string((rotator - abductor).norm()) + " mm apart)");
  }
  g.shoulder_mm = rotator;
  g.upper_leg_mm = Rounded(knee - rotator);
  g.lower_leg_mm = Rounded(Mm(leg.foot_position_m) - knee);
  for (int j = 0; j < kLegJoints; ++j) {
    const sim::JointDescription& joint = leg.joints[j];
    g.axes[j] = Eigen::Vector3d(joint.axis[0], joint.axis[1], joint.axis[2]);
    g.limits[j] = {joint.lower_rad, joint.upper_rad};
  }
  try {
    ValidateLegGeometry(g);
  } catch (const std::invalid_argument& e) {
    throw InputError("robot '" + urdf_path + "': " + e.what() +
                     " (leglab's kinematics solves rotator and knee about +-y, abductor about "
                     "+-x)");
  }
  return robot;
}

}  // namespace leglab::experiments
