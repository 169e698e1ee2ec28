#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "leglab/model/kinematics.h"

namespace leglab {

/// The Aibo's step: 88 ticks of 8 ms = 704 ms.
inline constexpr int kStepTicks = 88;

/// One cycle of the step test of eq. 1: theta_test for t < t_step / 2, then 0.
/// Throws std::invalid_argument if t_step < 2.
std::vector<double> StepTestRequests(double theta_test_deg, int t_step_ticks = kStepTicks);

/// The half-elliptical foot locus of the UT Austin Villa walk (ers210a.md): a flat bottom on
/// the ground, run backward at constant speed for `ground_fraction` of the step, then a
/// half-ellipse flown forward (uniform in the ellipse's angle) for the rest.
struct HalfEllipseLocus {
  double length_mm = 48.93;                  ///< fore-aft length of the flat bottom
  double height_mm = 42.0;                   ///< height of the arc above the flat bottom
  double ground_fraction = 0.5;              ///< fraction of the step on the ground, in (0, 1)
  Eigen::Vector3d centre_mm{0.0, 0.0, 0.0};  ///< middle of the flat bottom, body frame
  int t_step_ticks = kStepTicks;             ///< ticks per step
};

/// Empty when the locus is valid; otherwise what is wrong, naming the field
/// ("ground_fraction must be in (0, 1)").
std::string HalfEllipseLocusProblem(const HalfEllipseLocus& locus);

/// One step of foot positions (body frame, mm), t = 0..t_step-1; t = 0 is the front end of the
/// flat bottom (touch-down). Throws std::invalid_argument naming a bad locus parameter.
std::vector<Eigen::Vector3d> HalfEllipseFootPath(const HalfEllipseLocus& locus);

/// Joint angles (rows: ticks; columns: rotator, abductor, knee), degrees, that put the foot on
/// `foot_path_mm` by closed-form inverse kinematics. Throws std::domain_error naming the tick
/// and the point when one is unreachable.
std::vector<Eigen::Vector3d> JointTrajectoryDeg(const LegGeometry& geometry,
                                                const std::vector<Eigen::Vector3d>& foot_path_mm);

}  // namespace leglab
