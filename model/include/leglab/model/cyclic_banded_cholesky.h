#pragma once

#include <Eigen/Core>
#include <vector>

namespace leglab {

/// Solves A x = b for a symmetric positive definite A (size x size) stored in its envelope: for
/// each row i, the entries from its first non-zero left of the diagonal up to the diagonal. The
/// Cholesky factor A = L L^T of such a matrix has no non-zero outside that envelope, so it is
/// factored in place there. Made for cyclic banded matrices (a band of half-width w plus the
/// corner entries that close the cycle), whose envelope is the band and the last w rows whole:
/// O(size w^2) work and O(size w) storage instead of a dense factorisation's O(size^3) and
/// O(size^2), and no pivoting (none is needed for a positive definite A).
///
/// Use: Reset, Add every entry, Factor, then Solve any number of right-hand sides. The object
/// keeps its storage between uses (Reset only clears the envelope of the last matrix).
class CyclicBandedCholesky {
 public:
  /// Starts a new matrix A = 0 of size x size (size >= 1).
  void Reset(int size);

  /// A(row, column) and A(column, row) += value (once, on the diagonal when row == column),
  /// both in [0, size). Widens the envelope of max(row, column) to min(row, column), at a cost
  /// of the row's length when it widens (so add a row's leftmost entries first where it matters).
  void Add(int row, int column, double value);

  /// Factors A = L L^T in place (Cholesky-Banachiewicz, row by row). False when A is not
  /// numerically positive definite (a pivot not > 0); the factor is then unusable until Reset.
  bool Factor();

  /// Overwrites b (size `size`) with A^-1 b, by forward and back substitution with L. Only
  /// after Factor returned true.
  void Solve(Eigen::VectorXd& b) const;

  int size() const { return static_cast<int>(first_.size()); }

 private:
  // Row i's envelope, the lower triangle from column first_[i] to the diagonal, contiguous.
  std::vector<std::vector<double>> rows_;
  // The first column of each row's envelope.
  std::vector<int> first_;
};

}  // namespace leglab
