// Tests of cyclic_banded_cholesky.cc against a dense Eigen solve of the same matrix, and a
// case worked by hand.
#include "leglab/model/cyclic_banded_cholesky.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace leglab {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// A random symmetric cyclic banded matrix of half-width w (entries (i, i +- k mod n), k <= w),
// strictly diagonally dominant with a positive diagonal, hence positive definite.
MatrixXd RandomCyclicBanded(int n, int w, std::mt19937& rng) {
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  MatrixXd a = MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    for (int k = 1; k <= w; ++k) {
      const int j = (i + k) % n;
      const double v = entry(rng);
      a(i, j) += v;
      a(j, i) += v;
    }
  }
  for (int i = 0; i < n; ++i) a(i, i) = a.row(i).cwiseAbs().sum() + 0.5 + 0.5 * (entry(rng) + 1.0);
  return a;
}

// Loads the lower triangle of `a` into `solver`, entry by entry.
void Load(const MatrixXd& a, CyclicBandedCholesky& solver) {
  solver.Reset(static_cast<int>(a.rows()));
  for (int i = 0; i < a.rows(); ++i) {
    for (int j = 0; j <= i; ++j) {
      if (a(i, j) != 0.0) solver.Add(i, j, a(i, j));
    }
  }
}

TEST(CyclicBandedCholesky, SolvesTwoByTwoByHand) {
  // [4 2; 2 3] x = [2; 1]: determinant 8, x = [3 -2; -2 4] [2; 1] / 8 = [1/2, 0].
  CyclicBandedCholesky solver;
  solver.Reset(2);
  solver.Add(0, 0, 4.0);
  solver.Add(1, 0, 1.0);
  solver.Add(0, 1, 1.0);  // either order: the same symmetric entry, summed
  solver.Add(1, 1, 3.0);
  ASSERT_TRUE(solver.Factor());
  VectorXd b(2);
  b << 2.0, 1.0;
  solver.Solve(b);
  EXPECT_NEAR(b[0], 0.5, 1e-15);
  EXPECT_NEAR(b[1], 0.0, 1e-15);
}

TEST(CyclicBandedCholesky, MatchesADenseSolveOnRandomCyclicBandedSystems) {
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  for (const int n : {3, 5, 12, 40, 97}) {
    for (const int w : {1, 2, 4}) {
      if (2 * w >= n) continue;
      const MatrixXd a = RandomCyclicBanded(n, w, rng);
      VectorXd b(n);
      for (int i = 0; i < n; ++i) b[i] = entry(rng);
      const VectorXd expected = a.llt().solve(b);
      CyclicBandedCholesky solver;
      Load(a, solver);
      ASSERT_TRUE(solver.Factor()) << "n " << n << " w " << w;
      VectorXd x = b;
      solver.Solve(x);
      EXPECT_LT((x - expected).norm(), 1e-12 * expected.norm()) << "n " << n << " w " << w;
      EXPECT_LT((a * x - b).norm(), 1e-12 * b.norm()) << "n " << n << " w " << w;
    }
  }
}

TEST(CyclicBandedCholesky, ReusedForANewMatrixIsAsFresh) {
  // Reset clears only the last matrix's envelope: a second matrix of the same size with a
  // narrower envelope must still solve as in a fresh solver, bit for bit.
  std::mt19937 rng(7);
  const MatrixXd wide = RandomCyclicBanded(30, 4, rng);
  const MatrixXd narrow = RandomCyclicBanded(30, 1, rng);
  VectorXd b = VectorXd::LinSpaced(30, -1.0, 2.0);
  CyclicBandedCholesky reused;
  Load(wide, reused);
  ASSERT_TRUE(reused.Factor());
  Load(narrow, reused);
  ASSERT_TRUE(reused.Factor());
  CyclicBandedCholesky fresh;
  Load(narrow, fresh);
  ASSERT_TRUE(fresh.Factor());
  VectorXd x_reused = b;
  VectorXd x_fresh = b;
  reused.Solve(x_reused);
  fresh.Solve(x_fresh);
  EXPECT_EQ(x_reused, x_fresh);
  EXPECT_LT((x_fresh - narrow.llt().solve(b)).norm(), 1e-12 * x_fresh.norm());
}

TEST(CyclicBandedCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  // [1 2; 2 1]: eigenvalues 3 and -1.
  CyclicBandedCholesky solver;
  solver.Reset(2);
  solver.Add(0, 0, 1.0);
  solver.Add(1, 0, 2.0);
  solver.Add(1, 1, 1.0);
  EXPECT_FALSE(solver.Factor());
  // Cyclic tridiagonal, 0.5 on the diagonal and -1 beside it: the constant vector gives
  // x' A x = (0.5 - 2) n < 0. The second pivot is 0.5 - (-1)^2 / 0.5 = -1.5.
  const int n = 6;
  solver.Reset(n);
  for (int i = 0; i < n; ++i) {
    solver.Add(i, i, 0.5);
    solver.Add(i, (i + 1) % n, -1.0);
  }
  EXPECT_FALSE(solver.Factor());
}

}  // namespace
}  // namespace leglab
