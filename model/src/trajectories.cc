#include "leglab/model/trajectories.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "leglab/core/units.h"

namespace leglab {

std::vector<double> StepTestRequests(double theta_test_deg, int t_step) {
  if (const std::string problem =
          KeyValueProblem(t_step, WithRange(kAnyStepTicksDoc, 2, kAnyStepTicksDoc.max));
      !problem.empty()) {
    throw std::invalid_argument("step test: t_step must be " + problem + ", got " +
                                std::to_string(t_step));
  }
  std::vector<double> requests(t_step, 0.0);
  // Eq. 1: t < t_step / 2 compares against the real half, so an odd t_step rounds up.
  for (int t = 0; 2 * t < t_step; ++t) requests[t] = theta_test_deg;
  return requests;
}

void VisitKeys(KeyVisitor& v, HalfEllipseLocus& locus) {
  v.Key("length_mm", locus.length_mm,
        {.min = 0,
         .max = 1000,
         .unit = "mm",
         .description = "fore-aft length of the flat bottom (reachability is checked after)"});
  v.Key("height_mm", locus.height_mm,
        {.min = 0, .max = 1000, .unit = "mm", .description = "height of the arc above the bottom"});
  v.Key("ground_fraction", locus.ground_fraction,
        {.min = 0,
         .max = 1,
         .min_open = true,
         .max_open = true,
         .description = "fraction of the step the foot is on the ground"});
  v.Key("skew", locus.skew,
        {.min = -1,
         .max = 1,
         .description = "the locus skewed in the ground plane, outward mm per mm forward"});
  v.Key("swing_end_speed_fraction", locus.swing_end_speed_fraction,
        {.min = 0,
         .max = 2,
         .description = "the foot's backward speed at lift-off and touch-down over the stance's: "
                        "0, the plain half-ellipse; 1, it meets the ground at the stance's speed "
                        "(track_stand.yaml ships 1)"});
  v.Key("liftoff_ramp_mm", locus.liftoff_ramp_mm,
        {.min = 0,
         .max = 50,
         .unit = "mm",
         .description = "a slow lift-off's height (0: none); its line must stay under the arc's "
                        "top (track_stand.yaml ships 8)"});
  v.Key("liftoff_ramp_ticks", locus.liftoff_ramp_ticks, kLiftoffRampTicksDoc);
}

std::string HalfEllipseLocusProblem(const HalfEllipseLocus& locus) {
  if (std::string problem =
          KeysProblem(locus, [](KeyVisitor& v, HalfEllipseLocus& l) { VisitKeys(v, l); });
      !problem.empty()) {
    return problem;
  }
  if (const std::string problem = KeyValueProblem(locus.t_step_ticks, kAnyStepTicksDoc);
      !problem.empty()) {
    return "t_step_ticks must be " + problem + ", got " + std::to_string(locus.t_step_ticks);
  }
  if (!locus.centre_mm.allFinite()) return "centre_mm must be finite";
  if (locus.liftoff_ramp_mm > 0.0) {
    const int period = locus.t_step_ticks;
    const int ground_ticks =
        std::clamp(static_cast<int>(std::lround(locus.ground_fraction * period)), 1, period - 1);
    // With a ramp its length runs from 1 tick to the flight's less one.
    const KeyDoc with_ramp = WithRange(kLiftoffRampTicksDoc, 1, period - ground_ticks - 1);
    if (const std::string problem = KeyValueProblem(locus.liftoff_ramp_ticks, with_ramp);
        !problem.empty()) {
      return "liftoff_ramp_ticks must be " + problem +
             " with a lift-off ramp (shorter than the "
             "flight), got " +
             std::to_string(locus.liftoff_ramp_ticks);
    }
    // The line must stay under the arc's top (where the squeezed arc peaks, s = (1 + a) / 2),
    // so that the arc overtakes it on its way up and z stays continuous.
    const double a = static_cast<double>(locus.liftoff_ramp_ticks) / (period - ground_ticks);
    if (locus.liftoff_ramp_mm * (1.0 + a) / (2.0 * a) > locus.height_mm) {
      return "liftoff_ramp_mm must stay under the arc: liftoff_ramp_mm (1 + a) / (2 a) <= "
             "height_mm, a = liftoff_ramp_ticks / flight ticks";
    }
  }
  return {};
}

std::vector<Eigen::Vector3d> HalfEllipseFootPath(const HalfEllipseLocus& locus) {
  if (const std::string problem = HalfEllipseLocusProblem(locus); !problem.empty()) {
    throw std::invalid_argument("half-ellipse locus: " + problem);
  }
  const int period = locus.t_step_ticks;
  const int ground_ticks =
      std::clamp(static_cast<int>(std::lround(locus.ground_fraction * period)), 1, period - 1);
  const double half = 0.5 * locus.length_mm;
  // The flight's extra backward sweep, mm per unit of s at either end: the stance's speed
  // (length_mm / ground_ticks per tick) times the flight's ticks, times the fraction asked.
  const double end_sweep = locus.swing_end_speed_fraction * locus.length_mm *
                           static_cast<double>(period - ground_ticks) / ground_ticks;
  std::vector<Eigen::Vector3d> path(period);
  for (int t = 0; t < period; ++t) {
    Eigen::Vector3d offset = Eigen::Vector3d::Zero();
    if (t < ground_ticks) {
      offset.x() = half - locus.length_mm * t / ground_ticks;
    } else {
      const double angle = std::numbers::pi * (t - ground_ticks) / (period - ground_ticks);
      offset.x() = -half * std::cos(angle);
      offset.z() = locus.height_mm * std::sin(angle);
      if (locus.liftoff_ramp_mm > 0.0) {
        // The slow lift-off (0 off: the line above, the same bits).
        const double s = static_cast<double>(t - ground_ticks) / (period - ground_ticks);
        const double a = static_cast<double>(locus.liftoff_ramp_ticks) / (period - ground_ticks);
        const double u = std::clamp((s - a) / (1.0 - a), 0.0, 1.0);
        offset.z() = locus.height_mm * std::sin(std::numbers::pi * u);
        if (u <= 0.5) offset.z() = std::max(offset.z(), locus.liftoff_ramp_mm * s / a);
      }
      if (locus.swing_end_speed_fraction != 0.0) {
        // s - 3 s^2 + 2 s^3: 0 at both ends, slope 1 at both ends (0 off: the same bits).
        const double s = static_cast<double>(t - ground_ticks) / (period - ground_ticks);
        offset.x() -= end_sweep * (s - 3.0 * s * s + 2.0 * s * s * s);
      }
    }
    // A skew of 0 leaves y at +-0, so the plain locus keeps its bits.
    offset.y() = locus.skew * offset.x();
    path[t] = locus.centre_mm + offset;
  }
  return path;
}

std::vector<Eigen::Vector3d> PitchFootPath(const std::vector<Eigen::Vector3d>& foot_path_mm,
                                           const Eigen::Vector3d& pivot_mm, double pitch_deg) {
  if (const std::string problem = KeyValueProblem(pitch_deg, kBodyPitchDoc); !problem.empty()) {
    throw std::invalid_argument("body pitch must be " + problem + ", got " +
                                FormatNumber(pitch_deg, NumberStyle::kReadable));
  }
  if (pitch_deg == 0.0) return foot_path_mm;
  // Level-frame vectors seen from the pitched body: Ry(pitch)^T = Ry(-pitch).
  const Eigen::Matrix3d to_body =
      Eigen::AngleAxisd(-DegToRad(pitch_deg), Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::vector<Eigen::Vector3d> pitched;
  pitched.reserve(foot_path_mm.size());
  for (const Eigen::Vector3d& p : foot_path_mm)
    pitched.push_back(pivot_mm + to_body * (p - pivot_mm));
  return pitched;
}

std::vector<Eigen::Vector3d> JointTrajectoryDeg(const LegGeometry& geometry,
                                                const std::vector<Eigen::Vector3d>& foot_path_mm) {
  std::vector<Eigen::Vector3d> angles(foot_path_mm.size());
  for (size_t t = 0; t < foot_path_mm.size(); ++t) {
    try {
      const Eigen::Vector3d q_rad = InverseKinematics(geometry, foot_path_mm[t]);
      angles[t] = {RadToDeg(q_rad[0]), RadToDeg(q_rad[1]), RadToDeg(q_rad[2])};
    } catch (const std::domain_error& e) {
      throw std::domain_error("tick " + std::to_string(t) + ": " + e.what());
    }
  }
  return angles;
}

}  // namespace leglab
