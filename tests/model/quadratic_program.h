#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <vector>

namespace leglab {

/// A strictly convex quadratic program with linear inequality constraints:
///   minimise 0.5 x'Hx + g'x  subject to  A x <= b,
/// x of size n, H (n x n) symmetric positive definite, A (m x n). Each row of A with its bound
/// is one constraint; a lower bound is a negated row, an equality two rows. A is sparse because
/// the rows met in the model (differences of neighbouring samples) have two or three entries.
struct QuadraticProgram {
  Eigen::MatrixXd hessian;   ///< H, n x n, positive definite; only its lower triangle is read
  Eigen::VectorXd gradient;  ///< g, size n
  Eigen::SparseMatrix<double, Eigen::RowMajor> constraints;  ///< A, m x n
  Eigen::VectorXd bounds;                                    ///< b, size m
};

/// The minimiser with its certificate: H x + g + A' multipliers = 0, multipliers >= 0, and a
/// multiplier is non-zero only on a row of the active set, where A x = b.
struct QpSolution {
  Eigen::VectorXd x;            ///< the minimiser, size n
  Eigen::VectorXd multipliers;  ///< lambda, size m
  std::vector<int> active_set;  ///< rows of A in the final working set (linearly independent)
  int iterations = 0;           ///< active-set iterations (one row added or dropped, or a step)
};

/// Solves `qp` exactly (up to rounding) by the primal active-set method (Nocedal & Wright,
/// Numerical Optimization, 2nd ed., Algorithm 16.3) from `feasible_start`, a point with
/// A x <= b.
///
/// Why this method: the programs of the model are small and dense enough (n up to a few
/// hundred) that one exact method beats an iterative approximate one (ADMM, projected
/// gradient) in both accuracy and time: it ends on the optimal active set after finitely many
/// steps, each adding or dropping one row, and returns the multipliers as a certificate. A
/// primal method also keeps every iterate feasible and can be warm started: a previous
/// solution is a feasible start for a program with the same constraints.
///
/// The working set is kept as a QR factorisation of its rows in the coordinates y = L'x
/// (H = LL'), updated by Givens rotations as rows enter and leave, so a step costs O(n^2) and
/// the null-space step and the multipliers never form normal equations. Ties in the ratio
/// test go to the lowest row, so the result is deterministic.
///
/// Throws std::invalid_argument on mismatched sizes, non-finite data, an H that is not
/// positive definite, or a start that violates a row by more than 1e-9 (1 + |b_i|);
/// std::runtime_error if it has not finished after 20 (n + m) + 100 iterations (cycling on a
/// degenerate program).
QpSolution SolveQuadraticProgram(const QuadraticProgram& qp, const Eigen::VectorXd& feasible_start);

}  // namespace leglab
