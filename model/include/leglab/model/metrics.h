#pragma once

#include <span>

namespace leglab {

/// The paper's L2 distance between two trajectories of one step: the root mean square of the
/// sample differences (its L2 values sit below its L-infinity ones, so they are RMS, not sums).
/// Throws std::invalid_argument if the sizes differ or are zero.
double RmsDistance(std::span<const double> a, std::span<const double> b);

/// The paper's L-infinity distance: the largest absolute sample difference.
/// Throws std::invalid_argument if the sizes differ or are zero.
double MaxAbsDistance(std::span<const double> a, std::span<const double> b);

/// Root mean square of `values` (e.g. Euclidean foot errors); throws on an empty span.
double Rms(std::span<const double> values);

/// Largest absolute value of `values`; throws on an empty span.
double MaxAbs(std::span<const double> values);

/// Mean and sample standard deviation (n - 1 in the denominator; 0 for a single value).
struct MeanStd {
  double mean = 0.0;
  double std = 0.0;
};

/// Mean and sample standard deviation of `values` over steps; throws on an empty span.
MeanStd MeanAndStd(std::span<const double> values);

}  // namespace leglab
