#include "leglab/model/levenberg_marquardt.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace leglab {

LevenbergMarquardt::LevenbergMarquardt(int n)
    : n_(n),
      hessian_(n, n),
      gradient_(n),
      trial_hessian_(n, n),
      trial_gradient_(n),
      damped_(n, n),
      step_(n),
      trial_(n) {
  assert(n >= 1);
}

LevenbergMarquardt::Run LevenbergMarquardt::Start(const LeastSquaresObjective& objective,
                                                  const Eigen::VectorXd& x) {
  assert(x.size() == n_);
  Run run;
  run.x = x;
  run.hessian.resize(n_, n_);
  run.gradient.resize(n_);
  run.error = objective(x, run.hessian, run.gradient);
  return run;
}

double LevenbergMarquardt::Minimise(const LeastSquaresObjective& objective, Eigen::VectorXd& x,
                                    double relative_tolerance, int max_iterations) {
  Run run = Start(objective, x);
  Continue(objective, run, relative_tolerance, max_iterations);
  x = run.x;
  return run.error;
}

void LevenbergMarquardt::Continue(const LeastSquaresObjective& objective, Run& run,
                                  double relative_tolerance, int max_iterations) {
  if (run.finished || run.last_gain <= relative_tolerance * run.error) return;
  hessian_.swap(run.hessian);
  gradient_.swap(run.gradient);
  bool converged = false;
  for (; run.iteration < max_iterations && run.damping < 1e12; ++run.iteration) {
    SolveDamped(run.damping);
    trial_ = run.x + step_;
    const double trial_error = objective(trial_, trial_hessian_, trial_gradient_);
    // Reduction of the squared error that the linearised model predicts for the step.
    const double predicted = 2.0 * step_.dot(gradient_) - step_.dot(hessian_ * step_);
    const double ratio = predicted > 0.0 ? (run.error - trial_error) / predicted : -1.0;
    if (trial_error < run.error) {
      run.last_gain = run.error - trial_error;
      converged = run.last_gain <= relative_tolerance * trial_error;
      run.x = trial_;
      run.error = trial_error;
      hessian_.swap(trial_hessian_);
      gradient_.swap(trial_gradient_);
      run.damping *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * std::min(ratio, 1.0) - 1.0, 3));
      if (converged) {
        ++run.iteration;  // where the loop would have gone on
        break;
      }
    } else {
      // Rejected: raise the damping until the scaled step is a quarter as long. Only small
      // solves, no evaluations.
      const double target = 0.25 * ScaledNorm(step_);
      run.damping = std::max(run.damping, 1e-3);
      do {
        run.damping *= 2.0;
        SolveDamped(run.damping);
      } while (ScaledNorm(step_) > target && run.damping < 1e12);
    }
  }
  run.finished = !converged;
  hessian_.swap(run.hessian);
  gradient_.swap(run.gradient);
}

void LevenbergMarquardt::SolveDamped(double damping) {
  damped_ = hessian_;
  for (int i = 0; i < n_; ++i) {
    // A floor keeps the system solvable where a variable has no effect (in the joint-model fit:
    // every term of f saturated leaves theta_0 free).
    damped_(i, i) += damping * std::max(hessian_(i, i), 1e-12);
  }
  step_ = damped_.ldlt().solve(gradient_);
}

double LevenbergMarquardt::ScaledNorm(const Eigen::VectorXd& step) const {
  double sum = 0.0;
  for (int i = 0; i < n_; ++i) sum += std::max(hessian_(i, i), 1e-12) * step[i] * step[i];
  return std::sqrt(sum);
}

}  // namespace leglab
