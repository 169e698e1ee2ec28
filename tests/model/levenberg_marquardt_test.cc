// Tests of levenberg_marquardt.cc. Every expected minimiser is known by hand: Rosenbrock's (1, 1)
// from its residuals, a straight line fitted to three points by the normal equations worked on
// paper, and the edge of an admissible region.
#include "leglab/model/levenberg_marquardt.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

namespace leglab {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Writes J^T J and -J^T r for residuals r and Jacobian J; returns |r|^2.
double NormalEquations(const VectorXd& r, const MatrixXd& j, MatrixXd& jtj, VectorXd& descent) {
  jtj = j.transpose() * j;
  descent = -(j.transpose() * r);
  return r.squaredNorm();
}

// Rosenbrock's residuals r = (10 (y - x^2), 1 - x): |r|^2 is Rosenbrock's function, minimum 0
// at (1, 1).
double Rosenbrock(const VectorXd& p, MatrixXd& jtj, VectorXd& descent) {
  VectorXd r(2);
  r << 10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0];
  MatrixXd j(2, 2);
  j << -20.0 * p[0], 10.0, -1.0, 0.0;
  return NormalEquations(r, j, jtj, descent);
}

TEST(LevenbergMarquardt, FindsRosenbrocksMinimum) {
  LevenbergMarquardt solver(2);
  VectorXd x(2);
  x << -1.2, 1.0;
  const double error = solver.Minimise(Rosenbrock, x, 1e-12, 200);
  EXPECT_NEAR(x[0], 1.0, 1e-8);
  EXPECT_NEAR(x[1], 1.0, 1e-8);
  EXPECT_LT(error, 1e-16);
}

TEST(LevenbergMarquardt, FitsALineToThreePoints) {
  // y = p0 + p1 t through (0, 1), (1, 3), (2, 4). By hand: t mean 1, y mean 8/3, slope
  // sum (t - 1)(y - 8/3) / sum (t - 1)^2 = (5/3 + 4/3) / 2 = 3/2, intercept 8/3 - 3/2 = 7/6;
  // residuals -1/6, 1/3, -1/6, squared error 1/6.
  auto line = [](const VectorXd& p, MatrixXd& jtj, VectorXd& descent) {
    VectorXd r(3);
    r << p[0] - 1.0, p[0] + p[1] - 3.0, p[0] + 2.0 * p[1] - 4.0;
    MatrixXd j(3, 2);
    j << 1.0, 0.0, 1.0, 1.0, 1.0, 2.0;
    return NormalEquations(r, j, jtj, descent);
  };
  LevenbergMarquardt solver(2);
  VectorXd x = VectorXd::Zero(2);
  const double error = solver.Minimise(line, x, 1e-14, 100);
  EXPECT_NEAR(x[0], 7.0 / 6.0, 1e-9);
  EXPECT_NEAR(x[1], 1.5, 1e-9);
  EXPECT_NEAR(error, 1.0 / 6.0, 1e-14);
}

TEST(LevenbergMarquardt, StopsAtTheEdgeOfTheAdmissibleRegion) {
  // r = x - 2 with only x <= 1 admissible: the best admissible point is the edge, 1.
  auto bounded = [](const VectorXd& p, MatrixXd& jtj, VectorXd& descent) {
    if (p[0] > 1.0) return std::numeric_limits<double>::infinity();
    VectorXd r(1);
    r << p[0] - 2.0;
    return NormalEquations(r, MatrixXd::Identity(1, 1), jtj, descent);
  };
  LevenbergMarquardt solver(1);
  VectorXd x = VectorXd::Zero(1);
  LevenbergMarquardt::Run run = solver.Start(bounded, x);
  solver.Continue(bounded, run, 0.0, 1000);
  EXPECT_LE(run.x[0], 1.0);
  EXPECT_GT(run.x[0], 1.0 - 1e-6);
  EXPECT_EQ(run.error, (run.x[0] - 2.0) * (run.x[0] - 2.0));
  EXPECT_TRUE(run.finished);  // no step lowers the error any more: stopped for good
}

TEST(LevenbergMarquardt, ResumingAtATighterToleranceIsOneRunAtIt) {
  LevenbergMarquardt solver(2);
  VectorXd x(2);
  x << -1.2, 1.0;
  LevenbergMarquardt::Run resumed = solver.Start(Rosenbrock, x);
  solver.Continue(Rosenbrock, resumed, 1e-1, 200);
  const int loose_iterations = resumed.iteration;
  solver.Continue(Rosenbrock, resumed, 1e-6, 200);
  LevenbergMarquardt::Run direct = solver.Start(Rosenbrock, x);
  solver.Continue(Rosenbrock, direct, 1e-6, 200);
  EXPECT_LT(loose_iterations, direct.iteration);  // the loose stop came first
  EXPECT_EQ(resumed.x, direct.x);                 // and then the same steps, bit for bit
  EXPECT_EQ(resumed.error, direct.error);
  EXPECT_EQ(resumed.iteration, direct.iteration);
  EXPECT_EQ(resumed.damping, direct.damping);
}

TEST(LevenbergMarquardt, CountsTrialStepsAgainstTheLimit) {
  LevenbergMarquardt solver(2);
  VectorXd x(2);
  x << -1.2, 1.0;
  LevenbergMarquardt::Run run = solver.Start(Rosenbrock, x);
  solver.Continue(Rosenbrock, run, 0.0, 3);
  EXPECT_EQ(run.iteration, 3);
  EXPECT_TRUE(run.finished);
  VectorXd start(2);
  start << -1.2, 1.0;
  MatrixXd jtj(2, 2);
  VectorXd descent(2);
  EXPECT_LT(run.error, Rosenbrock(start, jtj, descent));  // never worse than the start
}

}  // namespace
}  // namespace leglab
