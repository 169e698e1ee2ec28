#include "leglab/controller/foot_objective.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "leglab/core/units.h"

namespace leglab {
namespace {

Eigen::Vector3d AnglesRad(const LegAngles& angles_deg) {
  return {DegToRad(angles_deg[0]), DegToRad(angles_deg[1]), DegToRad(angles_deg[2])};
}

}  // namespace

std::vector<Eigen::Vector3d> FootPathMm(const LegGeometry& geometry,
                                        const DesiredCycle& cycle_deg) {
  std::vector<Eigen::Vector3d> path;
  path.reserve(cycle_deg.size());
  for (const LegAngles& q : cycle_deg) path.push_back(ForwardKinematics(geometry, AnglesRad(q)));
  return path;
}

double FootRmsErrorMm(const LegGeometry& geometry, const DesiredCycle& angles_deg,
                      std::span<const Eigen::Vector3d> desired_foot_mm) {
  assert(angles_deg.size() == desired_foot_mm.size() && !angles_deg.empty());
  double sum = 0.0;
  for (size_t t = 0; t < angles_deg.size(); ++t) {
    sum +=
        (ForwardKinematics(geometry, AnglesRad(angles_deg[t])) - desired_foot_mm[t]).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(angles_deg.size()));
}

std::optional<FootJointProblem> FootObjectiveJointProblem(
    const LegGeometry& geometry, std::span<const Eigen::Vector3d> desired_foot_mm,
    const DesiredCycle& desired_deg, const DesiredCycle& angles_deg, int joint,
    double joint_weight) {
  const auto period = static_cast<int>(angles_deg.size());
  assert(desired_deg.size() == angles_deg.size() && desired_foot_mm.size() == angles_deg.size());
  std::vector<double> foot_weight(period);
  std::vector<double> pulls(period);  // K_j . r, mm^2/deg
  for (int t = 0; t < period; ++t) {
    const Eigen::Vector3d q_rad = AnglesRad(angles_deg[t]);
    const Eigen::Vector3d column = FootJacobian(geometry, q_rad).col(joint) * DegToRad(1.0);
    const Eigen::Vector3d error = ForwardKinematics(geometry, q_rad) - desired_foot_mm[t];
    foot_weight[t] = column.squaredNorm();
    pulls[t] = column.dot(error);
  }
  double mean_weight = 0.0;
  for (double w : foot_weight) mean_weight += w;
  mean_weight /= period;
  const double lambda = joint_weight * mean_weight;
  if (!(mean_weight + lambda > 0.0)) return std::nullopt;
  FootJointProblem problem{std::vector<double>(period), std::vector<double>(period),
                           mean_weight + lambda};
  for (int t = 0; t < period; ++t) {
    const double w = foot_weight[t] + lambda;
    const double angle = angles_deg[t][joint];
    const double desired = desired_deg[t][joint];
    problem.target_deg[t] =
        w > 0.0 ? (foot_weight[t] * angle - pulls[t] + lambda * desired) / w : desired;
    problem.weights[t] = w / (mean_weight + lambda);
  }
  if (!std::all_of(problem.target_deg.begin(), problem.target_deg.end(),
                   [](double x) { return std::isfinite(x); })) {
    return std::nullopt;
  }
  return problem;
}

}  // namespace leglab
