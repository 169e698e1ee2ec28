#pragma once

// PeriodicModel, the optimal request solver's model (internal to leglab::model, used by
// optimal_requests.cc and banded_step_solver.h only): eq. 3 on a request cycle with its steady
// state and the sensitivity of that steady state to the requests, and the cycle's index
// arithmetic (Wrap, SecondDifference).

#include <Eigen/Core>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include "leglab/model/joint_model.h"

namespace leglab::optimal_requests_internal {

// t modulo n in [0, n), as ((t % n) + n) % n, without its two integer divisions when t is in
// range or at most one period below it (every index of eq. 3's window unless l + a exceeds the
// cycle): a division takes tens of cycles, and the solves take these in their inner loops.
inline int Wrap(int t, int n) {
  if (t >= 0 && t < n) return t;
  if (t < 0 && t >= -n) return t + n;
  return ((t % n) + n) % n;
}

// What the sensitivity S = d M_ss / d R is made of (see PeriodicModel::Sensitivity): S is the
// cyclic solution of S(t) = alpha_t S(t-1) + u_t, u_t = sum_i slopes(t, i - l - 1) e_{t-i}.
struct SensitivityFactors {
  Eigen::VectorXd alphas;  // alpha_t
  Eigen::MatrixXd slopes;  // f'(x_ti) / a, row t, column i - l - 1
  double product = 1.0;    // alpha_0 ... alpha_{T-1}
};

// Eq. 3 run round a request cycle with f of eq. 2 (smoothing 0) or, for smoothing s > 0, the
// surrogate f_s(x) = (k/2) (sqrt((x + theta_0)^2 + s^2) - sqrt((x - theta_0)^2 + s^2)),
// k = v_max / theta_0: f itself at s = 0, odd, bounded by v_max, but increasing everywhere, so
// that a saturated request still has a (small) first-order effect.
class PeriodicModel {
 public:
  // `closed_kinks`: f' at x = +-theta_0 exactly is k (the linear branch's) instead of 0 (the
  // branch SpeedResponse takes there).
  PeriodicModel(const JointModelParams& params, std::span<const double> requests_deg,
                double smoothing_deg, bool closed_kinks)
      : params_(params),
        gain_(params.v_max_deg_per_tick / params.theta0_deg),
        requests_(requests_deg),
        smoothing_(smoothing_deg),
        closed_kinks_(closed_kinks) {}

  int period() const { return static_cast<int>(requests_.size()); }
  // The index of R(t - i) in the cycle.
  int IndexBefore(int t, int i) const { return Wrap(t - i, period()); }
  double RequestBefore(int t, int i) const { return requests_[IndexBefore(t, i)]; }

  double Response(double x) const {
    if (smoothing_ == 0.0) {
      // SpeedResponse, inlined (this is the inner loop of every steady state).
      if (x >= params_.theta0_deg) return params_.v_max_deg_per_tick;
      if (x <= -params_.theta0_deg) return -params_.v_max_deg_per_tick;
      return x * gain_;  // the same quotient, divided once
    }
    const double th = params_.theta0_deg;
    const double s2 = smoothing_ * smoothing_;
    return 0.5 * Gain() *
           (std::sqrt((x + th) * (x + th) + s2) - std::sqrt((x - th) * (x - th) + s2));
  }

  double ResponseSlope(double x) const {
    const double th = params_.theta0_deg;
    if (smoothing_ == 0.0) {
      const bool linear = closed_kinks_ ? (x >= -th && x <= th) : (x > -th && x < th);
      return linear ? Gain() : 0.0;
    }
    const double s2 = smoothing_ * smoothing_;
    return 0.5 * Gain() *
           ((x + th) / std::sqrt((x + th) * (x + th) + s2) -
            (x - th) / std::sqrt((x - th) * (x - th) + s2));
  }

  // One cycle of eq. 3 from M(-1) = `start_deg`; writes M(0..T-1) to `angles` when given.
  // Returns M(T-1) and d M(T-1) / d M(-1).
  std::pair<double, double> RunCycle(double start_deg, std::vector<double>* angles) const {
    const int l = params_.lag_ticks;
    const int a = params_.accel_ticks;
    double angle = start_deg;
    double gain = 1.0;
    // f exact with open kinks (every steady state): Response and ResponseSlope in one test,
    // the same sums term by term (a saturated term adds 0 to the slope, which leaves it).
    const bool exact_open = smoothing_ == 0.0 && !closed_kinks_;
    const double th = params_.theta0_deg;
    const double v_max = params_.v_max_deg_per_tick;
    for (int t = 0; t < period(); ++t) {
      double velocity = 0.0;
      double slope = 0.0;
      if (exact_open) {
        for (int i = l + 1; i <= l + a; ++i) {
          const double x = RequestBefore(t, i) - angle;
          if (x >= th) {
            velocity += v_max;
          } else if (x <= -th) {
            velocity += -v_max;
          } else {
            velocity += x * gain_;
            if (x > -th && x < th) slope += gain_;  // false only for NaN
          }
        }
      } else {
        for (int i = l + 1; i <= l + a; ++i) {
          const double x = RequestBefore(t, i) - angle;
          velocity += Response(x);
          slope += ResponseSlope(x);
        }
      }
      gain *= 1.0 - slope / a;
      angle += velocity / a;
      if (angles != nullptr) (*angles)[t] = angle;
    }
    return {angle, gain};
  }

  // The cyclic steady state M(0..T-1) that CyclicSteadyState converges to: the limit of the
  // cycle map P (M(-1) -> M(T-1)) iterated from M(-1) = mean R. With v_max <= theta_0 every
  // factor 1 - (1/a) sum f' of P' lies in [0, 1], so P is non-decreasing and phi(m) = P(m) - m
  // non-increasing, and the iterates climb (phi > 0) or fall (phi < 0) monotonically to the
  // nearest fixed point on that side. That point is found here by Newton's method from the
  // outer side, safeguarded by bisection: with f exact phi is piecewise linear, so this takes
  // a few cycles where iterating P converges only as fast as the model forgets (slowly, or
  // never exactly, when most of the cycle is saturated; where all of it is, the fixed points
  // fill an interval and the mean picks one). With v_max > theta_0, P need not be monotone:
  // CyclicSteadyState itself (f exact only).
  std::vector<double> SteadyState() const {
    if (params_.v_max_deg_per_tick > params_.theta0_deg) {
      assert(smoothing_ == 0.0);
      return CyclicSteadyState(params_, requests_);
    }
    double mean = 0.0;
    double scale = 1.0;
    for (double r : requests_) {
      mean += r;
      scale = std::max(scale, std::abs(r));
    }
    mean /= period();
    const double tolerance = 1e-12 * scale;
    // Work on the side where phi > 0 (mirrored when the iterates fall): find the least m >=
    // m0 with phi(m) <= tolerance. `outer` keeps phi > tolerance, `inner` phi <= tolerance.
    const auto [end0, gain0] = RunCycle(mean, nullptr);
    const double sign = end0 - mean >= 0.0 ? 1.0 : -1.0;
    double m = mean;
    if (std::abs(end0 - mean) > tolerance) {
      auto phi = [&](double x) {
        const auto [end, gain] = RunCycle(x, nullptr);
        return std::pair{sign * (end - x), gain};
      };
      double outer = mean;
      double phi_outer = sign * (end0 - mean);
      double gain_outer = gain0;
      // P maps [min R, max R] into itself, so the fixed point is no further than the far end.
      const auto [min_it, max_it] = std::minmax_element(requests_.begin(), requests_.end());
      double inner = sign > 0.0 ? *max_it : *min_it;
      const double resolution = 1e-14 * scale;
      for (int iteration = 0; iteration < 200 && std::abs(inner - outer) > resolution;
           ++iteration) {
        // Newton from the outer side (phi' = P' - 1 <= 0 in the signed variable).
        double next = 0.5 * (outer + inner);
        if (gain_outer < 1.0) {
          const double newton = outer + sign * phi_outer / (1.0 - gain_outer);
          if (sign * (newton - outer) > 0.0 && sign * (inner - newton) > 0.0) next = newton;
        }
        const auto [phi_next, gain_next] = phi(next);
        if (phi_next > tolerance) {
          outer = next;
          phi_outer = phi_next;
          gain_outer = gain_next;
          continue;
        }
        inner = next;
        // Landed on the fixed point itself, not past it into a flat run of fixed points? On
        // the outer side's linear piece phi would be 2 * tolerance a little way back.
        if (gain_outer < 1.0) {
          const double back = next - sign * 2.0 * tolerance / (1.0 - gain_outer);
          if (sign * (back - outer) <= 0.0 || phi(back).first > tolerance) break;
        }
      }
      m = inner;
    }
    std::vector<double> angles(period());
    RunCycle(m, &angles);
    return angles;
  }

  // d M_ss / d R at the steady state `angles`. With S(t) = d M(t) / d R (a row), eq. 3 gives
  //   S(t) = alpha_t S(t-1) + u_t,  alpha_t = 1 - (1/a) sum_i f'(x_ti),  u_t = (1/a) sum_i
  //   f'(x_ti) e_{t-i},
  // x_ti = R(t-i) - M(t-1). Run from S(-1) = 0 it gives S0; the periodic solution is
  // S(t) = S0(t) + (alpha_0 ... alpha_t) X, X = S(T-1) = S0(T-1) / (1 - alpha_0 ... alpha_{T-1}).
  // Written to `s` (resized to T x T). Terms (t, i) with saturated[t * a + i - l - 1] set take
  // f' = 0 (the side of a kink a step moves them to). With `normal`, also the Gauss-Newton
  // matrix S^T W S (see NormalMatrix); with `factors`, alpha_t, f'/a and their product.
  void Sensitivity(std::span<const double> angles, Eigen::MatrixXd& s,
                   const std::vector<char>* saturated = nullptr, Eigen::MatrixXd* normal = nullptr,
                   std::span<const double> row_weights = {},
                   SensitivityFactors* factors = nullptr) const {
    const int l = params_.lag_ticks;
    const int a = params_.accel_ticks;
    const int n = period();
    s.resize(n, n);
    Eigen::VectorXd decay(n);  // alpha_0 ... alpha_t
    Eigen::VectorXd alphas(n);
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(n);
    // With `normal`, also S0's rows as columns: the recursion below reads them contiguously.
    Eigen::MatrixXd rows_t;
    if (normal != nullptr) rows_t.resize(n, n);
    // f'(x_ti) / a, row t, column i - l - 1.
    Eigen::MatrixXd slopes(n, a);
    double product = 1.0;
    for (int t = 0; t < n; ++t) {
      const double previous = angles[(t - 1 + n) % n];
      double slope_sum = 0.0;
      for (int i = l + 1; i <= l + a; ++i) {
        const bool forced = saturated != nullptr && (*saturated)[t * a + i - l - 1] != 0;
        slopes(t, i - l - 1) = forced ? 0.0 : ResponseSlope(RequestBefore(t, i) - previous) / a;
        slope_sum += slopes(t, i - l - 1);
      }
      const double alpha = 1.0 - slope_sum;
      alphas[t] = alpha;
      row *= alpha;
      for (int i = l + 1; i <= l + a; ++i) row[IndexBefore(t, i)] += slopes(t, i - l - 1);
      product *= alpha;
      decay[t] = product;
      s.row(t) = row;
      if (normal != nullptr) rows_t.col(t) = row.transpose();
    }
    Eigen::RowVectorXd periodic_start;
    if (1.0 - product > 0.0) {
      periodic_start = s.row(n - 1) / (1.0 - product);
    } else {
      // Every term of the cycle saturated: a whole interval of steady states, of which
      // SteadyState takes the one through M(-1) = mean R. Each request moves it through the
      // mean, by 1/T.
      periodic_start = Eigen::RowVectorXd::Constant(n, 1.0 / n);
    }
    if (normal != nullptr) {
      NormalMatrix(s, rows_t, alphas, slopes, decay, periodic_start, row_weights, *normal);
    }
    s.noalias() += decay * periodic_start;
    if (factors != nullptr) {
      factors->alphas = alphas;
      factors->slopes = slopes;
      factors->product = product;
    }
  }

 private:
  // The Gauss-Newton matrix S^T W S (T x T, W = diag(omega), the rows' weights; empty
  // `row_weights`: all 1) into g, from Sensitivity's S0 (`s0`, and its rows as the columns of
  // `rows_t`), alpha_t, the slopes f'(x_ti) / a, the decay d(t) = alpha_0 ... alpha_t and the
  // periodic start p = X: O(T^2 a) instead of the O(T^3) of the product. With S = S0 + d p^T,
  //   S0^T W S0 = sum_t omega_t S0(t)^T S0(t) = sum_t w_t B_t,
  //   B_t = alpha_t (S0(t-1)^T u_t + u_t^T S0(t-1)) + u_t^T u_t,
  //   w_t = omega_t + alpha_{t+1}^2 w_{t+1}, w_{T-1} = omega_{T-1},
  // (unrolling S0(t)^T S0(t) = alpha_t^2 S0(t-1)^T S0(t-1) + B_t), where each B_t touches only
  // the a columns and rows of u_t; and S^T W S = S0^T W S0 + v p^T + p v^T + (d.W d) p p^T
  // with v = S0^T W d.
  void NormalMatrix(const Eigen::MatrixXd& s0, const Eigen::MatrixXd& rows_t,
                    const Eigen::VectorXd& alphas, const Eigen::MatrixXd& slopes,
                    const Eigen::VectorXd& decay, const Eigen::RowVectorXd& periodic_start,
                    std::span<const double> row_weights, Eigen::MatrixXd& g) const {
    const int l = params_.lag_ticks;
    const int a = params_.accel_ticks;
    const int n = period();
    g.setZero(n, n);
    auto omega = [&](int t) { return row_weights.empty() ? 1.0 : row_weights[t]; };
    double weight = omega(n - 1);  // w_t, from t = T-1 down
    for (int t = n - 1; t >= 0; --t) {
      if (t < n - 1) weight = omega(t) + alphas[t + 1] * alphas[t + 1] * weight;
      for (int i = 0; i < a; ++i) {
        const double ui = slopes(t, i);
        if (ui == 0.0) continue;
        const int ci = IndexBefore(t, i + l + 1);
        // One half of the cross term (the other is its transpose, added below).
        if (t > 0) g.col(ci) += (weight * alphas[t] * ui) * rows_t.col(t - 1);
        for (int k = 0; k < a; ++k) {
          g(IndexBefore(t, k + l + 1), ci) += 0.5 * weight * ui * slopes(t, k);
        }
      }
    }
    // g + g^T in place (a + b is b + a, bit for bit).
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < j; ++i) g(i, j) = g(j, i) = g(i, j) + g(j, i);
      g(j, j) += g(j, j);
    }
    Eigen::VectorXd weighted_decay = decay;
    for (int t = 0; t < n; ++t) weighted_decay[t] *= omega(t);
    const Eigen::VectorXd v = s0.transpose() * weighted_decay;
    const Eigen::VectorXd p = periodic_start.transpose();
    g.noalias() += v * p.transpose();
    g.noalias() += p * v.transpose();
    g.noalias() += decay.dot(weighted_decay) * (p * p.transpose());
  }

  double Gain() const { return gain_; }

  JointModelParams params_;
  double gain_;  // v_max / theta_0
  std::span<const double> requests_;
  double smoothing_;
  bool closed_kinks_;
};

// (R(t+1) - 2 R(t) + R(t-1)) round the cycle.
inline double SecondDifference(std::span<const double> r, int t) {
  const int n = static_cast<int>(r.size());
  return r[Wrap(t + 1, n)] - 2.0 * r[t] + r[Wrap(t - 1, n)];
}

}  // namespace leglab::optimal_requests_internal
