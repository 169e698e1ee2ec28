#include "leglab/model/piecewise_linear.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

std::vector<double> Sine(int period, double amplitude, double offset = 0.0) {
  std::vector<double> d(period);
  for (int t = 0; t < period; ++t) d[t] = offset + amplitude * std::sin(2.0 * M_PI * t / period);
  return d;
}

// A triangle wave with corners at t = 10 (value 40) and t = 50 (value 0), period 80: slopes
// +-1 deg/tick, within v_max = 2.5, so two segments reproduce it exactly.
std::vector<double> Triangle() {
  std::vector<double> d(80);
  for (int t = 0; t < 80; ++t) {
    if (t < 10)
      d[t] = 30.0 + t;
    else if (t < 50)
      d[t] = 40.0 - (t - 10);
    else
      d[t] = t - 50.0;
  }
  return d;
}

TEST(PiecewiseLinear, ReproducesAPiecewiseLinearTrajectoryExactly) {
  const std::vector<double> d = Triangle();
  const PiecewiseLinear at = FitPiecewiseLinearAt(d, 2.5, {10, 50});
  EXPECT_NEAR(at.values_deg[0], 40.0, 1e-9);
  EXPECT_NEAR(at.values_deg[1], 0.0, 1e-9);
  EXPECT_NEAR(at.Slope(0), -1.0, 1e-9);
  EXPECT_NEAR(at.Slope(1), 1.0, 1e-9);
  // The search finds the corners itself.
  const PiecewiseLinear found = FitPiecewiseLinear(d, 2.5, {.segments = 2});
  EXPECT_LT(PwlRmsError(found, d), 1e-9);
  EXPECT_EQ(found.breakpoints_tick, (std::vector<int>{10, 50}));
}

TEST(PiecewiseLinear, EvaluationWrapsRoundTheCycle) {
  const PiecewiseLinear p{10, {2, 6}, {0.0, 8.0}};  // up 2 deg/tick for 4 ticks, down 8/6
  EXPECT_EQ(p.SegmentAt(2), 0);
  EXPECT_EQ(p.SegmentAt(5), 0);
  EXPECT_EQ(p.SegmentAt(6), 1);
  EXPECT_EQ(p.SegmentAt(1), 1);   // before the first breakpoint: the wrapping segment
  EXPECT_EQ(p.SegmentAt(12), 0);  // 12 mod 10
  EXPECT_DOUBLE_EQ(p.At(4), 4.0);
  EXPECT_DOUBLE_EQ(p.At(9), 8.0 - 3.0 * 8.0 / 6.0);
  EXPECT_DOUBLE_EQ(p.At(1), 8.0 - 5.0 * 8.0 / 6.0);
  EXPECT_DOUBLE_EQ(p.At(-1), p.At(9));
  EXPECT_EQ(p.SegmentLength(1), 6);
}

TEST(PiecewiseLinear, UnconstrainedValuesAreOrdinaryLeastSquares) {
  // A slow trajectory: no slope bound is active, so the QP is plain least squares.
  const std::vector<double> d = Sine(60, 10.0, 3.0);  // max slope 1.05 deg/tick
  const std::vector<int> breakpoints{0, 9, 21, 33, 47};
  const PiecewiseLinear p = FitPiecewiseLinearAt(d, 2.5, breakpoints);
  // Independent least squares: hat functions built by hand, solved by QR.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(60, 5);
  for (int t = 0; t < 60; ++t) {
    int k = 0;
    while (k + 1 < 5 && breakpoints[k + 1] <= t) ++k;
    const int next = k + 1 < 5 ? breakpoints[k + 1] : 60;
    const double lambda = double(t - breakpoints[k]) / (next - breakpoints[k]);
    a(t, k) += 1 - lambda;
    a(t, (k + 1) % 5) += lambda;
  }
  const Eigen::VectorXd expected =
      a.colPivHouseholderQr().solve(Eigen::Map<const Eigen::VectorXd>(d.data(), 60));
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(p.values_deg[k], expected[k], 1e-9) << "k " << k;
}

TEST(PiecewiseLinear, ConstrainedValuesBeatEveryFeasiblePointOfAGrid) {
  // A fast sine (max slope 4.3 deg/tick) with two segments: brute force over a fine grid of
  // feasible (p0, p1) pairs can do no better than the QP.
  const std::vector<double> d = Sine(88, 60.0);
  const std::vector<int> breakpoints{22, 66};  // the sine's peak and trough
  const double v_max = 2.5;
  const PiecewiseLinear p = FitPiecewiseLinearAt(d, v_max, breakpoints);
  EXPECT_LE(std::abs(p.Slope(0)), v_max + 1e-9);
  EXPECT_NEAR(std::abs(p.Slope(0)), v_max, 1e-9);  // the bound binds
  const double qp_error = PwlRmsError(p, d);
  double grid_best = std::numeric_limits<double>::infinity();
  for (double p0 = 0.0; p0 <= 60.0; p0 += 0.05) {
    for (double p1 = -60.0; p1 <= 0.0; p1 += 0.05) {
      if (std::abs(p1 - p0) > v_max * 44) continue;
      const PiecewiseLinear candidate{88, breakpoints, {p0, p1}};
      grid_best = std::min(grid_best, PwlRmsError(candidate, d));
    }
  }
  EXPECT_LE(qp_error, grid_best + 1e-12);
  EXPECT_GT(qp_error, grid_best - 0.01);  // and the grid gets close to it
}

TEST(PiecewiseLinear, SlopesStayWithinVmaxAndBeatEvenSpacing) {
  const std::vector<double> d = Sine(88, 60.0, 20.0);  // exceeds v_max = 2.5 near the middle
  for (int segments : {3, 4, 6, 8, 10, 12}) {
    const PiecewiseLinear p = FitPiecewiseLinear(d, 2.5, {.segments = segments});
    ASSERT_EQ(p.num_segments(), segments);
    for (int k = 0; k < segments; ++k) {
      EXPECT_LE(std::abs(p.Slope(k)), 2.5 + 1e-9) << segments << " segments, k " << k;
    }
    std::vector<int> even(segments);
    for (int k = 0; k < segments; ++k) even[k] = k * 88 / segments;
    EXPECT_LE(PwlRmsError(p, d), PwlRmsError(FitPiecewiseLinearAt(d, 2.5, even), d) + 1e-12)
        << segments << " segments";
  }
}

TEST(PiecewiseLinear, ToleranceModeUsesTheFewestSegments) {
  const std::vector<double> d = Sine(88, 20.0);  // slow enough to follow closely
  const PiecewiseLinear p = FitPiecewiseLinear(d, 2.5, {.segments = 0, .tolerance_deg = 0.5});
  EXPECT_LE(PwlRmsError(p, d), 0.5);
  const PiecewiseLinear fewer = FitPiecewiseLinear(d, 2.5, {.segments = p.num_segments() - 1});
  EXPECT_GT(PwlRmsError(fewer, d), 0.5);
}

TEST(PiecewiseLinear, ToleranceBelowWhatVmaxAllowsIsAnError) {
  // A 60 deg sine at period 20 needs 18.8 deg/tick; with v_max 2.5 no fit gets near it.
  EXPECT_THROW(FitPiecewiseLinear(Sine(20, 60.0), 2.5, {.segments = 0, .tolerance_deg = 1.0}),
               std::invalid_argument);
}

TEST(PiecewiseLinear, RejectsBadInput) {
  const std::vector<double> d = Sine(20, 5.0);
  EXPECT_THROW(FitPiecewiseLinearAt(d, 2.5, {5, 5}), std::invalid_argument);
  EXPECT_THROW(FitPiecewiseLinearAt(d, 2.5, {7, 3}), std::invalid_argument);
  EXPECT_THROW(FitPiecewiseLinearAt(d, 2.5, {20}), std::invalid_argument);
  EXPECT_THROW(FitPiecewiseLinearAt(d, 0.0, {3}), std::invalid_argument);
  EXPECT_THROW(FitPiecewiseLinear(d, 2.5, {.segments = 21}), std::invalid_argument);
  std::vector<double> bad = d;
  bad[4] = NAN;
  EXPECT_THROW(FitPiecewiseLinear(bad, 2.5), std::invalid_argument);
}

// A cache shared by the fits of one D under several v_max gives each the bits of a fit without
// it (in either order, the second reusing the first's normal equations), and a fit of another
// D does not use it.
TEST(PiecewiseLinear, ASharedCacheGivesTheSameBits) {
  std::vector<double> d = Sine(88, 60.0, 10.0);
  for (int t = 0; t < 88; ++t) d[t] += 7.0 * std::sin(3.0 * t);
  PwlFitCache cache;
  for (const double v_max : {2.5, 1.7, 4.0}) {
    const PiecewiseLinear alone = FitPiecewiseLinear(d, v_max, {.segments = 8});
    const PiecewiseLinear cached = FitPiecewiseLinear(d, v_max, {.segments = 8}, &cache);
    EXPECT_EQ(cached.breakpoints_tick, alone.breakpoints_tick) << v_max;
    EXPECT_EQ(cached.values_deg, alone.values_deg) << v_max;
  }
  const std::vector<double> other = Sine(88, 40.0);
  EXPECT_EQ(cache.Get(other, {0, 44}), nullptr);
  const PiecewiseLinear cached = FitPiecewiseLinear(other, 2.5, {.segments = 6}, &cache);
  const PiecewiseLinear alone = FitPiecewiseLinear(other, 2.5, {.segments = 6});
  EXPECT_EQ(cached.values_deg, alone.values_deg);
  EXPECT_NE(cache.Get(d, {0, 44}), nullptr);
}

}  // namespace
}  // namespace leglab
