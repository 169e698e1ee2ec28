#pragma once

#include <Eigen/Dense>
#include <functional>
#include <limits>

namespace leglab {

/// A nonlinear least-squares objective for LevenbergMarquardt, at x (size n): returns
/// |r(x)|^2, the sum of squared residuals, and writes the Gauss-Newton normal equations into
/// `jtj` = J^T J (n x n, symmetric, both triangles) and `descent` = -J^T r (size n), J = dr/dx.
/// Both arrive sized. Returns +infinity where x is not admissible (the solver never moves
/// there; it ignores `jtj` and `descent` then).
using LeastSquaresObjective =
    std::function<double(const Eigen::VectorXd& x, Eigen::MatrixXd& jtj, Eigen::VectorXd& descent)>;

/// Levenberg-Marquardt minimisation of a LeastSquaresObjective over R^n, with Marquardt's scaling
/// D = diag(J^T J) (floored at 1e-12, so that a variable with no effect still has a solvable
/// step) and Nielsen's damping update. A step solves (J^T J + damping D) step = -J^T r and is
/// taken only when it lowers |r|^2; a rejected step (typically one across a kink of r) raises
/// the damping until the scaled step is a quarter as long, as a trust region would, without
/// evaluating the objective. It stops when an accepted step lowers |r|^2 by at most
/// `relative_tolerance` times the new value (converged), when no step can lower it (the damping
/// has grown past 1e12), or after `max_iterations` trial steps. Owns its work space, reused from
/// step to step and run to run. Deterministic.
class LevenbergMarquardt {
 public:
  /// Where a run stands: the point, its squared error and normal equations, the damping and
  /// the trial steps taken.
  struct Run {
    Eigen::VectorXd x;         ///< the point reached, size n
    double error = 0.0;        ///< |r(x)|^2
    Eigen::MatrixXd hessian;   ///< J^T J at x
    Eigen::VectorXd gradient;  ///< -J^T r at x
    double damping = 1e-3;     ///< the damping the next step starts from
    int iteration = 0;         ///< trial steps taken
    bool finished = false;     ///< stopped for good (no step lowers the error, or out of steps)
    /// What the last accepted step gained (its test against a tolerance is repeated on resuming).
    double last_gain = std::numeric_limits<double>::infinity();
  };

  /// A solver for n variables (n >= 1).
  explicit LevenbergMarquardt(int n);

  /// A run from x (size n), evaluated but not yet stepped.
  Run Start(const LeastSquaresObjective& objective, const Eigen::VectorXd& x);

  /// Steps `run` until one of the stopping rules holds (`max_iterations` counts the run's trial
  /// steps from its start). Resumable: a run stopped at a loose tolerance and continued at a
  /// tighter one takes exactly the steps of one run at the tighter tolerance throughout (the
  /// looser stop is an accepted step after which the tighter run simply goes on). Returns at
  /// once if the run is finished or already meets the tolerance.
  void Continue(const LeastSquaresObjective& objective, Run& run, double relative_tolerance,
                int max_iterations);

  /// Start and Continue in one: from x, writes the point reached into x and returns |r|^2 there.
  double Minimise(const LeastSquaresObjective& objective, Eigen::VectorXd& x,
                  double relative_tolerance, int max_iterations);

 private:
  // The step (J^T J + damping D) step = -J^T r at the current point, into step_.
  void SolveDamped(double damping);
  // Length of a step in the scaling D.
  double ScaledNorm(const Eigen::VectorXd& step) const;

  int n_;
  Eigen::MatrixXd hessian_;
  Eigen::VectorXd gradient_;
  Eigen::MatrixXd trial_hessian_;
  Eigen::VectorXd trial_gradient_;
  Eigen::MatrixXd damped_;
  Eigen::VectorXd step_;
  Eigen::VectorXd trial_;
};

}  // namespace leglab
