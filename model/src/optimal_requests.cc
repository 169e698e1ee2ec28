#include "leglab/model/optimal_requests.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "banded_step_solver.h"
#include "leglab/model/cyclic_banded_cholesky.h"
#include "periodic_model.h"

namespace leglab {
namespace {

// The smoothing is quartered from stage to stage while it is at least this fraction of theta_0.
constexpr double kLastSmoothingTheta0 = 1e-3;
// A smoothed stage only warms up the next one: it stops once a step gains less than this.
constexpr double kSmoothedStageToleranceDeg = 1e-6;

using optimal_requests_internal::BandedStepSolver;
using optimal_requests_internal::PeriodicModel;
using optimal_requests_internal::SecondDifference;
using optimal_requests_internal::SensitivityFactors;
using optimal_requests_internal::Wrap;

void RequireFinite(std::span<const double> values, const char* what) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument(std::string("optimal requests: ") + what + "[" +
                                  std::to_string(i) + "] is not finite");
    }
  }
}

// sum_t w_t (angles_t - desired_t)^2, w_t = 1 when `weights` is empty.
double SumOfSquares(std::span<const double> angles, std::span<const double> desired,
                    std::span<const double> weights) {
  double sum = 0.0;
  for (std::size_t t = 0; t < angles.size(); ++t) {
    const double e = angles[t] - desired[t];
    sum += weights.empty() ? e * e : weights[t] * e * e;
  }
  return sum;
}

struct Iterate {
  std::vector<double> requests;
  std::vector<double> angles;
  double cost = 0.0;  // sum of (weighted) squared errors, plus the move suppression
};

// The move suppression's weight, lambda * mean(w) (see request_smoothing); 0 when it is off.
double MoveSuppression(const OptimalRequestsOptions& options) {
  if (!(options.request_smoothing > 0.0)) return 0.0;
  double mean = 1.0;
  if (!options.weights.empty()) {
    double sum = 0.0;
    for (double w : options.weights) sum += w;
    mean = sum / static_cast<double>(options.weights.size());
  }
  return options.request_smoothing * mean;
}

Iterate Evaluate(const JointModelParams& params, std::vector<double> requests, double smoothing,
                 std::span<const double> desired, std::span<const double> weights,
                 double suppression = 0.0) {
  Iterate it;
  it.angles = PeriodicModel(params, requests, smoothing, false).SteadyState();
  it.cost = SumOfSquares(it.angles, desired, weights);
  if (suppression > 0.0) it.cost += suppression * SumOfSquaredSecondDifferences(requests);
  it.requests = std::move(requests);
  return it;
}

// Where request s acts: the angles M(t-1) it is compared with, t = s + l + 1 .. s + l + a.
// Returns their least and greatest.
std::pair<double, double> WindowRange(const JointModelParams& p, std::span<const double> angles,
                                      int s) {
  const int n = static_cast<int>(angles.size());
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    const double c = angles[(s + i - 1) % n];
    lo = std::min(lo, c);
    hi = std::max(hi, c);
  }
  return {lo, hi};
}

// Moves every request that no term of eq. 3 sees in f's linear range (a dead request: f is
// +-v_max for every term it enters) to the nearest point where one term is at the edge of
// that range, without entering it. The f values, hence the trajectory, do not change, but
// the request can act again at first order (from the inside of the edge).
void PullBackDeadRequests(const JointModelParams& p, std::span<const double> angles,
                          const OptimalRequestsOptions& options, std::vector<double>& requests) {
  const int n = static_cast<int>(requests.size());
  const double th = p.theta0_deg;
  for (int s = 0; s < n; ++s) {
    const double r = requests[s];
    double below = -std::numeric_limits<double>::infinity();  // nearest edge <= r
    double above = std::numeric_limits<double>::infinity();   // nearest edge >= r
    bool live = false;
    for (int i = p.lag_ticks + 1; i <= p.lag_ticks + p.accel_ticks && !live; ++i) {
      const double c = angles[(s + i - 1) % n];
      if (r > c - th && r < c + th) live = true;
      if (c + th <= r) below = std::max(below, c + th);
      if (c - th >= r) above = std::min(above, c - th);
    }
    if (live) continue;
    const bool below_ok = below >= options.lower_deg;
    const bool above_ok = above <= options.upper_deg;
    if (below_ok && (!above_ok || r - below <= above - r)) {
      requests[s] = below;
    } else if (above_ok) {
      requests[s] = above;
    }
  }
}

// One stage of the optimisation: f smoothed by `smoothing` (0: eq. 2 exactly), stopped when a
// step gains less than `tolerance_deg` of RMS error.
struct Stage {
  double smoothing = 0.0;
  double tolerance_deg = 0.0;
};

// Projected Levenberg-Marquardt on the sum of squared errors of the model of a Stage, from an
// iterate evaluated with that model; every accepted step lowers that sum.
//
// With f exact the objective is piecewise quadratic: while no term x_ti = R(t-i) - M(t-1) of
// eq. 3 crosses a kink +-theta_0, M_ss is affine in R and the Gauss-Newton model is exact. A
// step that fails because it crosses kinks is therefore retried up to the first crossing
// (a ratio test, as in active-set methods), where the model still holds and the cost must
// fall; the next linearisation then puts each term sitting on a kink on the side the step
// moves it to. So the iterate pivots from piece to piece instead of crawling towards a kink
// with ever shorter damped steps.
class StageMinimiser {
 public:
  StageMinimiser(const JointModelParams& params, std::span<const double> desired,
                 const OptimalRequestsOptions& options, const Stage& stage)
      : params_(params),
        desired_(desired),
        options_(options),
        stage_(stage),
        weights_(options.weights),
        n_(static_cast<int>(desired.size())),
        suppression_(MoveSuppression(options)),
        rms_scale_(std::sqrt(static_cast<double>(n_))),
        exact_(stage.smoothing == 0.0),
        kink_width_(1e-9 * (1.0 + params.theta0_deg)),
        jacobian_(n_, n_),
        gauss_newton_(n_, n_),
        normal_(n_, n_),
        damped_(n_, n_),
        factor_(n_),
        residual_(n_),
        gradient_(n_),
        g_free_(n_),
        step_(n_),
        full_step_(n_),
        angle_step_(n_),
        box_lo_(n_),
        box_hi_(n_),
        saturated_at_kink_(static_cast<std::size_t>(n_) * params.accel_ticks, 0),
        error_(n_) {
    free_.reserve(n_);
    if (suppression_ > 0.0) suppression_normal_ = SuppressionNormal();
  }

  // Steps `it` until a step gains less than the stage's tolerance or `budget` sensitivities
  // are used; returns how many it used.
  int Run(int budget, Iterate& it) {
    it_ = &it;
    int used = 0;
    while (used < budget) {
      const PeriodicModel model(params_, it.requests, stage_.smoothing, /*closed_kinks=*/exact_);
      const bool any_free = Linearise(model);
      ++used;
      if (!any_free || !Step(model)) break;
    }
    return used;
  }

 private:
  // lambda' L^T L, L the cyclic second difference: move suppression lambda' |L R|^2 adds it to
  // the Gauss-Newton matrix and lambda' L^T L R to the half gradient (the banded solve keeps
  // them as rows of its own, see BandedStepSolver).
  Eigen::MatrixXd SuppressionNormal() const {
    const int n = n_;
    Eigen::MatrixXd second(n, n);
    second.setZero();
    for (int t = 0; t < n; ++t) {
      second(t, Wrap(t + 1, n)) += 1.0;
      second(t, t) -= 2.0;
      second(t, Wrap(t - 1, n)) += 1.0;
    }
    return suppression_ * (second.transpose() * second);
  }

  // w_t, the objective's weight of tick t (1 without weights).
  double Weight(int t) const { return weights_.empty() ? 1.0 : weights_[t]; }
  // The fall of the RMS error from squared error `from` to `to`.
  double RmsGain(double from, double to) const {
    return (std::sqrt(from) - std::sqrt(std::max(to, 0.0))) / rms_scale_;
  }
  // Tick t's index in the cycle.
  int Index(int t) const { return Wrap(t, n_); }
  // Term x_ti of eq. 3 at the iterate, and its linearised change under the step.
  double Term(int t, int i) const {
    return it_->requests[Index(t - i)] - it_->angles[Index(t - 1)];
  }
  double TermChange(int t, int i) const {
    return full_step_[Index(t - i)] - angle_step_[Index(t - 1)];
  }
  // Whether term (t, i) is linearised as saturated (MarkKinksCrossedOutward).
  bool ForcedSaturated(int t, int i) const {
    const int l = params_.lag_ticks;
    return saturated_at_kink_[static_cast<std::size_t>(t) * params_.accel_ticks + i - l - 1] != 0;
  }

  // Linearises at the iterate and solves the first damped step, twice with f exact when the
  // step carries terms on a kink outward (they are then linearised as saturated). False when
  // every request is held at its box.
  bool Linearise(const PeriodicModel& model) {
    std::fill(saturated_at_kink_.begin(), saturated_at_kink_.end(), 0);
    for (int pass = 0; pass < 2; ++pass) {
      LineariseOnce(model);
      if (free_.empty()) return false;
      SetDampingScale();
      SolveStep(model);
      if (!exact_ || !MarkKinksCrossedOutward()) break;
    }
    return true;
  }

  // The sensitivity (and, for the dense solve, the normal matrix), the gradient and the
  // requests' boxes at the iterate.
  void LineariseOnce(const PeriodicModel& model) {
    banded_now_ = options_.structured_solve;
    model.Sensitivity(it_->angles, jacobian_, exact_ ? &saturated_at_kink_ : nullptr,
                      banded_now_ ? nullptr : &gauss_newton_, weights_,
                      banded_now_ ? &factors_ : nullptr);
    if (!banded_now_ && suppression_ > 0.0) gauss_newton_ += suppression_normal_;
    if (banded_now_) {
      for (int t = 0; t < n_; ++t) error_[t] = it_->angles[t] - desired_[t];
    }
    // The weighted residual W (M - D): the gradient of the cost's half is S^T W (M - D).
    for (int t = 0; t < n_; ++t) residual_[t] = Weight(t) * (it_->angles[t] - desired_[t]);
    gradient_.noalias() = jacobian_.transpose() * residual_;
    if (suppression_ > 0.0) {
      gradient_.noalias() +=
          suppression_normal_ * Eigen::Map<const Eigen::VectorXd>(it_->requests.data(), n_);
    }
    SetBoxes();
  }

  // Each request's box: the joint limits, and the range where it acts at the current
  // trajectory (widened by the smoothing): beyond it a step would only waste its length.
  // A request at its box that the gradient pushes outward stays there (projected step).
  void SetBoxes() {
    const double th = params_.theta0_deg;
    free_.clear();
    for (int s = 0; s < n_; ++s) {
      const auto [lo, hi] = WindowRange(params_, it_->angles, s);
      const double r = it_->requests[s];
      box_lo_[s] = std::max(options_.lower_deg, std::min(lo - th - stage_.smoothing, r));
      box_hi_[s] = std::min(options_.upper_deg, std::max(hi + th + stage_.smoothing, r));
      const bool held =
          (r <= box_lo_[s] && gradient_[s] > 0.0) || (r >= box_hi_[s] && gradient_[s] < 0.0);
      if (!held) free_.push_back(s);
    }
    const int m = FreeCount();
    g_free_.resize(m);
    for (int k = 0; k < m; ++k) g_free_[k] = gradient_[free_[k]];
  }

  // How many requests the step may move.
  int FreeCount() const { return static_cast<int>(free_.size()); }

  // The damping's scale: the largest diagonal entry of the free requests' normal matrix.
  void SetDampingScale() {
    const int m = FreeCount();
    if (!banded_now_) {
      FormNormal();
      scale_ = std::max(normal_.diagonal().maxCoeff(), 1e-12);
      return;
    }
    // The diagonal, sum_t w_t S(t, j)^2 (+ lambda' (L^T L)_jj = 6 lambda'), from S's columns.
    double largest = 0.0;
    for (int k = 0; k < m; ++k) {
      double sum = 6.0 * suppression_;
      for (int t = 0; t < n_; ++t) {
        const double v = jacobian_(t, free_[k]);
        sum += Weight(t) * v * v;
      }
      largest = std::max(largest, sum);
    }
    scale_ = std::max(largest, 1e-12);
  }

  // The dense normal matrix of the free requests (when the banded solve is not used).
  void FormNormal() {
    const int m = FreeCount();
    normal_.resize(m, m);
    for (int k = 0; k < m; ++k) {
      for (int q = 0; q < m; ++q) normal_(q, k) = gauss_newton_(free_[q], free_[k]);
    }
  }

  // The damped step at the current damping: step_ on the free requests, full_step_ on all
  // (0 where held), angle_step_ the linearised change of M_ss.
  void SolveStep(const PeriodicModel& model) {
    if (banded_now_ &&
        !banded_.Solve(params_, factors_, weights_, std::span<const double>(error_.data(), n_),
                       free_, damping_ * scale_, step_, suppression_, it_->requests)) {
      // Not applicable here: the dense normal matrix after all (the same S, bit for bit).
      banded_now_ = false;
      model.Sensitivity(it_->angles, jacobian_, exact_ ? &saturated_at_kink_ : nullptr,
                        &gauss_newton_, weights_);
      if (suppression_ > 0.0) gauss_newton_ += suppression_normal_;
      FormNormal();
    }
    if (!banded_now_) {
      damped_ = normal_;
      damped_.diagonal().array() += damping_ * scale_;
      factor_.compute(damped_);
      step_.resize(FreeCount());
      step_ = -factor_.solve(g_free_);
    }
    full_step_.setZero();
    for (int k = 0; k < FreeCount(); ++k) full_step_[free_[k]] = step_[k];
    angle_step_.noalias() = jacobian_ * full_step_;
  }

  // Terms on a kink that the step carries outward, into saturation: marks them to be
  // re-linearised as saturated (the closed convention took them as linear). Whether any was.
  bool MarkKinksCrossedOutward() {
    const int l = params_.lag_ticks;
    const int a = params_.accel_ticks;
    const double th = params_.theta0_deg;
    bool changed = false;
    for (int t = 0; t < n_; ++t) {
      for (int i = l + 1; i <= l + a; ++i) {
        const double x = Term(t, i);
        if (std::abs(std::abs(x) - th) > kink_width_) continue;
        if (x * TermChange(t, i) > 0.0) {
          saturated_at_kink_[static_cast<std::size_t>(t) * a + i - l - 1] = 1;
          changed = true;
        }
      }
    }
    return changed;
  }

  // step^T S_F^T W S_F step (+ the move suppression's curvature), the Gauss-Newton model's.
  double Curvature() const {
    if (!banded_now_) return step_.dot(normal_ * step_);
    double curvature = 0.0;
    for (int t = 0; t < n_; ++t) curvature += Weight(t) * angle_step_[t] * angle_step_[t];
    if (suppression_ > 0.0) {
      const std::span<const double> moved(full_step_.data(), n_);
      for (int t = 0; t < n_; ++t) {
        const double d = SecondDifference(moved, t);
        curvature += suppression_ * d * d;
      }
    }
    return curvature;
  }

  // Raises the damping until a step lowers the true cost; stops once even the Gauss-Newton
  // model of the damped step promises less than the tolerance. Whether the iterate moved by
  // at least the tolerance (or pivoted onto a kink, from where the next piece may go further).
  bool Step(const PeriodicModel& model) {
    for (bool first = true;; first = false) {
      if (!first) SolveStep(model);
      const double predicted = -g_free_.dot(step_) - 0.5 * Curvature();
      if (!(RmsGain(it_->cost, it_->cost - 2.0 * predicted) >= stage_.tolerance_deg)) {
        return false;
      }
      Iterate candidate = Moved(1.0);
      if (candidate.cost < it_->cost) {
        const bool improved = RmsGain(it_->cost, candidate.cost) >= stage_.tolerance_deg;
        *it_ = std::move(candidate);
        damping_ = std::max(damping_ / 3.0, 1e-9);
        return improved;
      }
      if (exact_ && Pivot()) return true;
      damping_ *= 4.0;
    }
  }

  // The iterate moved by `fraction` of the step, clamped into the boxes, and evaluated. (A
  // fraction of 1 moves by the step itself: x * 1.0 is x exactly.)
  Iterate Moved(double fraction) const {
    std::vector<double> moved = it_->requests;
    for (int s = 0; s < n_; ++s) {
      moved[s] = std::clamp(moved[s] + fraction * full_step_[s], box_lo_[s], box_hi_[s]);
    }
    return Evaluate(params_, std::move(moved), stage_.smoothing, desired_, weights_, suppression_);
  }

  // With f exact, after a step failed: moves to its first kink crossing if that lowers the
  // cost (the linear model holds up to there). Whether it moved.
  bool Pivot() {
    const double fraction = BreakpointFraction();
    if (!(fraction > 0.0 && fraction < 1.0)) return false;
    Iterate at_kink = Moved(fraction);
    if (!(at_kink.cost < it_->cost)) return false;
    *it_ = std::move(at_kink);
    return true;
  }

  // The largest fraction of the step that crosses no kink and leaves no box.
  double BreakpointFraction() const {
    const int l = params_.lag_ticks;
    const int a = params_.accel_ticks;
    const double th = params_.theta0_deg;
    double fraction = 1.0;
    for (int t = 0; t < n_; ++t) {
      for (int i = l + 1; i <= l + a; ++i) {
        const double x = Term(t, i);
        const double dx = TermChange(t, i);
        if (!ForcedSaturated(t, i) && std::abs(x) <= th) {  // linear: until it reaches either kink
          if (dx > 0.0) fraction = std::min(fraction, (th - x) / dx);
          if (dx < 0.0) fraction = std::min(fraction, (-th - x) / dx);
        } else if (x > 0.0 && dx < 0.0) {  // saturated high: until it comes back to theta_0
          fraction = std::min(fraction, (x - th) / -dx);
        } else if (x < 0.0 && dx > 0.0) {
          fraction = std::min(fraction, (-th - x) / dx);
        }
      }
    }
    for (int s = 0; s < n_; ++s) {
      const double r = it_->requests[s];
      if (full_step_[s] > 0.0) fraction = std::min(fraction, (box_hi_[s] - r) / full_step_[s]);
      if (full_step_[s] < 0.0) fraction = std::min(fraction, (box_lo_[s] - r) / full_step_[s]);
    }
    return std::max(fraction, 0.0);
  }

  const JointModelParams& params_;
  std::span<const double> desired_;
  const OptimalRequestsOptions& options_;
  const Stage& stage_;
  std::span<const double> weights_;
  int n_;
  double suppression_;  // lambda' (see MoveSuppression)
  double rms_scale_;    // sqrt(T)
  bool exact_;          // f exact (the stage's smoothing 0)
  double kink_width_;   // how near +-theta_0 a term counts as on the kink
  Iterate* it_ = nullptr;
  double damping_ = 1e-3;
  double scale_ = 0.0;  // the damping's scale (SetDampingScale)
  // Work space, allocated once a stage.
  Eigen::MatrixXd suppression_normal_;  // lambda' L^T L
  Eigen::MatrixXd jacobian_;
  Eigen::MatrixXd gauss_newton_;  // jacobian^T W jacobian (+ lambda' L^T L)
  Eigen::MatrixXd normal_;        // its rows and columns of the free requests
  Eigen::MatrixXd damped_;
  Eigen::LDLT<Eigen::MatrixXd> factor_;
  Eigen::VectorXd residual_;
  Eigen::VectorXd gradient_;
  Eigen::VectorXd g_free_;
  Eigen::VectorXd step_;
  Eigen::VectorXd full_step_;   // step on every request (0 where held)
  Eigen::VectorXd angle_step_;  // the linearised change of M_ss
  std::vector<double> box_lo_;
  std::vector<double> box_hi_;
  std::vector<int> free_;
  std::vector<char> saturated_at_kink_;
  // options.structured_solve: each step from BandedStepSolver, no T x T normal matrix.
  SensitivityFactors factors_;
  BandedStepSolver banded_;
  Eigen::VectorXd error_;  // M_ss - D
  bool banded_now_ = false;
};

// StageMinimiser on `it` with at most `budget` sensitivities; returns how many it used.
int MinimiseStage(const JointModelParams& params, std::span<const double> desired,
                  const OptimalRequestsOptions& options, const Stage& stage, int budget,
                  Iterate& it) {
  return StageMinimiser(params, desired, options, stage).Run(budget, it);
}

void Validate(std::span<const double> desired, const JointModelParams& params,
              std::span<const double> initial, const OptimalRequestsOptions& options) {
  ValidateJointModelParams(params);
  if (desired.empty()) throw std::invalid_argument("optimal requests: the desired cycle is empty");
  if (initial.size() != desired.size()) {
    throw std::invalid_argument("optimal requests: " + std::to_string(desired.size()) +
                                " desired angles but " + std::to_string(initial.size()) +
                                " initial requests");
  }
  RequireFinite(desired, "desired_deg");
  RequireFinite(initial, "initial_requests_deg");
  if (std::isnan(options.lower_deg) || std::isnan(options.upper_deg) ||
      options.lower_deg > options.upper_deg) {
    throw std::invalid_argument("optimal requests: need lower_deg <= upper_deg, got " +
                                std::to_string(options.lower_deg) + " and " +
                                std::to_string(options.upper_deg));
  }
  if (!options.weights.empty() && options.weights.size() != desired.size()) {
    throw std::invalid_argument("optimal requests: " + std::to_string(desired.size()) +
                                " desired angles but " + std::to_string(options.weights.size()) +
                                " weights");
  }
  if (std::string problem =
          KeysProblem(options, [](KeyVisitor& v, OptimalRequestsOptions& o) { VisitKeys(v, o); });
      !problem.empty()) {
    throw std::invalid_argument("optimal requests: " + problem);
  }
}

}  // namespace

void VisitKeys(KeyVisitor& v, OptimalRequestsOptions& options) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  v.Key("max_iterations", options.max_iterations,
        {.min = 1, .max = 1e6, .description = "sensitivity evaluations at most, over all stages"});
  v.Key("tolerance_deg", options.tolerance_deg, kOptimalToleranceDoc);
  v.Key("smoothing_theta0", options.smoothing_theta0,
        {.min = 0,
         .max = kInf,
         .max_open = true,
         .description = "f's kinks rounded in the first stage, a fraction of theta_0"});
  v.Key("weights", options.weights, kObjectiveWeightDoc);
  v.Key("request_smoothing", options.request_smoothing,
        {.min = 0,
         .max = kInf,
         .max_open = true,
         .description = "move suppression on the requests' second difference, lambda"});
}

double SumOfSquaredSecondDifferences(std::span<const double> cycle) {
  double sum = 0.0;
  for (int t = 0; t < static_cast<int>(cycle.size()); ++t) {
    const double d = SecondDifference(cycle, t);
    sum += d * d;
  }
  return sum;
}

OptimalRequests OptimizeRequests(std::span<const double> desired_deg,
                                 const JointModelParams& params,
                                 std::span<const double> initial_requests_deg,
                                 const OptimalRequestsOptions& options) {
  Validate(desired_deg, params, initial_requests_deg, options);
  std::vector<double> start(initial_requests_deg.begin(), initial_requests_deg.end());
  for (double& r : start) r = std::clamp(r, options.lower_deg, options.upper_deg);
  const double suppression = MoveSuppression(options);
  const Iterate initial = Evaluate(params, start, 0.0, desired_deg, options.weights, suppression);

  // Smoothed stages, each a quarter of the last, then eq. 2 exactly. (With v_max > theta_0
  // the steady state is CyclicSteadyState's iteration, for f exact only: no smoothing.)
  std::vector<Stage> stages;
  const double last_smoothing = kLastSmoothingTheta0 * params.theta0_deg;
  double smoothing = options.smoothing_theta0 * params.theta0_deg;
  if (params.v_max_deg_per_tick > params.theta0_deg) smoothing = 0.0;
  for (; smoothing >= last_smoothing; smoothing /= 4.0) {
    stages.push_back({smoothing, std::max(options.tolerance_deg, kSmoothedStageToleranceDeg)});
  }
  stages.push_back({0.0, options.tolerance_deg});

  Iterate it = initial;
  double evaluated_with = 0.0;  // the smoothing `it` was evaluated with
  int used = 0;
  for (std::size_t k = 0; k < stages.size() && used < options.max_iterations; ++k) {
    const int remaining = options.max_iterations - used;
    const int stages_left = static_cast<int>(stages.size() - k);
    // Dead requests are moved to the edge of f's linear range (exactly neutral for f exact).
    if (k == 0) PullBackDeadRequests(params, it.angles, options, it.requests);
    // (Evaluate is deterministic: `it` is kept when it is already this evaluation.)
    if (stages[k].smoothing != evaluated_with || it.requests != initial.requests) {
      it = Evaluate(params, std::move(it.requests), stages[k].smoothing, desired_deg,
                    options.weights, suppression);
      evaluated_with = stages[k].smoothing;
    }
    used += MinimiseStage(params, desired_deg, options, stages[k],
                          std::max(1, remaining / stages_left), it);
  }
  // Scored with f exact (the last stage's model, unless the budget ran out before it), and
  // never worse than the start.
  if (evaluated_with != 0.0) {
    it = Evaluate(params, std::move(it.requests), 0.0, desired_deg, options.weights, suppression);
  }
  if (!(it.cost <= initial.cost)) it = initial;

  // The tracking error alone (the cost also holds the move suppression when it is on).
  const double tracking =
      suppression > 0.0 ? SumOfSquares(it.angles, desired_deg, options.weights) : it.cost;
  OptimalRequests result;
  result.requests_deg = std::move(it.requests);
  result.steady_state_deg = std::move(it.angles);
  result.rms_error_deg = std::sqrt(tracking / static_cast<double>(desired_deg.size()));
  result.iterations = used;
  return result;
}

namespace {

// S = d M_ss / d R at the model's steady state under `requests_deg`, and S^T S when `normal`.
Eigen::MatrixXd SensitivityAtSteadyState(const JointModelParams& params,
                                         std::span<const double> requests_deg,
                                         Eigen::MatrixXd* normal,
                                         std::span<const double> row_weights = {}) {
  ValidateJointModelParams(params);
  if (requests_deg.empty()) throw std::invalid_argument("optimal requests: the cycle is empty");
  RequireFinite(requests_deg, "requests_deg");
  if (!row_weights.empty() && row_weights.size() != requests_deg.size()) {
    throw std::invalid_argument("optimal requests: " + std::to_string(requests_deg.size()) +
                                " requests but " + std::to_string(row_weights.size()) +
                                " row weights");
  }
  for (std::size_t t = 0; t < row_weights.size(); ++t) {
    if (const std::string problem = KeyValueProblem(row_weights[t], kObjectiveWeightDoc);
        !problem.empty()) {
      throw std::invalid_argument("optimal requests: row_weights[" + std::to_string(t) +
                                  "] must be " + problem + ", got " +
                                  FormatNumber(row_weights[t], NumberStyle::kReadable));
    }
  }
  const PeriodicModel model(params, requests_deg, 0.0, false);
  Eigen::MatrixXd sensitivity;
  model.Sensitivity(model.SteadyState(), sensitivity, nullptr, normal, row_weights);
  return sensitivity;
}

}  // namespace

Eigen::MatrixXd SteadyStateSensitivity(const JointModelParams& params,
                                       std::span<const double> requests_deg) {
  return SensitivityAtSteadyState(params, requests_deg, nullptr);
}

Eigen::VectorXd StructuredDampedStep(const JointModelParams& params,
                                     std::span<const double> requests_deg,
                                     std::span<const double> desired_deg,
                                     std::span<const double> weights, std::span<const int> free,
                                     double damping, double suppression) {
  ValidateJointModelParams(params);
  if (requests_deg.empty() || desired_deg.size() != requests_deg.size() ||
      (!weights.empty() && weights.size() != requests_deg.size())) {
    throw std::invalid_argument("optimal requests: sizes of the step's inputs differ");
  }
  RequireFinite(requests_deg, "requests_deg");
  RequireFinite(desired_deg, "desired_deg");
  RequireFinite(weights, "weights");
  if (const std::string problem = KeyValueProblem(damping, kStepDampingDoc); !problem.empty()) {
    throw std::invalid_argument("optimal requests: the step's damping must be " + problem +
                                ", got " + FormatNumber(damping, NumberStyle::kReadable));
  }
  if (const std::string problem = KeyValueProblem(suppression, kStepSuppressionDoc);
      !problem.empty()) {
    throw std::invalid_argument("optimal requests: the step's suppression must be " + problem +
                                ", got " + FormatNumber(suppression, NumberStyle::kReadable));
  }
  for (const int j : free) {
    if (j < 0 || j >= static_cast<int>(requests_deg.size())) {
      throw std::invalid_argument("optimal requests: free request " + std::to_string(j) +
                                  " is not in the cycle");
    }
  }
  const PeriodicModel model(params, requests_deg, 0.0, false);
  const std::vector<double> angles = model.SteadyState();
  Eigen::MatrixXd sensitivity;
  SensitivityFactors factors;
  model.Sensitivity(angles, sensitivity, nullptr, nullptr, {}, &factors);
  std::vector<double> error(angles.size());
  for (std::size_t t = 0; t < angles.size(); ++t) error[t] = angles[t] - desired_deg[t];
  Eigen::VectorXd step;
  BandedStepSolver banded;
  if (!banded.Solve(params, factors, weights, error, free, damping, step, suppression,
                    requests_deg)) {
    return {};
  }
  return step;
}

Eigen::MatrixXd SteadyStateNormalMatrix(const JointModelParams& params,
                                        std::span<const double> requests_deg,
                                        std::span<const double> row_weights) {
  Eigen::MatrixXd normal;
  SensitivityAtSteadyState(params, requests_deg, &normal, row_weights);
  return normal;
}

}  // namespace leglab
