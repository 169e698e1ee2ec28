#include "leglab/model/metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace leglab {
namespace {

void CheckSizes(std::span<const double> a, std::span<const double> b) {
  if (a.empty() || a.size() != b.size()) {
    throw std::invalid_argument("metrics: trajectories must have the same, non-zero length (got " +
                                std::to_string(a.size()) + " and " + std::to_string(b.size()) +
                                ")");
  }
}

void CheckNotEmpty(std::span<const double> values) {
  if (values.empty()) throw std::invalid_argument("metrics: no values");
}

}  // namespace

double RmsDistance(std::span<const double> a, std::span<const double> b) {
  CheckSizes(a, b);
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum / static_cast<double>(a.size()));
}

double MaxAbsDistance(std::span<const double> a, std::span<const double> b) {
  CheckSizes(a, b);
  double largest = 0.0;
  for (size_t i = 0; i < a.size(); ++i) largest = std::max(largest, std::abs(a[i] - b[i]));
  return largest;
}

double Rms(std::span<const double> values) {
  CheckNotEmpty(values);
  double sum = 0.0;
  for (double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

double MaxAbs(std::span<const double> values) {
  CheckNotEmpty(values);
  double largest = 0.0;
  for (double v : values) largest = std::max(largest, std::abs(v));
  return largest;
}

MeanStd MeanAndStd(std::span<const double> values) {
  CheckNotEmpty(values);
  const auto n = static_cast<double>(values.size());
  double mean = 0.0;
  for (double v : values) mean += v;
  mean /= n;
  if (values.size() == 1) return {mean, 0.0};
  double squares = 0.0;
  for (double v : values) squares += (v - mean) * (v - mean);
  return {mean, std::sqrt(squares / (n - 1.0))};
}

}  // namespace leglab
