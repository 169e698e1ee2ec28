#include "leglab/model/cyclic_banded_cholesky.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace leglab {

void CyclicBandedCholesky::Reset(int size) {
  assert(size >= 1);
  // Every write stays inside the envelope: zeroing the last matrix's envelope zeroes the lower
  // triangle (the whole matrix only when the size changes).
  if (m_.rows() != size) {
    m_.setZero(size, size);
  } else {
    for (int i = 0; i < size; ++i) {
      std::fill(&m_(i, first_[i]), &m_(i, i) + 1, 0.0);
    }
  }
  first_.resize(size);
  for (int t = 0; t < size; ++t) first_[t] = t;
}

void CyclicBandedCholesky::Add(int row, int column, double value) {
  assert(row >= 0 && row < size() && column >= 0 && column < size());
  const int lower = std::max(row, column);
  const int left = std::min(row, column);
  m_(lower, left) += value;
  first_[lower] = std::min(first_[lower], left);
}

bool CyclicBandedCholesky::Factor() {
  for (int i = 0; i < size(); ++i) {
    for (int j = first_[i]; j < i; ++j) {
      double sum = m_(i, j);
      for (int k = std::max(first_[i], first_[j]); k < j; ++k) sum -= m_(i, k) * m_(j, k);
      m_(i, j) = sum / m_(j, j);
    }
    double sum = m_(i, i);
    for (int k = first_[i]; k < i; ++k) sum -= m_(i, k) * m_(i, k);
    if (!(sum > 0.0)) return false;
    m_(i, i) = std::sqrt(sum);
  }
  return true;
}

void CyclicBandedCholesky::Solve(Eigen::VectorXd& b) const {
  assert(b.size() == size());
  const int n = size();
  for (int i = 0; i < n; ++i) {
    double sum = b[i];
    for (int k = first_[i]; k < i; ++k) sum -= m_(i, k) * b[k];
    b[i] = sum / m_(i, i);
  }
  for (int i = n - 1; i >= 0; --i) {
    b[i] /= m_(i, i);
    for (int k = first_[i]; k < i; ++k) b[k] -= m_(i, k) * b[i];
  }
}

}  // namespace leglab
