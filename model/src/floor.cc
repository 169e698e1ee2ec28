#include "leglab/model/floor.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/model/cyclic_banded_cholesky.h"

namespace leglab {
namespace {

using Eigen::VectorXd;

[[noreturn]] void Fail(const std::string& what) { throw std::invalid_argument("floor: " + what); }

// The floor's 4T rows as 2T bounded functionals of x (size T), indices cyclic:
//   functional 2t     speed   g(x) = x(t+1) - x(t),             |g| <= v
//   functional 2t + 1 change  g(x) = x(t+1) - 2 x(t) + x(t-1),  |g| <= c
// Row 2k is +g_k <= b_k and row 2k + 1 is -g_k <= b_k. The rows of A touching column t are
// those of the functionals 2t - 2 (speed t-1), 2t (speed t) and 2t - 1, 2t + 1, 2t + 3
// (change t-1, t, t+1).
class FloorRows {
 public:
  FloorRows(int period, double speed, double change)
      : period_(period), speed_(speed), change_(change) {}

  int period() const { return period_; }
  int functionals() const { return 2 * period_; }
  int rows() const { return 4 * period_; }
  double Bound(int k) const { return k % 2 == 0 ? speed_ : change_; }

  // Functional k's columns and their coefficients; returns how many (2 or 3).
  int Columns(int k, int columns[3], double coefficients[3]) const {
    const int t = k / 2;
    const int next = (t + 1) % period_;
    if (k % 2 == 0) {
      columns[0] = t;
      coefficients[0] = -1.0;
      columns[1] = next;
      coefficients[1] = 1.0;
      return 2;
    }
    columns[0] = (t + period_ - 1) % period_;
    coefficients[0] = 1.0;
    columns[1] = t;
    coefficients[1] = -2.0;
    columns[2] = next;
    coefficients[2] = 1.0;
    return 3;
  }

  // g = the functionals' values at x.
  template <typename Vector>
  void Apply(const Vector& x, VectorXd& g) const {
    for (Eigen::Index t = 0; t < period_; ++t) {
      const double here = x[t];
      const double next = x[(t + 1) % period_];
      const double previous = x[(t + period_ - 1) % period_];
      g[2 * t] = next - here;
      g[2 * t + 1] = next - 2.0 * here + previous;
    }
  }

  // out = sum over functionals k of y_k a_k (A' applied to per-functional net multipliers).
  void ApplyTransposed(const VectorXd& y, VectorXd& out) const {
    out.setZero(period_);
    for (Eigen::Index t = 0; t < period_; ++t) {
      const Eigen::Index next = (t + 1) % period_;
      const Eigen::Index previous = (t + period_ - 1) % period_;
      out[next] += y[2 * t] + y[2 * t + 1];
      out[t] -= y[2 * t] + 2.0 * y[2 * t + 1];
      out[previous] += y[2 * t + 1];
    }
  }

 private:
  int period_;
  double speed_;
  double change_;
};

// The projection's primal-dual interior point (Mehrotra's predictor-corrector; Nocedal &
// Wright, Numerical Optimization, 2nd ed., sections 14.2 and 16.6) in scaled coordinates:
//   minimise 0.5 |x - d|^2 subject to A x + s = b, s >= 0, with multipliers lambda >= 0.
// Each Newton step solves (I + A' W A) dx = r, W = diag(lambda / s), a cyclic pentadiagonal
// matrix: O(T) work a step. It ends with complementarity s o lambda small, and the rows with
// lambda > s are the active set, on which the projection is then solved exactly
// (SolveOnActiveSet): the interior point finds the set, the face solve gives the bits.
struct InteriorPoint {
  VectorXd x, slack, multipliers;  // sizes T, 4T, 4T
};

constexpr int kMaxInteriorIterations = 200;
constexpr int kMaxActiveSetRounds = 20;
constexpr int kMaxRefinementPasses = 100;
// delta of SolveOnFace, in the scaled coordinates where A's entries and b are of order one.
constexpr double kFaceRegularisation = 1e-10;
// Fraction of the step to the boundary taken, keeping s and lambda strictly positive.
constexpr double kStepFraction = 0.995;

class FloorSolver {
 public:
  FloorSolver(const FloorRows& rows, const VectorXd& desired)
      : rows_(rows), desired_(desired), g_(rows.functionals()), dg_(rows.functionals()) {}

  // Interior point iterations until the mean complementarity per row is below `gap` and both
  // residuals below `residual`; false if it stalls first (`point` is then its last iterate).
  bool Solve(InteriorPoint& point, double gap, double residual);

  // The projection, from `point`'s active set (lambda > s) refined until x is feasible and the
  // set's multipliers are >= 0 (optimality); false (x untouched) if that takes too many rounds.
  bool SolveOnActiveSet(const InteriorPoint& point, VectorXd& x);

  // x, the minimiser with one row of each functional k with side[k] != 0 as an equality (the
  // row +g_k = b_k for side +1, -g_k = b_k for -1), and nu its multipliers (per functional; the
  // start of the refinement on entry). False if the system is not positive definite.
  bool SolveOnFace(const std::vector<int>& side, VectorXd& nu, VectorXd& x);

 private:
  // dx, ds, dlambda of the Newton step at `point` with the given residuals, where
  // `complementarity` is what the step removes from s o lambda: s o lambda itself for the
  // predictor; for the corrector, that plus the predictor's ds o dlambda minus sigma mu.
  // False when W's spread has made the system numerically singular (an interior point's end).
  bool Step(const InteriorPoint& point, const VectorXd& dual_residual,
            const VectorXd& primal_residual, const VectorXd& complementarity, VectorXd& dx,
            VectorXd& ds, VectorXd& dlambda);

  const FloorRows& rows_;
  const VectorXd& desired_;
  CyclicBandedCholesky system_;
  VectorXd g_, dg_;
};

double Sign(int row) { return row % 2 == 0 ? 1.0 : -1.0; }

// The largest step in (0, 1] keeping v + alpha dv >= 0, times kStepFraction when it blocks.
double StepToBoundary(const VectorXd& v, const VectorXd& dv) {
  double alpha = 1.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (dv[i] < 0.0) alpha = std::min(alpha, -kStepFraction * v[i] / dv[i]);
  }
  return alpha;
}

bool FloorSolver::Step(const InteriorPoint& point, const VectorXd& dual_residual,
                       const VectorXd& primal_residual, const VectorXd& complementarity,
                       VectorXd& dx, VectorXd& ds, VectorXd& dlambda) {
  // With W = lambda / s per row, dlambda = W (A dx + r_p) - complementarity / s and
  // ds = -r_p - A dx; the dual equation dx + A' dlambda = -r_d becomes
  //   (I + A' W A) dx = -r_d - A' (W r_p - complementarity / s).
  const int n = rows_.period();
  const int m = rows_.rows();
  VectorXd net(rows_.functionals());
  VectorXd weight(rows_.functionals());
  for (int k = 0; k < rows_.functionals(); ++k) {
    double sum = 0.0;
    double w_sum = 0.0;
    for (int r = 2 * k; r < 2 * k + 2; ++r) {
      const double w = point.multipliers[r] / point.slack[r];
      sum += Sign(r) * (w * primal_residual[r] - complementarity[r] / point.slack[r]);
      w_sum += w;
    }
    net[k] = sum;
    weight[k] = w_sum;
  }
  VectorXd rhs(n);
  rows_.ApplyTransposed(net, rhs);
  rhs = -dual_residual - rhs;

  system_.Reset(n);
  for (int t = 0; t < n; ++t) system_.Add(t, t, 1.0);
  int columns[3];
  double coefficients[3];
  for (int k = 0; k < rows_.functionals(); ++k) {
    const int count = rows_.Columns(k, columns, coefficients);
    for (int i = 0; i < count; ++i) {
      for (int j = 0; j <= i; ++j) {
        system_.Add(columns[i], columns[j], weight[k] * coefficients[i] * coefficients[j]);
      }
    }
  }
  if (!system_.Factor()) return false;
  dx = rhs;
  system_.Solve(dx);
  rows_.Apply(dx, dg_);
  ds.resize(m);
  dlambda.resize(m);
  for (int r = 0; r < m; ++r) {
    const double a_dx = Sign(r) * dg_[r / 2];
    ds[r] = -primal_residual[r] - a_dx;
    dlambda[r] = point.multipliers[r] / point.slack[r] * (a_dx + primal_residual[r]) -
                 complementarity[r] / point.slack[r];
  }
  return true;
}

bool FloorSolver::Solve(InteriorPoint& point, double gap, double residual) {
  const int n = rows_.period();
  const int m = rows_.rows();
  VectorXd dual_residual(n), primal_residual(m), complementarity(m);
  VectorXd dx, ds, dlambda, dx_c, ds_c, dlambda_c, net(rows_.functionals());
  for (int iteration = 0; iteration < kMaxInteriorIterations; ++iteration) {
    for (Eigen::Index k = 0; k < rows_.functionals(); ++k) {
      net[k] = point.multipliers[2 * k] - point.multipliers[2 * k + 1];
    }
    rows_.ApplyTransposed(net, dual_residual);
    dual_residual += point.x - desired_;
    rows_.Apply(point.x, g_);
    for (int r = 0; r < m; ++r) {
      primal_residual[r] = Sign(r) * g_[r / 2] + point.slack[r] - rows_.Bound(r / 2);
    }
    const double mu = point.slack.dot(point.multipliers) / m;
    if (mu <= gap && dual_residual.lpNorm<Eigen::Infinity>() <= residual &&
        primal_residual.lpNorm<Eigen::Infinity>() <= residual) {
      return true;
    }
    // Predictor: the affine step to complementarity 0.
    complementarity = point.slack.cwiseProduct(point.multipliers);
    if (!Step(point, dual_residual, primal_residual, complementarity, dx, ds, dlambda)) {
      return false;
    }
    const double alpha_affine =
        std::min(StepToBoundary(point.slack, ds), StepToBoundary(point.multipliers, dlambda));
    const double mu_affine =
        (point.slack + alpha_affine * ds).dot(point.multipliers + alpha_affine * dlambda) / m;
    const double centring = std::pow(mu_affine / mu, 3);
    // Corrector: the centred step with the predictor's second-order term.
    complementarity.array() += ds.array() * dlambda.array() - centring * mu;
    if (!Step(point, dual_residual, primal_residual, complementarity, dx_c, ds_c, dlambda_c)) {
      return false;
    }
    const double alpha =
        std::min(StepToBoundary(point.slack, ds_c), StepToBoundary(point.multipliers, dlambda_c));
    if (!(alpha > 0.0) || !dx_c.allFinite()) return false;
    point.x += alpha * dx_c;
    point.slack += alpha * ds_c;
    point.multipliers += alpha * dlambda_c;
  }
  return false;
}

bool FloorSolver::SolveOnActiveSet(const InteriorPoint& point, VectorXd& x) {
  const int count = rows_.functionals();
  std::vector<int> side(count, 0);
  VectorXd nu = VectorXd::Zero(count);
  for (int k = 0; k < count; ++k) {
    for (int r = 2 * k; r < 2 * k + 2; ++r) {
      if (point.multipliers[r] > point.slack[r]) {
        side[k] = static_cast<int>(Sign(r));
        nu[k] = point.multipliers[r];
      }
    }
  }
  // The interior point's set is exact in all but degenerate programs, where a row that is
  // nearly active and nearly free can be misread; each round drops the rows whose multiplier
  // came out negative and adds those violated, the primal-dual active-set rule (Hintermuller,
  // Ito and Kunisch, SIAM J. Optim. 13(3), 2002), until the set certifies itself.
  VectorXd candidate;
  for (int round = 0; round < kMaxActiveSetRounds; ++round) {
    if (!SolveOnFace(side, nu, candidate)) return false;
    rows_.Apply(candidate, g_);
    const double tolerance = 1e-8 * (1.0 + nu.lpNorm<Eigen::Infinity>());
    bool changed = false;
    for (int k = 0; k < count; ++k) {
      if (side[k] != 0 && nu[k] < -tolerance) {
        side[k] = 0;
        nu[k] = 0.0;
        changed = true;
      } else if (side[k] == 0 && std::abs(g_[k]) > rows_.Bound(k) * (1.0 + 1e-12) + 1e-13) {
        side[k] = g_[k] > 0.0 ? 1 : -1;
        changed = true;
      }
    }
    if (!changed) {
      x = candidate;
      return true;
    }
  }
  return false;
}

bool FloorSolver::SolveOnFace(const std::vector<int>& side, VectorXd& nu, VectorXd& x) {
  // The rows S of `side` as equalities: x = d - A_S' nu with A_S A_S' nu = A_S d - b_S. A_S A_S'
  // may be singular (dependent rows, as when every speed row of one sign is active), so it is
  // solved by iterative refinement with A_S A_S' + delta I, from the given nu: each pass takes
  // the error of A_S x = b_S down by delta / (delta + sigma^2) along every singular value
  // sigma > 0, and the null space of A_S' does not change x.
  const int n = rows_.period();
  const int count = rows_.functionals();
  std::vector<int> active;               // the functionals with a row in S, in order
  std::vector<int> position(count, -1);  // functional -> its place in S
  for (int k = 0; k < count; ++k) {
    if (side[k] != 0) {
      position[k] = static_cast<int>(active.size());
      active.push_back(k);
    } else {
      nu[k] = 0.0;
    }
  }
  const int size = static_cast<int>(active.size());
  x = desired_;
  if (size == 0) return true;
  system_.Reset(size);
  for (int i = 0; i < size; ++i) system_.Add(i, i, kFaceRegularisation);
  int columns[3];
  double coefficients[3];
  // A_S A_S' = the sum over columns c of (column c of A_S)(column c of A_S)', with the rows
  // touching column c (FloorRows).
  for (int c = 0; c < n; ++c) {
    int members[5];
    double values[5];
    int touching = 0;
    for (int k : {2 * c - 2, 2 * c, 2 * c - 1, 2 * c + 1, 2 * c + 3}) {
      const int functional = (k + count) % count;
      const int place = position[functional];
      if (place < 0) continue;
      const int used = rows_.Columns(functional, columns, coefficients);
      for (int j = 0; j < used; ++j) {
        if (columns[j] == c) {
          members[touching] = place;
          values[touching++] = side[functional] * coefficients[j];
        }
      }
    }
    for (int i = 0; i < touching; ++i) {
      for (int j = 0; j <= i; ++j) system_.Add(members[i], members[j], values[i] * values[j]);
    }
  }
  if (!system_.Factor()) return false;
  VectorXd residual(size), net(count), shift(n);
  double last = std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < kMaxRefinementPasses; ++pass) {
    for (int k = 0; k < count; ++k) net[k] = side[k] * nu[k];
    rows_.ApplyTransposed(net, shift);
    VectorXd candidate = desired_ - shift;
    rows_.Apply(candidate, g_);
    for (int i = 0; i < size; ++i) {
      const int k = active[i];
      residual[i] = side[k] * g_[k] - rows_.Bound(k);
    }
    const double size_of_residual = residual.lpNorm<Eigen::Infinity>();
    if (!(size_of_residual < 0.5 * last)) break;  // at rounding level: keep the last x
    last = size_of_residual;
    x = candidate;
    system_.Solve(residual);
    for (int i = 0; i < size; ++i) nu[active[i]] += residual[i];
  }
  return true;
}

}  // namespace

std::vector<double> FloorTrajectory(std::span<const double> desired_deg,
                                    const JointModelParams& params) {
  ValidateJointModelParams(params);
  const int period = static_cast<int>(desired_deg.size());
  if (period < 3) {
    Fail("the desired cycle needs at least 3 samples, got " + std::to_string(period));
  }
  for (int t = 0; t < period; ++t) {
    if (!std::isfinite(desired_deg[t])) {
      Fail("desired sample " + std::to_string(t) + " is not finite");
    }
  }
  const double speed = params.v_max_deg_per_tick;
  const double speed_change = 2.0 * speed / params.accel_ticks;
  const Eigen::Map<const VectorXd> desired(desired_deg.data(), period);

  // The projection commutes with adding a constant and with scaling D and the bounds together:
  // it is solved for (D - mean) / scale and the bounds / scale, every number of order one.
  const double mean = desired.mean();
  const double spread = (desired.array() - mean).abs().maxCoeff();
  if (!std::isfinite(mean) || !std::isfinite(spread)) {
    Fail("the desired cycle's values overflow (beyond about 1e307 deg)");
  }
  const double scale = std::max({spread, speed, speed_change});
  const FloorRows rows(period, speed / scale, speed_change / scale);
  const VectorXd centred = (desired.array() - mean) / scale;
  // A D that meets every bound, tested in degrees as the caller's bounds are written.
  const FloorRows rows_deg(period, speed, speed_change);
  VectorXd values(rows_deg.functionals());
  rows_deg.Apply(desired, values);
  bool feasible = true;
  for (int k = 0; k < rows_deg.functionals(); ++k) {
    if (std::abs(values[k]) > rows_deg.Bound(k)) feasible = false;
  }
  if (feasible) return {desired_deg.begin(), desired_deg.end()};

  // From the constant cycle (x = 0, strictly feasible: s = b) with lambda = 1. The face solve
  // is tried at each tighter gap: most programs are done at the first.
  InteriorPoint point{VectorXd::Zero(period), VectorXd(rows.rows()), VectorXd::Ones(rows.rows())};
  for (int r = 0; r < rows.rows(); ++r) point.slack[r] = rows.Bound(r / 2);
  FloorSolver solver(rows, centred);
  VectorXd x;
  bool solved = false;
  for (double gap : {1e-8, 1e-10, 1e-12, 1e-14}) {
    const bool converged = solver.Solve(point, gap, 1e-8);
    if (solver.SolveOnActiveSet(point, x)) {
      solved = true;
      break;
    }
    if (!converged) break;
  }
  if (!solved) throw std::runtime_error("floor: the projection's active set was not found");
  std::vector<double> floor(period);
  for (int t = 0; t < period; ++t) floor[t] = mean + scale * x[t];
  return floor;
}

}  // namespace leglab
