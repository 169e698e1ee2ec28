#pragma once

#include <Eigen/Core>
#include <limits>
#include <span>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/model/joint_model.h"

namespace leglab {

/// Limits and stopping rules of OptimizeRequests.
struct OptimalRequestsOptions {
  /// The joint limits, deg: every request stays in [lower_deg, upper_deg].
  double lower_deg = -std::numeric_limits<double>::infinity();
  double upper_deg = std::numeric_limits<double>::infinity();
  /// Sensitivity evaluations (Gauss-Newton linearisations) at most, over all stages (>= 1).
  int max_iterations = 200;
  /// The exact stage stops when a step lowers the RMS error by less than this, deg, or when
  /// the Gauss-Newton model of the step promises less. (The smoothed stages, which only warm
  /// it up, stop at max(tolerance_deg, 1e-6 deg).)
  double tolerance_deg = 1e-9;
  /// How far f's kinks are rounded in the first stage, as a fraction of theta_0; 0 optimises
  /// eq. 2 exactly from the start. See OptimizeRequests.
  double smoothing_theta0 = 0.25;
  /// Per-tick weights w_t >= 0 of the objective, size T; empty (the default): every tick 1.
  /// The objective is then sum_t w_t (M_ss(t) - D(t))^2 and every "RMS" (the tolerance's and
  /// OptimalRequests::rms_error_deg) is sqrt of that over T. Used by ILC's foot-space
  /// objective, where w_t is how much the joint moves the foot at tick t.
  std::vector<double> weights;
  /// Solve each damped Gauss-Newton step from the sensitivity's structure (a cyclic banded
  /// system, O(T a^2 + a T^2)) instead of the dense T x T normal matrix and its factorisation
  /// (O(T^2 a + T^3)); the same step up to rounding, so the iterates may differ in the last
  /// digits. With request_smoothing too (a system twice the size, still banded). Falls back to
  /// the dense solve where it does not apply (a weight of 0, every term of the cycle
  /// saturated). Off by default; ILC's per-step updates and optimal's offline cycles (the joint
  /// optimum and the foot objective's sweeps) use it.
  bool structured_solve = false;
  /// Move suppression on the requests' second difference, lambda >= 0: the objective gains
  /// lambda * mean(w) * sum_t (R(t+1) - 2 R(t) + R(t-1))^2 (cyclic; mean(w) = 1 without
  /// weights), as extra least-squares rows of every Gauss-Newton step and of the objective a
  /// step must lower. It picks, among the many request cycles that track equally well (a
  /// request deep in saturation has no effect), the one whose requests do not chatter tick to
  /// tick. 0 (the default): the objective above, bit for bit. OptimalRequests::rms_error_deg is
  /// still the tracking error alone.
  double request_smoothing = 0.0;
};

/// The declared range of a tick's weight w_t in an objective (OptimalRequestsOptions::weights,
/// SteadyStateNormalMatrix's row_weights): finite and not negative.
inline constexpr KeyDoc kObjectiveWeightDoc{.min = 0,
                                            .max = std::numeric_limits<double>::infinity(),
                                            .max_open = true,
                                            .description = "a tick's weight w_t in the objective"};

/// The declared range of OptimalRequestsOptions::tolerance_deg (and of the joint optimum's
/// tolerance the optimal mode passes on): finite and not negative.
inline constexpr KeyDoc kOptimalToleranceDoc{
    .min = 0,
    .max = std::numeric_limits<double>::infinity(),
    .max_open = true,
    .unit = "deg",
    .description = "the exact stage stops when a step gains less RMS error than this"};

/// OptimalRequestsOptions' values with their ranges, what OptimizeRequests checks (with the
/// limits' order, lower_deg <= upper_deg, and the weights' count).
void VisitKeys(KeyVisitor& visitor, OptimalRequestsOptions& options);

/// The declared ranges of StructuredDampedStep's damping (positive, finite) and suppression
/// (finite, not negative).
inline constexpr KeyDoc kStepDampingDoc{.min = 0,
                                        .max = std::numeric_limits<double>::infinity(),
                                        .min_open = true,
                                        .max_open = true,
                                        .description = "the step's damping mu"};
inline constexpr KeyDoc kStepSuppressionDoc{.min = 0,
                                            .max = std::numeric_limits<double>::infinity(),
                                            .max_open = true,
                                            .description = "the step's move suppression"};

/// sum_t (R(t+1) - 2 R(t) + R(t-1))^2 over the cycle R(0..T-1) (indices mod T): what
/// request_smoothing suppresses, deg^2.
double SumOfSquaredSecondDifferences(std::span<const double> cycle);

/// The optimised request cycle and what the model does under it.
struct OptimalRequests {
  std::vector<double> requests_deg;      ///< R(0..T-1)
  std::vector<double> steady_state_deg;  ///< the model's cyclic steady state under R
  double rms_error_deg = 0.0;            ///< RMS of steady_state - D over the cycle (weighted)
  int iterations = 0;                    ///< sensitivity evaluations used
};

/// The request cycle R that minimises the RMS distance between the model's cyclic steady
/// state under R (eqs. 2-3 exactly; the steady state CyclicSteadyState converges to, no
/// piecewise-linear approximation) and the desired cycle D(0..T-1), deg, starting from
/// `initial_requests_deg` (size T; e.g. the paper's model-based requests) clamped into
/// [lower_deg, upper_deg], and never worse than that start. A local method: it reaches the
/// exhaustive-search optimum of small cycles (tests), but the objective is not convex and
/// from a poor start it may stop in a worse local minimum than from the model-based requests.
/// Deterministic: the same input gives the same bits.
///
/// Method: projected Levenberg-Marquardt on the residual M_ss(R) - D, with the analytic
/// sensitivity of SteadyStateSensitivity as Jacobian; a step is taken only if it lowers the
/// true objective, and requests are clamped into the limits (a request at a limit that the
/// gradient pushes outward is held there). Two features of eq. 2 shape the rest:
///  - Kinks. f is piecewise linear, so while no term x = R(t-i) - M(t-1) of eq. 3 crosses
///    +-theta_0, M_ss is affine in R: the objective is piecewise quadratic. Plain LM on it
///    stalls where the optimum lies on a kink (most optima of a speed-limited D do: top-speed
///    requests sit at the edge of saturation), zig-zagging across with ever shorter steps. So
///    the optimisation first runs on a smooth surrogate of f with the kinks rounded over
///    s = smoothing_theta0 * theta_0, f_s(x) = (k/2)(sqrt((x + theta_0)^2 + s^2) -
///    sqrt((x - theta_0)^2 + s^2)), k = v_max / theta_0, s quartered stage by stage down to
///    1e-3 theta_0; then on f exactly, where a step that fails across kinks is retried up to
///    its first kink crossing (a ratio test, where the linear model is still exact), and the
///    next linearisation puts a term sitting on a kink on the side the step moves it to.
///  - Flat regions. A request all of whose a terms are saturated (|x| >= theta_0) has no
///    first-order effect (its column of the Jacobian is 0), and LM's damping would leave it
///    where it is for good. Before the first stage every such request is moved to the nearest
///    point where one of its terms is at the edge of f's linear range: that changes no value
///    of f, so not the trajectory, and from there the request acts again (the exact stage
///    linearises a term on a kink as linear unless the step carries it outward). Each step
///    also keeps every request within the range where it acts at the current trajectory
///    (widened by s), so that no step throws one deep into saturation; the smoothed f keeps a
///    small slope there, so a request near the edge keeps a small effect.
/// Both features are needed to reach the exhaustive optimum of small cycles; see
/// docs/design/optimal-requests.md.
///
/// Throws std::invalid_argument on bad parameters, an empty or non-finite D or start, sizes
/// that differ, lower_deg > upper_deg, max_iterations < 1, or a negative tolerance or
/// smoothing; std::runtime_error as CyclicSteadyState when the model does not settle (v_max at
/// least 2 theta_0 can swing for ever, SettlesOnEveryCycle).
OptimalRequests OptimizeRequests(std::span<const double> desired_deg,
                                 const JointModelParams& params,
                                 std::span<const double> initial_requests_deg,
                                 const OptimalRequestsOptions& options = {});

/// d M_ss / d R: the sensitivity (T x T; row t = steady-state angle at t, column s = request
/// at s) of the model's cyclic steady state (eq. 3, as CyclicSteadyState) to each request of
/// the cycle R(0..T-1), deg/deg, at `requests_deg`. Computed exactly by differentiating eq. 3
/// round the cycle, S(t) = alpha_t S(t-1) + (1/a) sum_i f'(x_ti) e_{t-i} with alpha_t =
/// 1 - (1/a) sum_i f'(x_ti), and solving for the periodic solution. Where a term sits exactly
/// on a kink of f (x = +-theta_0) it takes the slope of the branch eq. 2 evaluates there, 0:
/// one-sided, from the saturated side. Where every term of the cycle is saturated the model
/// has a whole interval of steady states, of which CyclicSteadyState's moves with the mean
/// request: every entry is then 1/T. Every row sums to 1 (R + c gives M + c).
/// ILC uses it as its learning filter.
/// Throws std::invalid_argument on bad parameters or an empty or non-finite cycle.
Eigen::MatrixXd SteadyStateSensitivity(const JointModelParams& params,
                                       std::span<const double> requests_deg);

/// S^T W S for S = SteadyStateSensitivity(params, requests_deg) and W = diag(row_weights)
/// (empty: the identity): the Gauss-Newton matrix OptimizeRequests factors at every
/// linearisation, computed from the recursion that defines S in O(T^2 a) operations instead of
/// the product's O(T^3) (see the derivation at PeriodicModel::NormalMatrix in
/// optimal_requests.cc). Equal to the product up to rounding.
/// Throws as SteadyStateSensitivity, and std::invalid_argument when row_weights is neither
/// empty nor of the cycle's size, or not finite and >= 0.
Eigen::MatrixXd SteadyStateNormalMatrix(const JointModelParams& params,
                                        std::span<const double> requests_deg,
                                        std::span<const double> row_weights = {});

/// The damped Gauss-Newton step of OptimizeRequests with structured_solve (exposed for tests):
/// x (size |free|) minimising sum_t w_t (M_ss(t) - D(t) + (S_F x)(t))^2 + damping |x|^2 +
/// suppression |L (R + P_F x)|^2, with M_ss the model's cyclic steady state under R =
/// `requests_deg`, S_F the columns `free` of SteadyStateSensitivity there, w_t = `weights`
/// (empty: 1), L the cyclic second difference and P_F x the step placed at the free requests
/// (the move suppression, lambda * mean(w) for request_smoothing lambda; 0: none), solved from
/// the sensitivity's cyclic banded structure without forming S^T W S. Empty where that solve
/// does not apply (a weight not positive, every term of the cycle saturated). Throws
/// std::invalid_argument on bad parameters, sizes that differ, non-finite input (weights
/// included), a damping that is not positive and finite, a suppression that is negative or not
/// finite, or a free index outside the cycle.
Eigen::VectorXd StructuredDampedStep(const JointModelParams& params,
                                     std::span<const double> requests_deg,
                                     std::span<const double> desired_deg,
                                     std::span<const double> weights, std::span<const int> free,
                                     double damping, double suppression = 0.0);

}  // namespace leglab
