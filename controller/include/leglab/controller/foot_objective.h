#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/model/kinematics.h"

namespace leglab {

/// The foot's position (mm, ForwardKinematics) at every tick of a cycle of joint angles (deg).
std::vector<Eigen::Vector3d> FootPathMm(const LegGeometry& geometry, const DesiredCycle& cycle_deg);

/// RMS over the cycle of |FK(angles(t)) - desired_foot_mm(t)|, mm. Sizes must match.
double FootRmsErrorMm(const LegGeometry& geometry, const DesiredCycle& angles_deg,
                      std::span<const Eigen::Vector3d> desired_foot_mm);

/// Joint `joint`'s share of the foot objective, as the weighted problem OptimizeRequests
/// solves: minimise sum_t w_t (theta_j(t) - target(t))^2.
struct FootJointProblem {
  std::vector<double> target_deg;  ///< per tick, deg
  std::vector<double> weights;     ///< per tick, >= 0, scaled to mean 1
  /// The weights' mean before that scaling, (1 + joint_weight) mean_t |K_j|^2, mm^2/deg^2:
  /// a term c sum_t (...)^2 of this problem is (weight_scale c) sum_t (...)^2 in the foot
  /// objective's units.
  double weight_scale = 0.0;
};

/// One Gauss-Newton linearisation of the foot objective in joint `joint` at `angles_deg` (the
/// other joints held there): sum_t |FK(theta(t)) - desired_foot_mm(t)|^2 + lambda sum_t
/// (theta_j(t) - desired_deg(t)_j)^2, lambda = joint_weight times the mean |K_j|^2 over the
/// cycle, K_j = column j of FootJacobian (mm/deg). Linearised, r(t) + K_j(t) (theta_j(t) -
/// angles_j(t)) with r = FK(angles) - desired foot, it is the weighted problem with w_t =
/// |K_j|^2 + lambda and target (|K_j|^2 angles_j - K_j.r + lambda desired_j) / w_t (weights
/// then scaled to mean 1, so a solver's tolerance stays in degrees). ILC's foot objective (one
/// such solve per joint per step, on measured angles) and optimal's (sweeps of them on the
/// model's predicted steady state) both use it. Empty when the weights vanish or a target is
/// not finite (nothing to solve).
std::optional<FootJointProblem> FootObjectiveJointProblem(
    const LegGeometry& geometry, std::span<const Eigen::Vector3d> desired_foot_mm,
    const DesiredCycle& desired_deg, const DesiredCycle& angles_deg, int joint,
    double joint_weight);

}  // namespace leglab
