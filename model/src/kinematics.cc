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

#include "leglab/core/units.h"

namespace leglab {
namespace {

constexpr double kLimitToleranceRad = 1e-9;
constexpr double kAxisTolerance = 1e-9;

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

// The sign s of an axis +-e (validated): R(s e, q) = R(e, s q), so each joint turns about a
// coordinate axis by s q.
double Sign(const Eigen::Vector3d& axis, int coordinate) {
  return axis[coordinate] < 0.0 ? -1.0 : 1.0;
}

}  // namespace

void ValidateLegGeometry(const LegGeometry& geometry) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("leg geometry: " + what); };
  if (!geometry.shoulder_mm.allFinite()) fail("the shoulder vector is not finite");
  if (!geometry.upper_leg_mm.allFinite()) fail("the upper-leg vector is not finite");
  if (!geometry.lower_leg_mm.allFinite()) fail("the lower-leg vector is not finite");
  // Rotator and knee about y, abductor about x: the form the closed-form IK solves.
  constexpr int kCoordinate[kLegJoints] = {1, 0, 1};
  constexpr const char* kAxisName[kLegJoints] = {"+-y", "+-x", "+-y"};
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string joint(kLegJointNames[j]);
    const Eigen::Vector3d& a = geometry.axes[j];
    if (!a.allFinite() || std::abs(std::abs(a[kCoordinate[j]]) - 1.0) > kAxisTolerance ||
        std::abs(a.norm() - 1.0) > kAxisTolerance) {
      std::ostringstream got;
      got << a.transpose();
      fail("the " + joint + " axis must be " + kAxisName[j] + ", got (" + got.str() + ")");
    }
    const JointLimits& lim = geometry.limits[j];
    if (!std::isfinite(lim.lower_rad) || !std::isfinite(lim.upper_rad) ||
        !(lim.lower_rad < lim.upper_rad)) {
      fail("the " + joint + " limits must be finite with lower < upper");
    }
  }
}

Eigen::Vector3d ForwardKinematics(const LegGeometry& geometry, const Eigen::Vector3d& q_rad) {
  const double s1 = Sign(geometry.axes[kRotator], 1);
  const double s2 = Sign(geometry.axes[kAbductor], 0);
  const double s3 = Sign(geometry.axes[kKnee], 1);
  const Eigen::Vector3d knee_to_foot = RotY(s3 * q_rad[kKnee]) * geometry.lower_leg_mm;
  return geometry.shoulder_mm + RotY(s1 * q_rad[kRotator]) * RotX(s2 * q_rad[kAbductor]) *
                                    (geometry.upper_leg_mm + knee_to_foot);
}

Eigen::Matrix3d FootJacobian(const LegGeometry& geometry, const Eigen::Vector3d& q_rad) {
  // d/dc R(e, c) v = e x R(e, c) v, and joint j turns by c = s_j q_j about its coordinate axis.
  const double s1 = Sign(geometry.axes[kRotator], 1);
  const double s2 = Sign(geometry.axes[kAbductor], 0);
  const double s3 = Sign(geometry.axes[kKnee], 1);
  const Eigen::Matrix3d r1 = RotY(s1 * q_rad[kRotator]);
  const Eigen::Matrix3d r2 = RotX(s2 * q_rad[kAbductor]);
  const Eigen::Vector3d knee_to_foot = RotY(s3 * q_rad[kKnee]) * geometry.lower_leg_mm;
  const Eigen::Vector3d below_abductor = r2 * (geometry.upper_leg_mm + knee_to_foot);
  Eigen::Matrix3d jacobian;
  jacobian.col(kRotator) = s1 * Eigen::Vector3d::UnitY().cross(r1 * below_abductor);
  jacobian.col(kAbductor) = s2 * (r1 * Eigen::Vector3d::UnitX().cross(below_abductor));
  jacobian.col(kKnee) = s3 * (r1 * r2 * Eigen::Vector3d::UnitY().cross(knee_to_foot));
  return jacobian;
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

  // Solved for the turns about the coordinate axes (c = s q); the angles are q = s c.
  const double s1 = Sign(geometry.axes[kRotator], 1);
  const double s2 = Sign(geometry.axes[kAbductor], 0);
  const double s3 = Sign(geometry.axes[kKnee], 1);
  std::optional<Eigen::Vector3d> best;
  std::vector<std::string> rejected;  // why each branch outside the limits was dropped
  for (double c3 : knees) {
    // Abductor: RotY keeps the y component, so v.y = cos(c2) k.y - sin(c2) k.z.
    const Eigen::Vector3d k = u + RotY(c3) * w;
    for (double c2 : SolveHarmonic(k.y(), -k.z(), v.y())) {
      // Rotator: the sagittal angle left between RotX(c2) k and v (RotY(c) turns the x-z
      // plane's angle atan2(z, x) by -c).
      const Eigen::Vector3d r = RotX(c2) * k;
      const double c1 = WrapToPi(std::atan2(r.z(), r.x()) - std::atan2(v.z(), v.x()));
      const Eigen::Vector3d q(s1 * c1, s2 * c2, s3 * c3);
      if (const int j = FirstViolatedJoint(geometry, q); j >= 0) {
        std::ostringstream why;
        why << "the " << kLegJointNames[j] << " at " << RadToDeg(q[j]) << " deg (limits ["
            << RadToDeg(geometry.limits[j].lower_rad) << ", "
            << RadToDeg(geometry.limits[j].upper_rad) << "])";
        rejected.push_back(why.str());
      } else if (!best || std::abs(q[kRotator]) < std::abs((*best)[kRotator])) {
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
