#include "leglab/model/floor.h"

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cmath>
#include <stdexcept>
#include <string>

#include "leglab/model/quadratic_program.h"

namespace leglab {
namespace {

[[noreturn]] void Fail(const std::string& what) { throw std::invalid_argument("floor: " + what); }

}  // namespace

std::vector<double> FloorTrajectory(std::span<const double> desired_deg,
                                    const JointModelParams& params) {
  ValidateJointModelParams(params);
  const int period = static_cast<int>(desired_deg.size());
  if (period < 3) {
    Fail("the desired cycle needs at least 3 samples, got " + std::to_string(period));
  }
  for (int t = 0; t < period; ++t) {
    if (!std::isfinite(desired_deg[t])) {
      Fail("desired sample " + std::to_string(t) + " is not finite");
    }
  }
  const double speed = params.v_max_deg_per_tick;
  const double speed_change = 2.0 * speed / params.accel_ticks;

  // Rows 4t .. 4t+3: the speed from t to t+1 at most v_max either way, and the change of
  // speed at t at most 2 v_max / a either way.
  const int num_rows = 4 * period;
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<size_t>(period) * 10);
  Eigen::VectorXd bounds(num_rows);
  for (int t = 0; t < period; ++t) {
    const int next = (t + 1) % period;
    const int previous = (t + period - 1) % period;
    for (int sign : {1, -1}) {
      const int speed_row = 4 * t + (sign > 0 ? 0 : 1);
      entries.emplace_back(speed_row, next, sign);
      entries.emplace_back(speed_row, t, -sign);
      bounds[speed_row] = speed;
      const int change_row = 4 * t + (sign > 0 ? 2 : 3);
      entries.emplace_back(change_row, next, sign);
      entries.emplace_back(change_row, t, -2 * sign);
      entries.emplace_back(change_row, previous, sign);
      bounds[change_row] = speed_change;
    }
  }
  QuadraticProgram qp;
  qp.constraints.resize(num_rows, period);
  qp.constraints.setFromTriplets(entries.begin(), entries.end());
  qp.bounds = bounds;

  const Eigen::Map<const Eigen::VectorXd> desired(desired_deg.data(), period);
  if (((qp.constraints * desired).array() <= bounds.array()).all()) {
    return {desired_deg.begin(), desired_deg.end()};
  }
  qp.hessian = Eigen::MatrixXd::Identity(period, period);
  qp.gradient = -desired;
  const Eigen::VectorXd start = Eigen::VectorXd::Constant(period, desired.mean());
  const Eigen::VectorXd x = SolveQuadraticProgram(qp, start).x;
  return {x.data(), x.data() + period};
}

}  // namespace leglab
