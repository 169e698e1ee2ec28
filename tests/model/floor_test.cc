// Tests of floor.cc, and of the dense active-set solver quadratic_program.cc beside this file,
// the reference the floor is checked against (its own results are checked here too). Every
// expected result is found without the floor's solver: by enumerating candidate active sets, by
// non-negative least squares on the optimality conditions, by the dense solver, by symmetry, or
// by hand.
#include "leglab/model/floor.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "leglab/model/metrics.h"
#include "leglab/model/paper.h"
#include "quadratic_program.h"

namespace leglab {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// ---- An independent description of the floor's constraints ----------------------------------

// The floor's rows, dense and written out again here: for every t, +-(x(t+1) - x(t)) <= v and
// +-(x(t+1) - 2 x(t) + x(t-1)) <= 2 v / a.
struct DenseRows {
  MatrixXd a;
  VectorXd b;
};

DenseRows FloorRows(int period, const JointModelParams& params) {
  const double v = params.v_max_deg_per_tick;
  const double c = 2.0 * v / params.accel_ticks;
  const int num_rows = 4 * period;
  DenseRows rows{MatrixXd::Zero(num_rows, period), VectorXd(num_rows)};
  int r = 0;
  for (int t = 0; t < period; ++t) {
    const int next = (t + 1) % period;
    const int prev = (t + period - 1) % period;
    for (double sign : {1.0, -1.0}) {
      rows.a(r, next) += sign;
      rows.a(r, t) -= sign;
      rows.b[r++] = v;
      rows.a(r, next) += sign;
      rows.a(r, t) -= 2.0 * sign;
      rows.a(r, prev) += sign;
      rows.b[r++] = c;
    }
  }
  return rows;
}

VectorXd AsVector(const std::vector<double>& v) {
  return Eigen::Map<const VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// Largest violation of A x <= b (<= 0 when feasible).
double MaxViolation(const DenseRows& rows, const VectorXd& x) {
  return (rows.a * x - rows.b).maxCoeff();
}

// ---- Brute force: enumerate active sets ----------------------------------------------------

// The minimiser of 0.5 x'Hx + g'x subject to A x <= b, found by trying every linearly
// independent set S of at most n rows: minimise with A_S x = b_S (a KKT solve) and keep the best
// feasible result. The optimum is the minimiser on one such set (its multipliers can be carried
// by independent active rows), so this is exact; it is exponential, so only for tiny programs.
VectorXd EnumerateActiveSets(const MatrixXd& h, const VectorXd& g, const DenseRows& rows) {
  const int n = static_cast<int>(h.rows());
  const int m = static_cast<int>(rows.a.rows());
  double best = std::numeric_limits<double>::infinity();
  VectorXd best_x;
  std::vector<int> subset;
  std::function<void(int)> visit = [&](int first) {
    const int k = static_cast<int>(subset.size());
    MatrixXd a_s(k, n);
    VectorXd b_s(k);
    for (int i = 0; i < k; ++i) {
      a_s.row(i) = rows.a.row(subset[i]);
      b_s[i] = rows.b[subset[i]];
    }
    if (k > 0 && Eigen::FullPivLU<MatrixXd>(a_s).rank() < k) return;  // dependent: skip
    MatrixXd kkt = MatrixXd::Zero(n + k, n + k);
    kkt.topLeftCorner(n, n) = h;
    kkt.bottomLeftCorner(k, n) = a_s;
    kkt.topRightCorner(n, k) = a_s.transpose();
    VectorXd rhs(n + k);
    rhs << -g, b_s;
    const VectorXd x = kkt.fullPivLu().solve(rhs).head(n);
    if ((rows.a * x - rows.b).maxCoeff() <= 1e-9) {
      const double objective = 0.5 * x.dot(h * x) + g.dot(x);
      if (objective < best) {
        best = objective;
        best_x = x;
      }
    }
    if (k == n) return;
    for (int i = first; i < m; ++i) {
      subset.push_back(i);
      visit(i + 1);
      subset.pop_back();
    }
  };
  visit(0);
  return best_x;
}

// ---- Optimality conditions by non-negative least squares -----------------------------------

// Lawson and Hanson's NNLS: min |E lambda - f| subject to lambda >= 0.
VectorXd Nnls(const MatrixXd& e, const VectorXd& f) {
  const int k = static_cast<int>(e.cols());
  VectorXd lambda = VectorXd::Zero(k);
  std::vector<bool> passive(k, false);
  for (int outer = 0; outer < 3 * k + 10; ++outer) {
    const VectorXd w = e.transpose() * (f - e * lambda);
    int enter = -1;
    double largest = 1e-12 * (1.0 + f.norm());
    for (int i = 0; i < k; ++i) {
      if (!passive[i] && w[i] > largest) {
        largest = w[i];
        enter = i;
      }
    }
    if (enter < 0) break;
    passive[enter] = true;
    for (int inner = 0; inner < 3 * k + 10; ++inner) {
      std::vector<int> p;
      for (int i = 0; i < k; ++i) {
        if (passive[i]) p.push_back(i);
      }
      MatrixXd e_p(e.rows(), static_cast<Eigen::Index>(p.size()));
      for (size_t j = 0; j < p.size(); ++j) e_p.col(static_cast<Eigen::Index>(j)) = e.col(p[j]);
      const VectorXd z_p = e_p.completeOrthogonalDecomposition().solve(f);
      VectorXd z = VectorXd::Zero(k);
      for (size_t j = 0; j < p.size(); ++j) z[p[j]] = z_p[static_cast<Eigen::Index>(j)];
      double alpha = 1.0;
      for (int i : p) {
        if (z[i] <= 0.0) alpha = std::min(alpha, lambda[i] / (lambda[i] - z[i]));
      }
      lambda += alpha * (z - lambda);
      if (alpha == 1.0) break;
      for (int i : p) {
        if (lambda[i] <= 1e-15) {
          lambda[i] = 0.0;
          passive[i] = false;
        }
      }
    }
  }
  return lambda;
}

// How far x is from satisfying the optimality conditions of the projection of D: the residual
// of x - D + A_act' lambda = 0 for the best lambda >= 0 on the rows active at x.
double KktResidual(const DenseRows& rows, const VectorXd& x, const VectorXd& d) {
  const VectorXd slack = rows.b - rows.a * x;
  std::vector<int> active;
  for (int i = 0; i < rows.a.rows(); ++i) {
    if (slack[i] <= 1e-9) active.push_back(i);
  }
  MatrixXd e(x.size(), static_cast<Eigen::Index>(active.size()));
  for (size_t j = 0; j < active.size(); ++j) {
    e.col(static_cast<Eigen::Index>(j)) = rows.a.row(active[j]).transpose();
  }
  const VectorXd lambda = Nnls(e, d - x);
  EXPECT_GE(lambda.size() == 0 ? 0.0 : lambda.minCoeff(), 0.0);
  return (e * lambda - (d - x)).lpNorm<Eigen::Infinity>();
}

// ---- Cycles ------------------------------------------------------------------------------

// A walking-like cycle: D(t) = 40 sin(2 pi t / 88) + 15 sin(4 pi t / 88 + 1).
std::vector<double> WalkingCycle() {
  std::vector<double> d(88);
  for (int t = 0; t < 88; ++t) {
    d[t] = 40.0 * std::sin(2.0 * M_PI * t / 88.0) + 15.0 * std::sin(4.0 * M_PI * t / 88.0 + 1.0);
  }
  return d;
}

std::vector<double> RandomCycle(int period, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-amplitude, amplitude);
  std::vector<double> d(period);
  for (double& value : d) value = uniform(rng);
  return d;
}

// ---- The floor -----------------------------------------------------------------------------

TEST(Floor, ReturnsACycleThatMeetsTheBoundsUnchanged) {
  // 20 sin(2 pi t / 88): speed at most 20 (2 pi / 88) = 1.43 <= 2.5 deg/tick, change of speed
  // at most 20 (2 pi / 88)^2 = 0.10 <= 2 * 2.5 / 6 = 0.83 deg/tick^2.
  std::vector<double> d(88);
  for (int t = 0; t < 88; ++t) d[t] = 5.0 + 20.0 * std::sin(2.0 * M_PI * t / 88.0);
  EXPECT_EQ(FloorTrajectory(d, paper::kTable1), d);
}

TEST(Floor, MatchesEnumerationOfActiveSetsOnSmallCycles) {
  const std::vector<std::vector<double>> shapes = {
      {0.0, 0.0, 10.0, 10.0},       // a step up and back down
      {0.0, 0.0, 0.0, 10.0},        // a spike
      {0.0, 0.0, 0.0, 0.0, -12.0},  // a spike, odd period
      {0.0, 0.0, 30.0, 30.0, 30.0}, RandomCycle(4, 10.0, 1),
      RandomCycle(5, 10.0, 2),      RandomCycle(5, 3.0, 3),
  };
  for (const JointModelParams& params :
       {paper::kTable1, JointModelParams{2.5, 7.0, 4, 1}, JointModelParams{1.0, 7.0, 4, 3}}) {
    for (const std::vector<double>& shape : shapes) {
      const int period = static_cast<int>(shape.size());
      const DenseRows rows = FloorRows(period, params);
      const VectorXd d = AsVector(shape);
      const VectorXd expected = EnumerateActiveSets(MatrixXd::Identity(period, period), -d, rows);
      const VectorXd x = AsVector(FloorTrajectory(shape, params));
      SCOPED_TRACE(::testing::Message()
                   << "period " << period << ", a " << params.accel_ticks << ", D(0) " << shape[0]);
      EXPECT_LE(MaxViolation(rows, x), 1e-9);
      EXPECT_LE((x - d).squaredNorm(), (expected - d).squaredNorm() + 1e-9);
      EXPECT_LT((x - expected).lpNorm<Eigen::Infinity>(), 1e-9);  // the projection is unique
    }
  }
}

TEST(Floor, MeetsTheOptimalityConditionsOnAWalkingCycle) {
  const std::vector<double> d = WalkingCycle();
  const VectorXd x = AsVector(FloorTrajectory(d, paper::kTable1));
  const DenseRows rows = FloorRows(88, paper::kTable1);
  EXPECT_LE(MaxViolation(rows, x), 1e-9);
  // x - D = -A_act' lambda with lambda >= 0: with feasibility this proves x is the projection.
  EXPECT_LT(KktResidual(rows, x, AsVector(d)), 1e-8);

  // The same through the variational inequality (x - D).(y - x) >= 0 for feasible y: random
  // directions r from the mean, scaled to stay feasible.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  const double mean = x.mean();
  for (int trial = 0; trial < 500; ++trial) {
    VectorXd r(88);
    for (double& value : r) value = uniform(rng);
    const VectorXd rate = rows.a * r;
    double largest = std::numeric_limits<double>::infinity();
    for (int i = 0; i < rate.size(); ++i) {
      if (rate[i] > 0.0) largest = std::min(largest, rows.b[i] / rate[i]);
    }
    const VectorXd y = VectorXd::Constant(88, mean) + fraction(rng) * largest * r;
    ASSERT_LE(MaxViolation(rows, y), 1e-12);
    EXPECT_GE((x - AsVector(d)).dot(y - x), -1e-9);
  }

  // Regression pin for the report (the value is this solver's, certified by the checks above).
  EXPECT_NEAR(RmsDistance(std::vector<double>(x.data(), x.data() + 88), d), 6.923747, 1e-6);
}

TEST(Floor, MeetsTheOptimalityConditionsOnRandomCycles) {
  for (unsigned seed = 10; seed < 16; ++seed) {
    const int period = 40 + static_cast<int>(seed);
    const std::vector<double> d = RandomCycle(period, 30.0, seed);
    for (int accel : {1, 2, 6}) {
      const JointModelParams params{2.5, 7.0, 4, accel};
      const VectorXd x = AsVector(FloorTrajectory(d, params));
      const DenseRows rows = FloorRows(period, params);
      SCOPED_TRACE(::testing::Message() << "seed " << seed << ", a " << accel);
      EXPECT_LE(MaxViolation(rows, x), 1e-9);
      EXPECT_LT(KktResidual(rows, x, AsVector(d)), 1e-8);
    }
  }
}

TEST(Floor, ProjectsAZigzagOntoTheLargestFeasibleZigzag) {
  // D(t) = m + A (-1)^t. D is unchanged by the map x(t) -> 2m - x(t + 1), and so are the bounds,
  // so the projection is too: x(t) = m + u (-1)^t. Then |x(t+1) - x(t)| = 2|u| <= v and
  // |x(t+1) - 2x(t) + x(t-1)| = 4|u| <= c, and the nearest u to A is min(A, v/2, c/4).
  // Paper model: v = 2.5, c = 5/6, u = 5/24. With a = 1, c = 2v: u = v/2 = 1.25, where all 2T
  // rows of the one sign are active at once (degenerate: they span only T - 1 dimensions).
  const double m = 3.0;
  const double amplitude = 10.0;
  std::vector<double> d(88);
  for (int t = 0; t < 88; ++t) d[t] = m + (t % 2 == 0 ? amplitude : -amplitude);
  const std::vector<std::pair<JointModelParams, double>> cases = {
      {paper::kTable1, 5.0 / 24.0}, {JointModelParams{2.5, 7.0, 4, 1}, 1.25}};
  for (const auto& [params, u] : cases) {
    const std::vector<double> x = FloorTrajectory(d, params);
    for (int t = 0; t < 88; ++t) EXPECT_NEAR(x[t], m + (t % 2 == 0 ? u : -u), 1e-12) << t;
  }
}

TEST(Floor, TurnsAFastSquareWaveIntoARampAtTopSpeed) {
  // D = +40 on ticks 0..43 and -40 on 44..87: a jump of 80 deg where the joint can move 2.5 deg
  // per tick. D(t + 44) = -D(t) and D(43 - k) = -D(44 + k), and the bounds are unchanged by both
  // maps, so the floor has the same symmetries: it crosses zero half-way between 43 and 44. In
  // the middle of each transition it moves at exactly v_max, so x(43) = 1.25 and x(44) = -1.25,
  // and the ramp carries on at 2.5 deg/tick for ten ticks either side (80 deg at 2.5 deg/tick
  // take 32 ticks).
  std::vector<double> d(88);
  for (int t = 0; t < 88; ++t) d[t] = t < 44 ? 40.0 : -40.0;
  const std::vector<double> x = FloorTrajectory(d, paper::kTable1);
  for (int t = 0; t < 88; ++t) {
    EXPECT_NEAR(x[(t + 44) % 88], -x[t], 1e-9) << t;
    EXPECT_NEAR(x[87 - t], -x[t], 1e-9) << t;  // k = 43 - t: 43 - k and 44 + k
  }
  EXPECT_NEAR(x[43], 1.25, 1e-9);
  EXPECT_NEAR(x[44], -1.25, 1e-9);
  for (int k = -10; k < 10; ++k) {
    EXPECT_NEAR(x[44 + k + 1] - x[44 + k], -2.5, 1e-9) << k;
    EXPECT_NEAR(x[(88 + k + 1) % 88] - x[(88 + k) % 88], 2.5, 1e-9) << k;
  }
  EXPECT_LE(MaxViolation(FloorRows(88, paper::kTable1), AsVector(x)), 1e-9);
}

TEST(Floor, ShiftsWithAConstantAndRotatesWithTheCycle) {
  const std::vector<double> d = WalkingCycle();
  const std::vector<double> x = FloorTrajectory(d, paper::kTable1);
  std::vector<double> shifted = d;
  for (double& value : shifted) value += 17.5;
  const std::vector<double> x_shifted = FloorTrajectory(shifted, paper::kTable1);
  std::vector<double> rotated(88);
  for (int t = 0; t < 88; ++t) rotated[t] = d[(t + 13) % 88];
  const std::vector<double> x_rotated = FloorTrajectory(rotated, paper::kTable1);
  for (int t = 0; t < 88; ++t) {
    EXPECT_NEAR(x_shifted[t], x[t] + 17.5, 1e-9) << t;
    EXPECT_NEAR(x_rotated[t], x[(t + 13) % 88], 1e-9) << t;
  }
}

TEST(Floor, EqualsTheDenseActiveSetSolverOnCyclesOfManyShapes) {
  // The dense primal active-set solver shares no code with the floor's interior point. Shapes
  // chosen to be degenerate as well as generic: noise, a zigzag, a square wave, two sines far
  // from zero, steps, spikes; amplitudes 0.01 to 10^4 deg, v_max 0.03 to 30 deg/tick.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int period = 3 + static_cast<int>(rng() % 120);
    const int shape = static_cast<int>(rng() % 6);
    const double amplitude = std::pow(10.0, static_cast<int>(rng() % 7) - 2);
    std::vector<double> d(period);
    for (int t = 0; t < period; ++t) {
      const double phase = 2.0 * M_PI * t / period;
      switch (shape) {
        case 0:
          d[t] = amplitude * uniform(rng);
          break;
        case 1:
          d[t] = t % 2 == 0 ? amplitude : -amplitude;
          break;
        case 2:
          d[t] = t < period / 2 ? amplitude : -amplitude;
          break;
        case 3:
          d[t] = 1000.0 + amplitude * (std::sin(phase) + 0.3 * std::sin(3 * phase + 1));
          break;
        case 4:
          d[t] = amplitude * std::round(3.0 * uniform(rng));
          break;
        default:
          d[t] = t % 7 == 0 ? amplitude : 0.0;
          break;
      }
    }
    const JointModelParams params{std::pow(10.0, 1.5 * uniform(rng)), 7.0, 4,
                                  1 + static_cast<int>(rng() % 10)};
    const DenseRows rows = FloorRows(period, params);
    QuadraticProgram qp;
    qp.hessian = MatrixXd::Identity(period, period);
    qp.gradient = -AsVector(d);
    qp.constraints = rows.a.sparseView();
    qp.bounds = rows.b;
    const VectorXd expected =
        SolveQuadraticProgram(qp, VectorXd::Constant(period, AsVector(d).mean())).x;
    const VectorXd x = AsVector(FloorTrajectory(d, params));
    SCOPED_TRACE(::testing::Message() << "trial " << trial << ", period " << period << ", shape "
                                      << shape << ", amplitude " << amplitude);
    const double scale = std::max(1.0, AsVector(d).lpNorm<Eigen::Infinity>());
    EXPECT_LE(MaxViolation(rows, x), 1e-9 * scale);
    EXPECT_LT((x - expected).lpNorm<Eigen::Infinity>(), 1e-9 * scale);
  }
}

TEST(Floor, OfALongCycleIsItsPeriodsFloorRepeated) {
  // D repeating an 88-tick cycle 100 times is unchanged by a rotation of 88 ticks, and so are
  // the bounds, so its (unique) floor is too: the 88-tick cycle's floor, repeated. 8800 ticks
  // are far beyond what the dense solver or enumeration can check.
  const std::vector<double> one = WalkingCycle();
  std::vector<double> d;
  for (int copy = 0; copy < 100; ++copy) d.insert(d.end(), one.begin(), one.end());
  const std::vector<double> x_one = FloorTrajectory(one, paper::kTable1);
  const std::vector<double> x = FloorTrajectory(d, paper::kTable1);
  ASSERT_EQ(x.size(), d.size());
  for (size_t t = 0; t < x.size(); ++t) ASSERT_NEAR(x[t], x_one[t % 88], 1e-9) << t;
}

TEST(Floor, IsDeterministic) {
  const std::vector<double> d = RandomCycle(120, 50.0, 42);
  EXPECT_EQ(FloorTrajectory(d, paper::kTable1), FloorTrajectory(d, paper::kTable1));
}

TEST(Floor, RejectsBadInput) {
  const std::vector<double> ok = {0.0, 1.0, 2.0, 1.0};
  EXPECT_THROW(FloorTrajectory(std::vector<double>{0.0, 1.0}, paper::kTable1),
               std::invalid_argument);
  EXPECT_THROW(FloorTrajectory(std::vector<double>{}, paper::kTable1), std::invalid_argument);
  EXPECT_THROW(FloorTrajectory(std::vector<double>{0.0, std::nan(""), 1.0}, paper::kTable1),
               std::invalid_argument);
  EXPECT_THROW(
      FloorTrajectory(std::vector<double>{0.0, std::numeric_limits<double>::infinity(), 1.0},
                      paper::kTable1),
      std::invalid_argument);
  EXPECT_THROW(FloorTrajectory(ok, JointModelParams{0.0, 7.0, 4, 6}), std::invalid_argument);
  EXPECT_THROW(FloorTrajectory(ok, JointModelParams{2.5, 7.0, 4, 0}), std::invalid_argument);
  EXPECT_THROW(FloorTrajectory(ok, JointModelParams{2.5, -1.0, 4, 6}), std::invalid_argument);
  EXPECT_NO_THROW(FloorTrajectory(std::vector<double>{0.0, 0.0, 50.0}, paper::kTable1));
}

// ---- The solver on general programs ----------------------------------------------------------

QuadraticProgram MakeProgram(const MatrixXd& h, const VectorXd& g, const DenseRows& rows) {
  QuadraticProgram qp;
  qp.hessian = h;
  qp.gradient = g;
  qp.constraints = rows.a.sparseView();
  qp.bounds = rows.b;
  return qp;
}

TEST(QuadraticProgram, MatchesEnumerationWithAGeneralHessian) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> slack(0.0, 1.0);
  for (int trial = 0; trial < 30; ++trial) {
    const int n = 2 + trial % 4;
    const int m = 2 * n + 2;
    MatrixXd root(n, n);
    for (double& value : root.reshaped()) value = normal(rng);
    const MatrixXd h = root * root.transpose() + 0.1 * MatrixXd::Identity(n, n);
    VectorXd g(n);
    for (double& value : g) value = 5.0 * normal(rng);
    DenseRows rows{MatrixXd(m, n), VectorXd(m)};
    for (double& value : rows.a.reshaped()) value = normal(rng);
    for (double& value : rows.b) value = slack(rng);  // the origin is feasible
    const VectorXd expected = EnumerateActiveSets(h, g, rows);
    const QpSolution s = SolveQuadraticProgram(MakeProgram(h, g, rows), VectorXd::Zero(n));
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    EXPECT_LT((s.x - expected).lpNorm<Eigen::Infinity>(), 1e-8);
    // The certificate: stationary, multipliers >= 0 and only on rows that hold with equality.
    EXPECT_LT((h * s.x + g + rows.a.transpose() * s.multipliers).lpNorm<Eigen::Infinity>(), 1e-9);
    EXPECT_GE(s.multipliers.minCoeff(), 0.0);
    const VectorXd slack_at_x = rows.b - rows.a * s.x;
    EXPECT_GE(slack_at_x.minCoeff(), -1e-12);
    for (int i = 0; i < m; ++i) {
      if (s.multipliers[i] > 0.0) {
        EXPECT_LT(slack_at_x[i], 1e-12) << i;
      }
    }
  }
}

TEST(QuadraticProgram, HandlesRepeatedAndRedundantRows) {
  // min |x - (5, 5)|^2 subject to x1 <= 1 (twice), x2 <= 1, x1 + x2 <= 2: x = (1, 1), where all
  // four rows hold with equality but only two are independent.
  DenseRows rows{MatrixXd(4, 2), VectorXd(4)};
  rows.a << 1, 0, 1, 0, 0, 1, 1, 1;
  rows.b << 1, 1, 1, 2;
  const QpSolution s = SolveQuadraticProgram(
      MakeProgram(MatrixXd::Identity(2, 2), VectorXd::Constant(2, -5.0), rows), VectorXd::Zero(2));
  EXPECT_NEAR(s.x[0], 1.0, 1e-14);
  EXPECT_NEAR(s.x[1], 1.0, 1e-14);
  EXPECT_EQ(s.active_set.size(), 2u);
  EXPECT_LT((s.x - VectorXd::Constant(2, 5.0) + rows.a.transpose() * s.multipliers).norm(), 1e-12);
}

TEST(QuadraticProgram, WithoutActiveRowsReturnsTheUnconstrainedMinimiser) {
  // min 0.5 x'Hx + g'x with H = [[2, 1], [1, 2]], g = (-3, -3): x = (1, 1); the bound x1 <= 5
  // stays inactive.
  MatrixXd h(2, 2);
  h << 2, 1, 1, 2;
  DenseRows rows{MatrixXd(1, 2), VectorXd(1)};
  rows.a << 1, 0;
  rows.b << 5;
  const QpSolution s =
      SolveQuadraticProgram(MakeProgram(h, VectorXd::Constant(2, -3.0), rows), VectorXd::Zero(2));
  EXPECT_NEAR(s.x[0], 1.0, 1e-14);
  EXPECT_NEAR(s.x[1], 1.0, 1e-14);
  EXPECT_TRUE(s.active_set.empty());
  EXPECT_EQ(s.multipliers[0], 0.0);
}

TEST(QuadraticProgram, RejectsBadInput) {
  DenseRows rows{MatrixXd(1, 2), VectorXd(1)};
  rows.a << 1, 0;
  rows.b << 1;
  const QuadraticProgram good =
      MakeProgram(MatrixXd::Identity(2, 2), VectorXd::Constant(2, -5.0), rows);
  EXPECT_NO_THROW(SolveQuadraticProgram(good, VectorXd::Zero(2)));
  // A start that violates a row.
  EXPECT_THROW(SolveQuadraticProgram(good, VectorXd::Constant(2, 2.0)), std::invalid_argument);
  // Mismatched sizes.
  EXPECT_THROW(SolveQuadraticProgram(good, VectorXd::Zero(3)), std::invalid_argument);
  QuadraticProgram bad = good;
  bad.bounds = VectorXd::Zero(2);
  EXPECT_THROW(SolveQuadraticProgram(bad, VectorXd::Zero(2)), std::invalid_argument);
  // A Hessian that is not positive definite.
  bad = good;
  bad.hessian(1, 1) = -1.0;
  EXPECT_THROW(SolveQuadraticProgram(bad, VectorXd::Zero(2)), std::invalid_argument);
  // Non-finite data.
  bad = good;
  bad.gradient[0] = std::nan("");
  EXPECT_THROW(SolveQuadraticProgram(bad, VectorXd::Zero(2)), std::invalid_argument);
}

}  // namespace
}  // namespace leglab
