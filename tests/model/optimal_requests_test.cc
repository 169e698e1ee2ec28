#include "leglab/model/optimal_requests.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "leglab/model/metrics.h"
#include "leglab/model/paper.h"
#include "leglab/model/piecewise_linear.h"
#include "leglab/model/request_synthesis.h"

namespace leglab {
namespace {

constexpr JointModelParams kPaper = paper::kTable1;

// The steady state everything here is scored against: CyclicSteadyState, converged tightly.
std::vector<double> SteadyState(const JointModelParams& p, std::span<const double> requests) {
  return CyclicSteadyState(p, requests, 1e-13);
}

double RmsError(const JointModelParams& p, std::span<const double> requests,
                std::span<const double> desired) {
  return RmsDistance(SteadyState(p, requests), desired);
}

// sqrt(sum_t w_t (M_ss(t) - D(t))^2 / T): the weighted objective, written out.
double WeightedRmsError(const JointModelParams& p, std::span<const double> requests,
                        std::span<const double> desired, std::span<const double> weights) {
  const std::vector<double> m = SteadyState(p, requests);
  double sum = 0.0;
  for (std::size_t t = 0; t < m.size(); ++t)
    sum += weights[t] * (m[t] - desired[t]) * (m[t] - desired[t]);
  return std::sqrt(sum / static_cast<double>(m.size()));
}

// The walking-like cycle of the brief: D(t) = amplitude sin(2 pi t / 88) + 15 sin(4 pi t / 88 + 1).
std::vector<double> WalkingCycle(double amplitude_deg) {
  std::vector<double> d(88);
  for (int t = 0; t < 88; ++t) {
    const double phase = 2.0 * std::numbers::pi * t / 88.0;
    d[t] = amplitude_deg * std::sin(phase) + 15.0 * std::sin(2.0 * phase + 1.0);
  }
  return d;
}

// The paper's method (sections 4.1-4.3): 8-segment PWL fit, exact C_m.
std::vector<double> ModelBasedRequests(const JointModelParams& p, std::span<const double> d) {
  const PiecewiseLinear pwl = FitPiecewiseLinear(d, p.v_max_deg_per_tick, {.segments = 8});
  return SynthesizeRequests(p, pwl, CmMethod::kExact);
}

// x_ti = R(t-i) - M(t-1) for every term of eq. 3 in the steady state: how far each is from f's
// kinks at +-theta_0 (the smallest such distance), and whether any lies inside (-theta_0,
// theta_0) by more than 1e-4 deg.
struct TermsSummary {
  double kink_distance = std::numeric_limits<double>::infinity();
  bool any_live = false;
};
TermsSummary SummariseTerms(const JointModelParams& p, std::span<const double> requests) {
  const std::vector<double> m = SteadyState(p, requests);
  const int n = static_cast<int>(requests.size());
  TermsSummary summary;
  for (int t = 0; t < n; ++t) {
    for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
      const double x = requests[((t - i) % n + n) % n] - m[(t - 1 + n) % n];
      summary.kink_distance = std::min(summary.kink_distance, std::abs(std::abs(x) - p.theta0_deg));
      if (std::abs(x) < p.theta0_deg - 1e-4) summary.any_live = true;
    }
  }
  return summary;
}

// --- Sensitivity -------------------------------------------------------------------------

// Central differences of CyclicSteadyState. Inside one pattern of f's branches the steady state
// is affine in R (f is piecewise linear), so away from the kinks the difference quotient is
// exact up to rounding; the step is kept well inside the distance to the nearest kink.
Eigen::MatrixXd FiniteDifferenceSensitivity(const JointModelParams& p,
                                            std::span<const double> requests, double h) {
  const int n = static_cast<int>(requests.size());
  Eigen::MatrixXd s(n, n);
  std::vector<double> plus(requests.begin(), requests.end());
  std::vector<double> minus = plus;
  for (int col = 0; col < n; ++col) {
    plus[col] += h;
    minus[col] -= h;
    const std::vector<double> up = SteadyState(p, plus);
    const std::vector<double> down = SteadyState(p, minus);
    for (int row = 0; row < n; ++row) s(row, col) = (up[row] - down[row]) / (2.0 * h);
    plus[col] = minus[col] = requests[col];
  }
  return s;
}

struct SensitivityCase {
  JointModelParams params;
  std::vector<double> requests;
};

std::vector<SensitivityCase> SensitivityCases() {
  std::vector<SensitivityCase> cases;
  // A slow cycle the model follows in f's linear range throughout.
  {
    std::vector<double> r(40);
    for (int t = 0; t < 40; ++t) r[t] = 10.0 * std::sin(2.0 * std::numbers::pi * t / 40.0);
    cases.push_back({kPaper, r});
  }
  // A square wave: most terms saturated (f' = 0), some in the linear range.
  {
    std::vector<double> r(30);
    for (int t = 0; t < 30; ++t) r[t] = t < 12 ? 22.0 + 0.4 * t : -18.0 + 0.15 * t;
    cases.push_back({kPaper, r});
    cases.push_back({{2.5, 7.0, 0, 1}, r});
    cases.push_back({{1.5, 4.0, 2, 3}, r});
  }
  // The paper's model-based requests for the walking cycle, T = 88.
  cases.push_back({kPaper, ModelBasedRequests(kPaper, WalkingCycle(40.0))});
  // A short, irregular cycle.
  cases.push_back({{2.0, 5.0, 1, 2}, {0.0, 9.0, 4.0, -3.0, 12.0, 1.5, -8.0}});
  return cases;
}

TEST(SteadyStateSensitivity, MatchesCentralDifferencesAwayFromTheKinks) {
  for (const SensitivityCase& c : SensitivityCases()) {
    const TermsSummary terms = SummariseTerms(c.params, c.requests);
    const double h = 1e-5;
    ASSERT_GT(terms.kink_distance, 20.0 * h) << "T = " << c.requests.size();
    const Eigen::MatrixXd analytic = SteadyStateSensitivity(c.params, c.requests);
    const Eigen::MatrixXd numeric = FiniteDifferenceSensitivity(c.params, c.requests, h);
    ASSERT_EQ(analytic.rows(), static_cast<long>(c.requests.size()));
    ASSERT_EQ(analytic.cols(), static_cast<long>(c.requests.size()));
    EXPECT_LT((analytic - numeric).cwiseAbs().maxCoeff(), 1e-5) << "T = " << c.requests.size();
    // Not trivially zero: the cycles do respond to their requests.
    EXPECT_GT(numeric.cwiseAbs().maxCoeff(), 0.05);
  }
}

TEST(SteadyStateSensitivity, RowsSumToOneAndCausalityHolds) {
  // Eq. 3 depends only on R - M, so R + c gives M + c: every row of d M / d R sums to 1.
  // And a request R(s) acts first at t = s + l + 1: in a cycle that forgets quickly, M(t) is
  // (almost) blind to the l requests just before it.
  const std::vector<double> r = SensitivityCases()[0].requests;
  const Eigen::MatrixXd s = SteadyStateSensitivity(kPaper, r);
  for (int t = 0; t < s.rows(); ++t) EXPECT_NEAR(s.row(t).sum(), 1.0, 1e-12) << "t = " << t;
  const int n = static_cast<int>(r.size());
  for (int t = 0; t < n; ++t) {
    for (int back = 0; back < kPaper.lag_ticks; ++back) {
      EXPECT_LT(std::abs(s(t, ((t - back) % n + n) % n)), 1e-6) << t << " " << back;
    }
  }
}

TEST(SteadyStateNormalMatrix, IsTheProductOfTheSensitivityWithItself) {
  // The O(T^2 a) recursion against S^T S multiplied out, on the sensitivity cases and on the
  // corners of the recursion: a cycle shorter than l + a (a request enters a tick's sum more
  // than once), a cycle saturated throughout (the 1/T rows), and v_max > theta_0 (negative
  // alpha).
  std::vector<SensitivityCase> cases = SensitivityCases();
  cases.push_back({kPaper, {3.0, -4.0, 8.0, 1.0}});
  cases.push_back({kPaper, {60.0, 60.0, -60.0, -60.0, 60.0, -60.0}});
  cases.push_back({{9.0, 5.0, 1, 2}, {0.0, 3.0, 4.0, 2.0, -1.0, -2.5, -1.0, 0.5}});
  for (const SensitivityCase& c : cases) {
    const Eigen::MatrixXd s = SteadyStateSensitivity(c.params, c.requests);
    const Eigen::MatrixXd product = s.transpose() * s;
    const Eigen::MatrixXd normal = SteadyStateNormalMatrix(c.params, c.requests);
    ASSERT_EQ(normal.rows(), product.rows());
    ASSERT_EQ(normal.cols(), product.cols());
    EXPECT_LT((normal - product).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + product.norm()))
        << "T = " << c.requests.size();
  }
}

TEST(SteadyStateNormalMatrix, WeightedIsTheProductWithTheWeightsBetween) {
  // S^T W S multiplied out, with weights that differ by tick, a zero among them.
  std::vector<SensitivityCase> cases = SensitivityCases();
  cases.push_back({kPaper, {3.0, -4.0, 8.0, 1.0}});
  cases.push_back({{9.0, 5.0, 1, 2}, {0.0, 3.0, 4.0, 2.0, -1.0, -2.5, -1.0, 0.5}});
  for (const SensitivityCase& c : cases) {
    const auto n = static_cast<int>(c.requests.size());
    std::vector<double> w(n);
    for (int t = 0; t < n; ++t) w[t] = t % 5 == 3 ? 0.0 : 0.3 + 0.17 * (t % 7);
    const Eigen::MatrixXd s = SteadyStateSensitivity(c.params, c.requests);
    const Eigen::VectorXd wv = Eigen::Map<const Eigen::VectorXd>(w.data(), n);
    const Eigen::MatrixXd product = s.transpose() * wv.asDiagonal() * s;
    const Eigen::MatrixXd normal = SteadyStateNormalMatrix(c.params, c.requests, w);
    EXPECT_LT((normal - product).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + product.norm()))
        << "T = " << c.requests.size();
  }
  const std::vector<double> two_weights = {1.0, 2.0};  // not one per tick
  EXPECT_THROW(SteadyStateNormalMatrix(kPaper, SensitivityCases()[0].requests, two_weights),
               std::invalid_argument);
  std::vector<double> negative(SensitivityCases()[0].requests.size(), 1.0);
  negative[2] = -0.5;
  EXPECT_THROW(SteadyStateNormalMatrix(kPaper, SensitivityCases()[0].requests, negative),
               std::invalid_argument);
}

// --- The structured step -------------------------------------------------------------------

// The damped Gauss-Newton step written out densely: x = -(S_F^T W S_F + c I + s L_F^T L_F)^-1
// (S_F^T W e + s L_F^T L R), S_F and L_F the columns `free` of SteadyStateSensitivity and of
// the cyclic second difference L, e = M_ss - D, s the move suppression.
Eigen::VectorXd DenseDampedStep(const JointModelParams& p, std::span<const double> requests,
                                std::span<const double> desired, std::span<const double> weights,
                                std::span<const int> free, double damping,
                                double suppression = 0.0) {
  const auto n = static_cast<Eigen::Index>(requests.size());
  const auto m = static_cast<Eigen::Index>(free.size());
  const Eigen::MatrixXd s = SteadyStateSensitivity(p, requests);
  Eigen::MatrixXd s_free(n, m);
  for (Eigen::Index k = 0; k < m; ++k) s_free.col(k) = s.col(free[k]);
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n);
  if (!weights.empty()) w = Eigen::Map<const Eigen::VectorXd>(weights.data(), n);
  const std::vector<double> m_ss = SteadyState(p, requests);
  Eigen::VectorXd e(n);
  for (Eigen::Index t = 0; t < n; ++t) e[t] = m_ss[t] - desired[t];
  Eigen::MatrixXd h = s_free.transpose() * w.asDiagonal() * s_free;
  h.diagonal().array() += damping;
  Eigen::VectorXd g = s_free.transpose() * w.asDiagonal() * e;
  // The move suppression: suppression |L (R + P_F x)|^2, L the cyclic second difference.
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index t = 0; t < n; ++t) {
    second(t, (t + 1) % n) += 1.0;
    second(t, t) -= 2.0;
    second(t, (t + n - 1) % n) += 1.0;
  }
  Eigen::MatrixXd second_free(n, m);
  for (Eigen::Index k = 0; k < m; ++k) second_free.col(k) = second.col(free[k]);
  h += suppression * second_free.transpose() * second_free;
  g += suppression * second_free.transpose() *
       (second * Eigen::Map<const Eigen::VectorXd>(requests.data(), n));
  return -h.fullPivLu().solve(g);
}

// Structured against dense on one case: every request free, then every third held; damping
// from 1e-6 to 10 times the normal matrix's largest diagonal entry; equal weights and unequal;
// no move suppression, request_smoothing's 0.3 and 10 (the cycle at least 3 ticks long).
void ExpectStructuredStepIsDense(const JointModelParams& p, const std::vector<double>& requests,
                                 const std::vector<double>& desired) {
  const auto n = static_cast<int>(requests.size());
  std::vector<double> unequal(n);
  for (int t = 0; t < n; ++t) unequal[t] = 0.2 + 0.37 * (t % 5) + 0.05 * (t % 3);
  const Eigen::MatrixXd s = SteadyStateSensitivity(p, requests);
  const double scale = std::max((s.transpose() * s).diagonal().maxCoeff(), 1e-12);
  for (const std::vector<double>& weights : {std::vector<double>{}, unequal}) {
    for (int held_every : {0, 3}) {
      std::vector<int> free;
      for (int j = 0; j < n; ++j) {
        if (held_every == 0 || j % held_every != 1) free.push_back(j);
      }
      for (double suppression : {0.0, 0.3, 10.0}) {
        if (suppression > 0.0 && n < 3) continue;
        for (double damping : {1e-6, 1e-3, 1.0, 10.0}) {
          const Eigen::VectorXd dense =
              DenseDampedStep(p, requests, desired, weights, free, damping * scale, suppression);
          const Eigen::VectorXd banded = StructuredDampedStep(p, requests, desired, weights, free,
                                                              damping * scale, suppression);
          ASSERT_EQ(banded.size(), dense.size())
              << "T " << n << " l " << p.lag_ticks << " a " << p.accel_ticks;
          // The dense solve's own rounding grows with the condition number, up to 1 / damping.
          EXPECT_LT((banded - dense).norm(), 1e-11 / damping * (1.0 + dense.norm()))
              << "T " << n << " l " << p.lag_ticks << " a " << p.accel_ticks << " damping "
              << damping << " weights " << (weights.empty() ? "equal" : "unequal") << " held every "
              << held_every << " suppression " << suppression;
        }
      }
    }
  }
}

TEST(StructuredDampedStep, IsTheDenseStepOnTheSensitivityCases) {
  // The sensitivity's cases (slow, square wave with most terms saturated, the walking cycle,
  // a short irregular cycle), a cycle shorter than l + a, and v_max > theta_0 (negative alpha).
  std::vector<SensitivityCase> cases = SensitivityCases();
  cases.push_back({kPaper, {3.0, -4.0, 8.0, 1.0}});
  cases.push_back({{9.0, 5.0, 1, 2}, {0.0, 3.0, 4.0, 2.0, -1.0, -2.5, -1.0, 0.5}});
  for (const SensitivityCase& c : cases) {
    const auto n = static_cast<int>(c.requests.size());
    std::vector<double> desired(n);
    for (int t = 0; t < n; ++t) desired[t] = c.requests[(t + 2) % n] + 0.5 * std::cos(t);
    ExpectStructuredStepIsDense(c.params, c.requests, desired);
  }
}

TEST(StructuredDampedStep, IsTheDenseStepOnRandomCycles) {
  // 40 random models and cycles: T 5-90, l 0-5, a 1-8, v_max up to 1.2 theta_0, requests up
  // to 4 theta_0 apart (some terms saturated, some not).
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 5 + static_cast<int>(unit(rng) * 86.0);
    JointModelParams p;
    p.theta0_deg = 2.0 + 8.0 * unit(rng);
    p.v_max_deg_per_tick = p.theta0_deg * (0.1 + 1.1 * unit(rng));
    p.lag_ticks = static_cast<int>(unit(rng) * 6.0);
    p.accel_ticks = 1 + static_cast<int>(unit(rng) * 8.0);
    std::vector<double> requests(n), desired(n);
    for (int t = 0; t < n; ++t) {
      requests[t] = 2.0 * p.theta0_deg * (2.0 * unit(rng) - 1.0) +
                    20.0 * std::sin(2.0 * std::numbers::pi * t / n);
      desired[t] = requests[t] + 3.0 * (2.0 * unit(rng) - 1.0);
    }
    ExpectStructuredStepIsDense(p, requests, desired);
  }
}

TEST(StructuredDampedStep, DoesNotApplyToAZeroWeightOrACycleSaturatedThroughout) {
  const SensitivityCase c = SensitivityCases()[0];
  const std::vector<int> all = [&] {
    std::vector<int> v(c.requests.size());
    std::iota(v.begin(), v.end(), 0);
    return v;
  }();
  std::vector<double> weights(c.requests.size(), 1.0);
  weights[3] = 0.0;
  EXPECT_EQ(StructuredDampedStep(kPaper, c.requests, c.requests, weights, all, 1.0).size(), 0);
  // Bang-bang requests: every term saturated, alpha = 1 all round (B singular).
  const std::vector<double> bang = {60.0, 60.0, -60.0, -60.0, 60.0, -60.0};
  const std::vector<int> six = {0, 1, 2, 3, 4, 5};
  EXPECT_EQ(StructuredDampedStep(kPaper, bang, bang, {}, six, 1.0).size(), 0);
  const std::vector<int> outside = {0, 40};
  EXPECT_THROW(StructuredDampedStep(kPaper, c.requests, c.requests, {}, all, 1.0, -0.1),
               std::invalid_argument);
  EXPECT_THROW(StructuredDampedStep(kPaper, c.requests, c.requests, {}, outside, 1.0),
               std::invalid_argument);
  // Non-finite weights and a damping that is not positive are refused, not an empty step.
  weights[3] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(StructuredDampedStep(kPaper, c.requests, c.requests, weights, all, 1.0),
               std::invalid_argument);
  weights[3] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(StructuredDampedStep(kPaper, c.requests, c.requests, weights, all, 1.0),
               std::invalid_argument);
  for (const double damping : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    EXPECT_THROW(StructuredDampedStep(kPaper, c.requests, c.requests, {}, all, damping),
                 std::invalid_argument)
        << damping;
  }
}

// --- Brute force on small cycles -----------------------------------------------------------

// The least `score` over an exhaustive grid of `points`^n request cycles on the box [lo, hi]^n,
// each of the 40 best grid points refined by compass search (halving the step from the grid's
// spacing down to 1e-8 deg). Writes the best cycle into `best_requests` when given.
template <typename Score>
double GridThenCompassSearch(const Score& score, int n, double lo, double hi, int points,
                             std::vector<double>* best_requests = nullptr) {
  const double spacing = (hi - lo) / (points - 1);
  std::vector<std::pair<double, std::vector<double>>> grid;
  std::vector<int> index(n, 0);
  std::vector<double> r(n);
  while (true) {
    for (int s = 0; s < n; ++s) r[s] = lo + spacing * index[s];
    grid.emplace_back(score(r), r);
    int k = 0;
    while (k < n && ++index[k] == points) index[k++] = 0;
    if (k == n) break;
  }
  const std::size_t starts = 40;
  std::partial_sort(grid.begin(), grid.begin() + starts, grid.end());

  double best = std::numeric_limits<double>::infinity();
  for (std::size_t g = 0; g < starts; ++g) {
    std::vector<double> x = grid[g].second;
    double fx = grid[g].first;
    for (double step = spacing; step > 1e-8;) {
      bool moved = false;
      for (int s = 0; s < n; ++s) {
        for (double sign : {-1.0, 1.0}) {
          std::vector<double> y = x;
          y[s] += sign * step;
          const double fy = score(y);
          if (fy < fx) {
            fx = fy;
            x = std::move(y);
            moved = true;
          }
        }
      }
      if (!moved) step /= 2.0;
    }
    if (fx < best) {
      best = fx;
      if (best_requests != nullptr) *best_requests = x;
    }
  }
  return best;
}

// The best RMS error over a grid of 21^4 or 11^5 request cycles round D, refined
// (GridThenCompassSearch).
double BruteForceBest(const JointModelParams& p, std::span<const double> d,
                      std::vector<double>* best_requests, std::span<const double> weights = {}) {
  const int n = static_cast<int>(d.size());
  const auto [dmin, dmax] = std::minmax_element(d.begin(), d.end());
  // Past theta_0 + (l + a) v_max beyond D a request is saturated for any nearby angle.
  const double reach = p.theta0_deg + p.v_max_deg_per_tick * (p.lag_ticks + p.accel_ticks) + 2.0;
  const double lo = *dmin - reach;
  const double hi = *dmax + reach;
  const int points = n == 4 ? 21 : 11;
  auto score = [&](const std::vector<double>& r) {
    try {
      return weights.empty() ? RmsError(p, r, d) : WeightedRmsError(p, r, d, weights);
    } catch (const std::runtime_error&) {  // no settled steady state: not a candidate
      return std::numeric_limits<double>::infinity();
    }
  };
  return GridThenCompassSearch(score, n, lo, hi, points, best_requests);
}

struct SmallCase {
  JointModelParams params;
  std::vector<double> desired;
  bool saturated_optimum;  // every term of eq. 3 saturated at the optimum
};

TEST(OptimizeRequests, ReachesTheBruteForceOptimumOnSmallCycles) {
  // T = 4 or 5, l = 0 or 1, a = 1 or 2, D a small step or spike, too fast to follow exactly.
  // In the two a = 2 steps the best answer saturates every term of eq. 3 all round the cycle
  // (bang-bang requests): the model then has a whole interval of steady states, of which
  // CyclicSteadyState picks the one through the mean request, and the error jumps where a
  // term leaves saturation; the optimum is reached there too.
  const std::vector<SmallCase> cases = {
      {{2.5, 7.0, 0, 1}, {0, 0, 6, 6}, false},    {{2.5, 7.0, 1, 1}, {0, 0, 6, 6}, false},
      {{2.5, 7.0, 0, 2}, {0, 0, 6, 6}, true},     {{2.5, 7.0, 1, 2}, {0, 0, 6, 6}, true},
      {{2.5, 7.0, 0, 1}, {0, 0, 8, 0, 0}, false}, {{2.5, 7.0, 0, 2}, {0, 0, 8, 0, 0}, false},
      {{2.5, 7.0, 1, 2}, {0, 0, 8, 0, 0}, false}, {{1.0, 2.0, 1, 2}, {0, 0, 3, 3, 0}, false},
      {{1.0, 2.0, 0, 1}, {0, 4, 4, 0}, false},    {{1.0, 2.0, 1, 1}, {0, 0, 3, 0, 0}, false},
  };
  for (const SmallCase& c : cases) {
    std::vector<double> grid_requests;
    const double grid_best = BruteForceBest(c.params, c.desired, &grid_requests);
    EXPECT_EQ(SummariseTerms(c.params, grid_requests).any_live, !c.saturated_optimum);
    const OptimalRequests opt = OptimizeRequests(c.desired, c.params, c.desired);
    EXPECT_LT(opt.rms_error_deg, grid_best + 2e-6)
        << "T " << c.desired.size() << " l " << c.params.lag_ticks << " a " << c.params.accel_ticks
        << ": grid " << grid_best;
    EXPECT_NEAR(opt.rms_error_deg, RmsError(c.params, opt.requests_deg, c.desired), 1e-9);
    // The structured (banded) solve of each step reaches it too.
    OptimalRequestsOptions structured;
    structured.structured_solve = true;
    const OptimalRequests banded = OptimizeRequests(c.desired, c.params, c.desired, structured);
    EXPECT_LT(banded.rms_error_deg, grid_best + 2e-6)
        << "structured, T " << c.desired.size() << " l " << c.params.lag_ticks << " a "
        << c.params.accel_ticks << ": grid " << grid_best;
    EXPECT_NEAR(banded.rms_error_deg, RmsError(c.params, banded.requests_deg, c.desired), 1e-9);
  }
}

// --- Contract ------------------------------------------------------------------------------

TEST(OptimizeRequests, ReachesTheWeightedBruteForceOptimum) {
  // The same kind of small cycles with unequal weights, one of them zero (that tick's error
  // does not count): the optimum moves, and the weighted brute force finds where.
  struct WeightedCase {
    JointModelParams params;
    std::vector<double> desired;
    std::vector<double> weights;
  };
  const std::vector<WeightedCase> cases = {
      {{2.5, 7.0, 0, 1}, {0, 0, 6, 6}, {1.0, 0.2, 3.0, 1.0}},
      {{2.5, 7.0, 1, 1}, {0, 0, 6, 6}, {0.0, 1.0, 1.0, 4.0}},
      {{2.5, 7.0, 0, 1}, {0, 0, 8, 0, 0}, {1.0, 1.0, 5.0, 0.5, 1.0}},
      {{1.0, 2.0, 1, 2}, {0, 0, 3, 3, 0}, {2.0, 0.0, 1.0, 1.0, 0.3}},
      {{1.0, 2.0, 0, 1}, {0, 4, 4, 0}, {0.1, 1.0, 2.0, 1.0}},
  };
  for (const WeightedCase& c : cases) {
    std::vector<double> grid_requests;
    const double grid_best = BruteForceBest(c.params, c.desired, &grid_requests, c.weights);
    OptimalRequestsOptions options;
    options.weights = c.weights;
    const OptimalRequests opt = OptimizeRequests(c.desired, c.params, c.desired, options);
    EXPECT_LT(opt.rms_error_deg, grid_best + 2e-6)
        << "T " << c.desired.size() << " l " << c.params.lag_ticks << " a " << c.params.accel_ticks
        << ": grid " << grid_best;
    EXPECT_NEAR(opt.rms_error_deg,
                WeightedRmsError(c.params, opt.requests_deg, c.desired, c.weights), 1e-9);
    // The structured solve (dense where a weight is 0) reaches it too.
    options.structured_solve = true;
    const OptimalRequests banded = OptimizeRequests(c.desired, c.params, c.desired, options);
    EXPECT_LT(banded.rms_error_deg, grid_best + 2e-6)
        << "structured, T " << c.desired.size() << " l " << c.params.lag_ticks << " a "
        << c.params.accel_ticks << ": grid " << grid_best;
  }
}

// --- Move suppression (request_smoothing) ---------------------------------------------------

// sum_t (R(t+1) - 2 R(t) + R(t-1))^2 round the cycle, written out.
double SquaredSecondDifferences(const std::vector<double>& r) {
  const int n = static_cast<int>(r.size());
  double sum = 0.0;
  for (int t = 0; t < n; ++t) {
    const double d = r[(t + 1) % n] - 2.0 * r[t] + r[(t + n - 1) % n];
    sum += d * d;
  }
  return sum;
}

// The penalised objective: sum_t (M_ss(t) - D(t))^2 + lambda sum_t (second difference)^2.
double PenalisedCost(const JointModelParams& p, const std::vector<double>& r,
                     std::span<const double> d, double lambda) {
  const std::vector<double> m = SteadyState(p, r);
  double sum = 0.0;
  for (std::size_t t = 0; t < d.size(); ++t) sum += (m[t] - d[t]) * (m[t] - d[t]);
  return sum + lambda * SquaredSecondDifferences(r);
}

TEST(OptimizeRequests, ReachesThePenalisedBruteForceOptimum) {
  // Small cycles, the objective with the move suppression written out (no weights): a grid of
  // 21^4 points, the 40 best refined by compass search, against the optimiser from R = D.
  const std::vector<SmallCase> cases = {
      {{2.5, 7.0, 0, 1}, {0, 0, 6, 6}, false},
      {{2.5, 7.0, 1, 1}, {0, 0, 6, 6}, false},
      {{1.0, 2.0, 0, 1}, {0, 4, 4, 0}, false},
  };
  for (const SmallCase& c : cases) {
    for (double lambda : {0.05, 0.5, 5.0}) {
      const JointModelParams& p = c.params;
      const std::vector<double>& d = c.desired;
      const int n = static_cast<int>(d.size());
      const double reach = p.theta0_deg + p.v_max_deg_per_tick * (p.lag_ticks + p.accel_ticks);
      const double lo = *std::min_element(d.begin(), d.end()) - reach;
      const double hi = *std::max_element(d.begin(), d.end()) + reach;
      const double best = GridThenCompassSearch(
          [&](const std::vector<double>& r) { return PenalisedCost(p, r, d, lambda); }, n, lo, hi,
          21);
      OptimalRequestsOptions options;
      options.request_smoothing = lambda;
      const OptimalRequests opt = OptimizeRequests(d, p, d, options);
      // As RMS over the cycle. Within 1e-4 deg, not the 2e-6 of the plain objective: with the
      // penalty an optimum can sit on a ridge along a kink of eq. 3 (a term held at +-theta_0,
      // each side's step crossing to the other), which the piecewise pivots approach but do not
      // follow (the {1, 2, 0, 1} case at lambda 0.05 ends 4e-5 deg above the brute force).
      auto rms = [n](double cost) { return std::sqrt(cost / n); };
      EXPECT_LT(rms(PenalisedCost(p, opt.requests_deg, d, lambda)), rms(best) + 1e-4)
          << "l " << p.lag_ticks << " a " << p.accel_ticks << " lambda " << lambda;
      // rms_error_deg stays the tracking error alone.
      EXPECT_NEAR(opt.rms_error_deg, RmsError(p, opt.requests_deg, d), 1e-9);
      // The structured solve (the same steps up to rounding) reaches it too.
      options.structured_solve = true;
      const OptimalRequests banded = OptimizeRequests(d, p, d, options);
      EXPECT_LT(rms(PenalisedCost(p, banded.requests_deg, d, lambda)), rms(best) + 1e-4)
          << "structured, l " << p.lag_ticks << " a " << p.accel_ticks << " lambda " << lambda;
    }
  }
}

TEST(OptimizeRequests, MoveSuppressionZeroIsTheObjectiveWithout) {
  const std::vector<double> d = WalkingCycle(20.0);
  const std::vector<double> start = ModelBasedRequests(kPaper, d);
  for (bool structured : {false, true}) {
    OptimalRequestsOptions plain;
    plain.structured_solve = structured;
    OptimalRequestsOptions zero = plain;
    zero.request_smoothing = 0.0;
    const OptimalRequests a = OptimizeRequests(d, kPaper, start, plain);
    const OptimalRequests b = OptimizeRequests(d, kPaper, start, zero);
    EXPECT_EQ(a.requests_deg, b.requests_deg);
    EXPECT_EQ(a.rms_error_deg, b.rms_error_deg);
  }
}

TEST(OptimizeRequests, LargeMoveSuppressionGivesANearlySmoothCycle) {
  // The optimiser never ends above its start, so lambda |L R*|^2 <= J(R*) <= J(start):
  // the squared second differences are at most J(start) / lambda, whatever the weights
  // (weights scale lambda by their mean).
  const std::vector<double> d = WalkingCycle(20.0);
  const std::vector<double> start = ModelBasedRequests(kPaper, d);
  std::vector<double> weights(d.size());
  for (std::size_t t = 0; t < d.size(); ++t)
    weights[t] =
        0.5 + 0.5 * std::sin(0.3 * static_cast<double>(t)) * std::sin(0.3 * static_cast<double>(t));
  const double mean_weight =
      std::accumulate(weights.begin(), weights.end(), 0.0) / static_cast<double>(weights.size());
  const double plain_roughness =
      SquaredSecondDifferences(OptimizeRequests(d, kPaper, start).requests_deg);
  for (double lambda : {1.0, 100.0, 1e4}) {
    for (bool weighted : {false, true}) {
      OptimalRequestsOptions options;
      options.request_smoothing = lambda;
      if (weighted) options.weights = weights;
      const double scale = weighted ? lambda * mean_weight : lambda;
      const std::vector<double> m0 = SteadyState(kPaper, start);
      double start_cost = scale * SquaredSecondDifferences(start);
      for (std::size_t t = 0; t < d.size(); ++t) {
        start_cost += (weighted ? weights[t] : 1.0) * (m0[t] - d[t]) * (m0[t] - d[t]);
      }
      const OptimalRequests opt = OptimizeRequests(d, kPaper, start, options);
      const double roughness = SquaredSecondDifferences(opt.requests_deg);
      EXPECT_LE(roughness, start_cost / scale * (1.0 + 1e-9)) << "lambda " << lambda;
      EXPECT_LT(roughness, plain_roughness) << "lambda " << lambda;
    }
  }
}

TEST(OptimizeRequests, FollowsAReachableCycleExactly) {
  // D is the steady state of known requests R0, so some R has zero error; from R = D.
  std::vector<double> r0(88);
  for (int t = 0; t < 88; ++t) {
    const double phase = 2.0 * std::numbers::pi * t / 88.0;
    r0[t] = 20.0 * std::sin(phase) + 5.0 * std::sin(2.0 * phase + 1.0) + (t % 11 == 0 ? 3.0 : 0.0);
  }
  const std::vector<double> d = SteadyState(kPaper, r0);
  ASSERT_GT(RmsError(kPaper, d, d), 1.0);  // requesting D itself lags it
  const OptimalRequests opt = OptimizeRequests(d, kPaper, d);
  EXPECT_LT(opt.rms_error_deg, 1e-6);
  EXPECT_LT(RmsError(kPaper, opt.requests_deg, d), 1e-6);
}

TEST(OptimizeRequests, SteadyStateIsCyclicSteadyStatesAndErrorIsItsRms) {
  const std::vector<double> d = WalkingCycle(40.0);
  const OptimalRequests opt = OptimizeRequests(d, kPaper, ModelBasedRequests(kPaper, d));
  ASSERT_EQ(opt.requests_deg.size(), d.size());
  const std::vector<double> m = SteadyState(kPaper, opt.requests_deg);
  ASSERT_EQ(opt.steady_state_deg.size(), d.size());
  for (std::size_t t = 0; t < d.size(); ++t) EXPECT_NEAR(opt.steady_state_deg[t], m[t], 1e-8);
  EXPECT_NEAR(opt.rms_error_deg, RmsDistance(m, d), 1e-9);
  EXPECT_GT(opt.iterations, 0);
}

TEST(OptimizeRequests, RequestsStayWithinTheLimits) {
  const std::vector<double> d = WalkingCycle(40.0);
  const std::vector<double> model_based = ModelBasedRequests(kPaper, d);
  const auto [lowest, highest] = std::minmax_element(model_based.begin(), model_based.end());
  ASSERT_LT(*lowest, -55.0);  // the paper's requests overshoot D by up to C_m
  ASSERT_GT(*highest, 45.0);
  OptimalRequestsOptions limits;
  limits.lower_deg = -50.0;
  limits.upper_deg = 40.0;
  const OptimalRequests opt = OptimizeRequests(d, kPaper, model_based, limits);
  for (double r : opt.requests_deg) {
    EXPECT_GE(r, limits.lower_deg);
    EXPECT_LE(r, limits.upper_deg);
  }
  // Never worse than the start clamped into the limits.
  std::vector<double> clamped = model_based;
  for (double& r : clamped) r = std::clamp(r, limits.lower_deg, limits.upper_deg);
  EXPECT_LE(opt.rms_error_deg, RmsError(kPaper, clamped, d) + 1e-9);
}

TEST(OptimizeRequests, NeverWorseThanTheStart) {
  const std::vector<double> d = WalkingCycle(70.0);
  std::vector<std::vector<double>> starts = {d, ModelBasedRequests(kPaper, d)};
  std::vector<double> noisy = d;
  for (int t = 0; t < 88; ++t) noisy[t] += 30.0 * std::sin(7.3 * t * t);
  starts.push_back(noisy);
  for (const std::vector<double>& start : starts) {
    const double start_rms = RmsError(kPaper, start, d);
    for (int iterations : {1, 3, 200}) {
      OptimalRequestsOptions options;
      options.max_iterations = iterations;
      const OptimalRequests opt = OptimizeRequests(d, kPaper, start, options);
      EXPECT_LE(opt.rms_error_deg, start_rms + 1e-9) << iterations;
      EXPECT_LE(RmsError(kPaper, opt.requests_deg, d), start_rms + 1e-9) << iterations;
      EXPECT_LE(opt.iterations, iterations);
    }
  }
}

TEST(OptimizeRequests, RevivesRequestsLostInSaturation) {
  // Every other request starts 200 deg away: all its terms are saturated, so it has no
  // first-order effect on the steady state. Exact f only (no smoothing), so it is the move to
  // the edge of f's linear range that lets these requests work again.
  std::vector<double> r0(88);
  for (int t = 0; t < 88; ++t) r0[t] = 20.0 * std::sin(2.0 * std::numbers::pi * t / 88.0);
  const std::vector<double> d = SteadyState(kPaper, r0);
  std::vector<double> start = d;
  for (int t = 1; t < 88; t += 2) start[t] += 200.0;
  ASSERT_GT(RmsError(kPaper, start, d), 10.0);
  OptimalRequestsOptions exact;
  exact.smoothing_theta0 = 0.0;
  EXPECT_LT(OptimizeRequests(d, kPaper, start, exact).rms_error_deg, 1e-3);
  EXPECT_LT(OptimizeRequests(d, kPaper, start).rms_error_deg, 1e-3);
}

TEST(OptimizeRequests, IsDeterministic) {
  const std::vector<double> d = WalkingCycle(70.0);
  const std::vector<double> start = ModelBasedRequests(kPaper, d);
  const OptimalRequests a = OptimizeRequests(d, kPaper, start);
  const OptimalRequests b = OptimizeRequests(d, kPaper, start);
  EXPECT_EQ(a.requests_deg, b.requests_deg);  // bit for bit
  EXPECT_EQ(a.steady_state_deg, b.steady_state_deg);
  EXPECT_EQ(a.rms_error_deg, b.rms_error_deg);
  EXPECT_EQ(a.iterations, b.iterations);
}

TEST(OptimizeRequests, RejectsBadInput) {
  const std::vector<double> d = {0.0, 1.0, 2.0};
  const std::vector<double> r = {0.0, 1.0, 2.0};
  EXPECT_THROW(OptimizeRequests({}, kPaper, {}), std::invalid_argument);
  EXPECT_THROW(OptimizeRequests(d, kPaper, std::vector<double>{0.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(
      OptimizeRequests(std::vector<double>{0.0, std::numeric_limits<double>::quiet_NaN(), 2.0},
                       kPaper, r),
      std::invalid_argument);
  EXPECT_THROW(
      OptimizeRequests(d, kPaper,
                       std::vector<double>{0.0, std::numeric_limits<double>::infinity(), 2.0}),
      std::invalid_argument);
  EXPECT_THROW(OptimizeRequests(d, {2.5, -7.0, 4, 6}, r), std::invalid_argument);
  OptimalRequestsOptions bad;
  bad.lower_deg = 10.0;
  bad.upper_deg = -10.0;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad = {};
  bad.max_iterations = 0;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad = {};
  bad.tolerance_deg = -1.0;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad = {};
  bad.smoothing_theta0 = -0.5;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad = {};
  bad.request_smoothing = -1.0;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad.request_smoothing = std::numeric_limits<double>::infinity();
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad = {};
  bad.weights = {1.0, 1.0};  // not one per tick
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad.weights.assign(d.size(), 1.0);
  bad.weights[1] = -0.5;
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  bad.weights[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(OptimizeRequests(d, kPaper, r, bad), std::invalid_argument);
  EXPECT_THROW(SteadyStateSensitivity(kPaper, {}), std::invalid_argument);
  EXPECT_THROW(SteadyStateSensitivity({0.0, 7.0, 4, 6}, r), std::invalid_argument);
  EXPECT_THROW(SteadyStateNormalMatrix(kPaper, {}), std::invalid_argument);
}

// --- The paper's walking cycles --------------------------------------------------------------

TEST(OptimizeRequests, BeatsThePapersModelBasedRequestsOnWalkingCycles) {
  // Pinned RMS errors to D (deg): the paper's model-based requests (8-segment PWL, exact C_m)
  // and the optimum from them. No steady state of the model can beat the best trajectory
  // whose every step is within v_max (|M(t) - M(t-1)| <= v_max by eq. 3): a slope-limited
  // least-squares fit with a breakpoint at every tick gives that bound independently.
  struct Expected {
    double amplitude_deg;
    double model_based_rms_deg;
    double optimal_rms_deg;
  };
  for (const Expected& e : {Expected{40.0, 7.0519, 6.9196}, Expected{70.0, 21.4292, 21.3496}}) {
    const std::vector<double> d = WalkingCycle(e.amplitude_deg);
    const std::vector<double> model_based = ModelBasedRequests(kPaper, d);
    const double model_based_rms = RmsError(kPaper, model_based, d);
    const OptimalRequests opt = OptimizeRequests(d, kPaper, model_based);
    std::vector<int> every_tick(d.size());
    std::iota(every_tick.begin(), every_tick.end(), 0);
    const double bound =
        PwlRmsError(FitPiecewiseLinearAt(d, kPaper.v_max_deg_per_tick, every_tick), d);
    RecordProperty("model_based_rms_deg_" + std::to_string(static_cast<int>(e.amplitude_deg)),
                   std::to_string(model_based_rms));
    RecordProperty("optimal_rms_deg_" + std::to_string(static_cast<int>(e.amplitude_deg)),
                   std::to_string(opt.rms_error_deg));
    EXPECT_NEAR(model_based_rms, e.model_based_rms_deg, 2e-3) << e.amplitude_deg;
    EXPECT_NEAR(opt.rms_error_deg, e.optimal_rms_deg, 5e-3) << e.amplitude_deg;
    EXPECT_LT(opt.rms_error_deg, model_based_rms - 0.05) << e.amplitude_deg;
    EXPECT_GT(opt.rms_error_deg, bound) << e.amplitude_deg;
  }
}

}  // namespace
}  // namespace leglab
