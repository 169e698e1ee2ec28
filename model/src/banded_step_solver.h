#pragma once

// BandedStepSolver, the optimal request solver's damped Gauss-Newton step solved through the
// cyclic banded structure of PeriodicModel's sensitivity (internal to leglab::model, used by
// optimal_requests.cc only).

#include <Eigen/Core>
#include <cassert>
#include <cstddef>
#include <span>
#include <vector>

#include "leglab/model/cyclic_banded_cholesky.h"
#include "leglab/model/joint_model.h"
#include "periodic_model.h"

namespace leglab::optimal_requests_internal {

// The damped Gauss-Newton step of MinimiseStage without its T x T normal matrix:
//   (S_F^T W S_F + c I) x = -S_F^T W e,
// S_F the columns F (the free requests) of the sensitivity S, W = diag(w) > 0, e = M_ss - D.
// S is the cyclic solution of S(t) = alpha_t S(t-1) + u_t, that is B S = U with B the cyclic
// bidiagonal (B y)_t = y_t - alpha_t y_{t-1} (invertible when alpha_0 ... alpha_{T-1} != 1)
// and U's row t holding u_t. x is the minimiser of (1/2)|W^1/2 (S_F x + e)|^2 + (c/2)|x|^2;
// with y = S_F x, i.e. B y = U_F x, and a multiplier lambda for that constraint:
//   W (y + e) + B^T lambda = 0,   c x = U_F^T lambda,   B y = U_F x.
// Eliminating y = -e - W^-1 B^T lambda and x = U_F^T lambda / c, with mu = lambda / c:
//   (c B W^-1 B^T + U_F U_F^T) mu = -B e,   x = U_F^T mu.
// B W^-1 B^T is cyclic tridiagonal and U_F U_F^T cyclic banded (request j's column of U has
// its a non-zeros in rows j + l + 1 .. j + l + a): the matrix's envelope (each row from its
// first non-zero to the diagonal) holds the band and, from the cyclic corners, the last rows
// whole, and a Cholesky factor stays inside the envelope (CyclicBandedCholesky). That is
// O(T a^2 + a T^2) work instead of the dense matrix's O(T^2 a) and its factorisation's O(T^3).
//
// With move suppression lambda' |L (R + P_F x)|^2 (L the cyclic second difference, P_F placing
// x at the free requests; see request_smoothing) the step minimises that too. A second
// auxiliary z = L_F x with its multiplier nu keeps the regulariser of x at c I:
//   c x = U_F^T lambda + L_F^T nu,   lambda' (L R + z) + nu = 0,
// and with mu = lambda / c, eta = nu / c the system in (mu, eta) is
//   (c B W^-1 B^T + U_F U_F^T) mu + U_F L_F^T eta = -B e,
//   L_F U_F^T mu + ((c / lambda') I + L_F L_F^T) eta = -L R,   x = U_F^T mu + L_F^T eta.
// Interleaved (mu_0, eta_0, mu_1, eta_1, ...), its matrix is
// diag(c B W^-1 B^T, (c/lambda') I) plus the sum over free requests j of v_j v_j^T, v_j holding
// U's column j (at the mu indices) and L's (1, -2, 1 at the eta indices of j - 1, j, j + 1):
// positive definite, cyclic banded, and CyclicBandedCholesky solves it the same way.
class BandedStepSolver {
 public:
  // False (x then undefined) where it does not apply: a weight not positive, B (nearly) singular,
  // or the matrix not numerically positive definite; the caller then solves densely.
  // `suppression` is lambda' (0: none); `requests` R, needed only with it.
  bool Solve(const JointModelParams& params, const SensitivityFactors& f,
             std::span<const double> weights, std::span<const double> error,
             std::span<const int> free, double c, Eigen::VectorXd& x, double suppression = 0.0,
             std::span<const double> requests = {}) {
    const auto n = static_cast<int>(error.size());
    if (n < 3 || !(c > 0.0) || !(1.0 - f.product >= 1e-9)) return false;
    for (double w : weights) {
      if (!(w > 0.0)) return false;
    }
    n_ = n;
    lag_ = params.lag_ticks;
    accel_ = params.accel_ticks;
    smooth_ = suppression > 0.0;
    assert(!smooth_ || requests.size() == error.size());
    system_.Reset(smooth_ ? 2 * n : n);
    AddCycleTerms(f, weights, c, suppression);
    for (const int j : free) AddFreeRequest(f, j);
    if (!system_.Factor()) return false;
    SetRightHandSide(f, error, requests);
    system_.Solve(mu_);
    StepFromMultipliers(f, free, x);
    return x.allFinite();
  }

 private:
  // Where mu_t and eta_t sit in the (interleaved, with suppression) unknowns.
  int MuAt(int t) const { return smooth_ ? 2 * t : t; }
  static int EtaAt(int t) { return 2 * t + 1; }
  // The cycle's neighbours of tick t.
  int Before(int t) const { return t == 0 ? n_ - 1 : t - 1; }
  int After(int t) const { return t == n_ - 1 ? 0 : t + 1; }

  // Adds c B W^-1 B^T: (t, t) c (1/w_t + alpha_t^2 / w_{t-1}), (t, t-1) -c alpha_t / w_{t-1};
  // and, with suppression, (c / lambda') I at the eta indices.
  void AddCycleTerms(const SensitivityFactors& f, std::span<const double> weights, double c,
                     double suppression) {
    auto inverse_weight = [&](int t) { return weights.empty() ? 1.0 : 1.0 / weights[t]; };
    for (int t = 0; t < n_; ++t) {
      const int before = Before(t);
      const double alpha = f.alphas[t];
      system_.Add(MuAt(t), MuAt(t),
                  c * (inverse_weight(t) + alpha * alpha * inverse_weight(before)));
      system_.Add(MuAt(t), MuAt(before), -c * alpha * inverse_weight(before));
      if (smooth_) system_.Add(EtaAt(t), EtaAt(t), c / suppression);
    }
  }

  // Adds v_j v_j^T for free request j: it enters row t = j + i + l + 1 (mod T) of U with
  // slopes(t, i), and (with suppression) rows j - 1, j, j + 1 of L with 1, -2, 1.
  void AddFreeRequest(const SensitivityFactors& f, int j) {
    const int entries = smooth_ ? accel_ + 3 : accel_;
    rows_.resize(entries);
    values_.resize(entries);
    for (int i = 0; i < accel_; ++i) {
      const int t = (j + i + lag_ + 1) % n_;
      rows_[i] = MuAt(t);
      values_[i] = f.slopes(t, i);
    }
    if (smooth_) {
      rows_[accel_] = EtaAt(Before(j)), values_[accel_] = 1.0;
      rows_[accel_ + 1] = EtaAt(j), values_[accel_ + 1] = -2.0;
      rows_[accel_ + 2] = EtaAt(After(j)), values_[accel_ + 2] = 1.0;
    }
    // Each unordered pair once (Add puts it in the lower triangle), twice where two terms
    // fall in the same row (a > T: the ordered pairs (i, k) and (k, i) both count there).
    for (int i = 0; i < entries; ++i) {
      if (values_[i] == 0.0) continue;
      for (int k = 0; k <= i; ++k) {
        if (values_[k] == 0.0) continue;
        const double product = values_[i] * values_[k];
        system_.Add(rows_[i], rows_[k], k != i && rows_[k] == rows_[i] ? 2.0 * product : product);
      }
    }
  }

  // mu_ = -(B e, L R), the right-hand side of the system in (mu, eta).
  void SetRightHandSide(const SensitivityFactors& f, std::span<const double> error,
                        std::span<const double> requests) {
    mu_.resize(system_.size());
    for (int t = 0; t < n_; ++t) {
      mu_[MuAt(t)] = -(error[t] - f.alphas[t] * error[Before(t)]);
      if (smooth_) mu_[EtaAt(t)] = -SecondDifference(requests, t);
    }
  }

  // x = U_F^T mu (+ L_F^T eta) from the solved (mu, eta) in mu_.
  void StepFromMultipliers(const SensitivityFactors& f, std::span<const int> free,
                           Eigen::VectorXd& x) const {
    x.resize(static_cast<Eigen::Index>(free.size()));
    for (std::size_t q = 0; q < free.size(); ++q) {
      const int j = free[q];
      double sum = 0.0;
      for (int i = 0; i < accel_; ++i) {
        const int t = (j + i + lag_ + 1) % n_;
        sum += f.slopes(t, i) * mu_[MuAt(t)];
      }
      if (smooth_) {
        sum += mu_[EtaAt(Before(j))] - 2.0 * mu_[EtaAt(j)] + mu_[EtaAt(After(j))];
      }
      x[static_cast<Eigen::Index>(q)] = sum;
    }
  }

  int n_ = 0;
  int lag_ = 0;
  int accel_ = 0;
  bool smooth_ = false;
  CyclicBandedCholesky system_;
  std::vector<int> rows_;
  std::vector<double> values_;
  Eigen::VectorXd mu_;
};

}  // namespace leglab::optimal_requests_internal
