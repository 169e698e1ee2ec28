#include "leglab/model/kinematics.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace leglab {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kLimitToleranceRad = 1e-9;
constexpr const char* kJointNames[3] = {"rotator", "abductor", "knee"};

Eigen::Matrix3d RotX(double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d RotY(double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

double WrapToPi(double angle_rad) { return std::remainder(angle_rad, 2.0 * std::numbers::pi); }

[[noreturn]] void Unreachable(const Eigen::Vector3d& foot_mm, const std::string& reason) {
  std::ostringstream msg;
  msg.precision(6);
  msg << "foot target (" << foot_mm.x() << ", " << foot_mm.y() << ", " << foot_mm.z()
      << ") mm is unreachable: " << reason;
  throw std::domain_error(msg.str());
}

bool WithinLimits(const JointLimits& limits, double angle_rad) {
  return angle_rad >= limits.lower_rad - kLimitToleranceRad &&
         angle_rad <= limits.upper_rad + kLimitToleranceRad;
}

// The solutions of A cos(x) + B sin(x) = C in (-pi, pi]: none when |C| > hypot(A, B) (beyond
// rounding at the edge of the workspace), else the two branches phase +- spread.
std::vector<double> SolveHarmonic(double a, double b, double c) {
  const double ratio = c / std::hypot(a, b);
  if (!(std::abs(ratio) <= 1.0 + 1e-12)) return {};
  const double phase = std::atan2(b, a);
  const double spread = std::acos(std::clamp(ratio, -1.0, 1.0));
  return {WrapToPi(phase + spread), WrapToPi(phase - spread)};
}

// The first joint of `q` outside its limits, or -1.
int FirstViolatedJoint(const LegGeometry& geometry, const Eigen::Vector3d& q) {
  for (int j = 0; j < 3; ++j) {
    if (!WithinLimits(geometry.limits[j], q[j])) return j;
  }
  return -1;
}

}  // namespace

LegGeometry LegGeometry::Ers210aFrontLeft() {
  LegGeometry g;
  g.shoulder_mm = {59.5, 59.2, 0.0};
  g.upper_leg_mm = {12.8, 0.5, -64.0};
  g.lower_leg_mm = {-18.88, 0.0, -66.0};
  g.limits[kRotator] = {-117.0 * kDeg, 117.0 * kDeg};
  g.limits[kAbductor] = {-11.0 * kDeg, 89.0 * kDeg};
  g.limits[kKnee] = {-27.0 * kDeg, 147.0 * kDeg};
  return g;
}

Eigen::Vector3d ForwardKinematics(const LegGeometry& geometry, const Eigen::Vector3d& q_rad) {
  const Eigen::Vector3d knee_to_foot = RotY(q_rad[kKnee]) * geometry.lower_leg_mm;
  return geometry.shoulder_mm +
         RotY(-q_rad[kRotator]) * RotX(q_rad[kAbductor]) * (geometry.upper_leg_mm + knee_to_foot);
}

Eigen::Vector3d InverseKinematics(const LegGeometry& geometry, const Eigen::Vector3d& foot_mm) {
  if (!foot_mm.allFinite()) Unreachable(foot_mm, "the target is not finite");
  const Eigen::Vector3d& u = geometry.upper_leg_mm;
  const Eigen::Vector3d& w = geometry.lower_leg_mm;
  const Eigen::Vector3d v = foot_mm - geometry.shoulder_mm;

  // Knee: rotations about the shoulder keep |v| = |u + Ry(q3) w|, and
  // u . Ry(q3) w = cos(q3) (ux wx + uz wz) + sin(q3) (ux wz - uz wx) + uy wy.
  const std::vector<double> knees =
      SolveHarmonic(u.x() * w.x() + u.z() * w.z(), u.x() * w.z() - u.z() * w.x(),
                    0.5 * (v.squaredNorm() - u.squaredNorm() - w.squaredNorm()) - u.y() * w.y());
  if (knees.empty()) Unreachable(foot_mm, "it is out of the leg's workspace");

  std::optional<Eigen::Vector3d> best;
  std::vector<std::string> rejected;  // why each branch outside the limits was dropped
  for (double knee : knees) {
    // Abductor: Ry(-q1) keeps the y component, so v.y = cos(q2) k.y - sin(q2) k.z.
    const Eigen::Vector3d k = u + RotY(knee) * w;
    for (double abductor : SolveHarmonic(k.y(), -k.z(), v.y())) {
      // Rotator: the sagittal angle left between Rx(q2) k and v.
      const Eigen::Vector3d r = RotX(abductor) * k;
      const double rotator = WrapToPi(std::atan2(v.z(), v.x()) - std::atan2(r.z(), r.x()));
      const Eigen::Vector3d q(rotator, abductor, knee);
      if (const int j = FirstViolatedJoint(geometry, q); j >= 0) {
        std::ostringstream why;
        why << "the " << kJointNames[j] << " at " << q[j] / kDeg << " deg (limits ["
            << geometry.limits[j].lower_rad / kDeg << ", " << geometry.limits[j].upper_rad / kDeg
            << "])";
        rejected.push_back(why.str());
      } else if (!best || std::abs(rotator) < std::abs((*best)[kRotator])) {
        best = q;
      }
    }
  }
  if (best) return *best;
  if (rejected.empty()) Unreachable(foot_mm, "it is out of the leg's workspace");
  std::string msg = "it needs " + rejected.front();
  for (size_t i = 1; i < rejected.size(); ++i) msg += " or " + rejected[i];
  Unreachable(foot_mm, msg);
}

}  // namespace leglab
