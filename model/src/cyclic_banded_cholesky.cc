#include "leglab/model/cyclic_banded_cholesky.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace leglab {

void CyclicBandedCholesky::Reset(int size) {
  assert(size >= 1);
  // Each row keeps its storage (and its capacity) between matrices: only the diagonal is left.
  rows_.resize(size);
  first_.resize(size);
  for (int t = 0; t < size; ++t) {
    rows_[t].assign(1, 0.0);
    first_[t] = t;
  }
}

void CyclicBandedCholesky::Add(int row, int column, double value) {
  assert(row >= 0 && row < size() && column >= 0 && column < size());
  const int lower = std::max(row, column);
  const int left = std::min(row, column);
  std::vector<double>& entries = rows_[lower];
  if (left < first_[lower]) {
    entries.insert(entries.begin(), first_[lower] - left, 0.0);
    first_[lower] = left;
  }
  entries[left - first_[lower]] += value;
}

bool CyclicBandedCholesky::Factor() {
  for (int i = 0; i < size(); ++i) {
    double* row_i = rows_[i].data() - first_[i];  // row_i[k] is L(i, k) for k >= first_[i]
    for (int j = first_[i]; j < i; ++j) {
      const double* row_j = rows_[j].data() - first_[j];
      double sum = row_i[j];
      for (int k = std::max(first_[i], first_[j]); k < j; ++k) sum -= row_i[k] * row_j[k];
      row_i[j] = sum / row_j[j];
    }
    double sum = row_i[i];
    for (int k = first_[i]; k < i; ++k) sum -= row_i[k] * row_i[k];
    if (!(sum > 0.0)) return false;
    row_i[i] = std::sqrt(sum);
  }
  return true;
}

void CyclicBandedCholesky::Solve(Eigen::VectorXd& b) const {
  assert(b.size() == size());
  const int n = size();
  for (int i = 0; i < n; ++i) {
    const double* row_i = rows_[i].data() - first_[i];
    double sum = b[i];
    for (int k = first_[i]; k < i; ++k) sum -= row_i[k] * b[k];
    b[i] = sum / row_i[i];
  }
  for (int i = n - 1; i >= 0; --i) {
    const double* row_i = rows_[i].data() - first_[i];
    b[i] /= row_i[i];
    for (int k = first_[i]; k < i; ++k) b[k] -= row_i[k] * b[i];
  }
}

}  // namespace leglab
