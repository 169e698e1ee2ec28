#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include "leglab/core/config_keys.h"

namespace leglab {

/// A cyclic, continuous piecewise-linear trajectory P over one period of T ticks (section
/// 4.1): values at integer breakpoint ticks, joined by straight segments. Segment k runs from
/// breakpoints_tick[k] to breakpoints_tick[k + 1]; the last wraps round to
/// breakpoints_tick[0] + T. One breakpoint is a constant trajectory.
struct PiecewiseLinear {
  int period_ticks = 0;               ///< T
  std::vector<int> breakpoints_tick;  ///< strictly increasing, in [0, T)
  std::vector<double> values_deg;     ///< P at each breakpoint

  /// Number of segments (= number of breakpoints).
  int num_segments() const { return static_cast<int>(breakpoints_tick.size()); }
  /// Length of segment k, ticks.
  int SegmentLength(int k) const;
  /// Slope of segment k, deg/tick.
  double Slope(int k) const;
  /// The segment that contains tick t (any integer; taken modulo T), i.e. the k with
  /// breakpoints_tick[k] <= t mod T < breakpoints_tick[k + 1] (cyclically).
  int SegmentAt(long t) const;
  /// P(t), deg, for any integer t (taken modulo T).
  double At(long t) const;
  /// P(0), ..., P(T - 1), deg.
  std::vector<double> Sample() const;
};

/// How many segments a fit uses: a fixed number, or the fewest that meet a tolerance.
struct PwlFitOptions {
  int segments = 8;            ///< number of segments (1 to T); 0 selects the tolerance mode
  double tolerance_deg = 1.0;  ///< tolerance mode: the largest acceptable RMS error to D
  int max_segments = 32;       ///< tolerance mode: give up beyond this many segments
};

/// The declared range of an approximation's number of segments (controller.pwl_segments, a
/// fixed-count fit's segments); a fit of T ticks further takes at most T.
inline constexpr KeyDoc kPwlSegmentsDoc{
    .min = 1,
    .max = 1000,
    .description =
        "segments of each joint's piecewise-linear approximation P; at most "
        "track.t_step_ticks"};

/// The declared range of a breakpoint's tick; in a fit of T ticks, [0, T - 1].
inline constexpr KeyDoc kPwlBreakpointDoc{.min = 0, .max = 1000, .unit = "ticks"};

/// PwlFitOptions' values with their ranges (segments 0 or kPwlSegmentsDoc's, a positive
/// tolerance, max_segments from 1), what FitPiecewiseLinear checks.
void VisitKeys(KeyVisitor& visitor, PwlFitOptions& options);

/// Least-squares values at fixed breakpoints: minimises the sum over t of (P(t) - D(t))^2
/// subject to |slope| <= v_max on every segment (a small convex QP, solved exactly by an
/// active-set method). `desired_deg` is one period D(0..T-1).
/// Throws std::invalid_argument on bad breakpoints (unsorted, repeated, outside [0, T)),
/// a non-finite D, T < 2 or v_max <= 0.
PiecewiseLinear FitPiecewiseLinearAt(std::span<const double> desired_deg, double v_max_deg_per_tick,
                                     std::vector<int> breakpoints_tick);

/// What the fits of one desired cycle D share whatever v_max: each breakpoint set's
/// least-squares normal equations (A^T A and A^T D, which do not depend on v_max). Passed to
/// the fits of the same D under several v_max (the controller contexts of two models), they
/// are formed once; every result is the same bits as without the cache. Thread-safe. A fit
/// of another D than the first one it served does not use it.
class PwlFitCache {
 public:
  struct NormalEquations;
  /// The normal equations of `breakpoints` for `desired` (formed now unless already there);
  /// null when the cache serves another D.
  std::shared_ptr<const NormalEquations> Get(std::span<const double> desired_deg,
                                             const std::vector<int>& breakpoints_tick);

 private:
  std::mutex mutex_;
  std::vector<double> desired_;
  std::map<std::vector<int>, std::shared_ptr<const NormalEquations>> entries_;
};

/// Automatic piecewise-linear approximation of a cyclic D (the paper drew its by hand):
/// breakpoints chosen to reduce the RMS error to D, every slope within +-v_max, values
/// optimal for them (FitPiecewiseLinearAt). The breakpoint search is a multi-start local
/// search, not an exhaustive one: from every phase of evenly spaced breakpoints it moves one
/// breakpoint at a time while the error falls, and keeps the best. So the result is never
/// worse than evenly spaced breakpoints, but it may miss the global optimum.
/// Throws std::invalid_argument on bad input, or in tolerance mode when no fit with up to
/// max_segments segments reaches the tolerance (the message gives the best error found).
PiecewiseLinear FitPiecewiseLinear(std::span<const double> desired_deg, double v_max_deg_per_tick,
                                   const PwlFitOptions& options = {}, PwlFitCache* cache = nullptr);

/// Throws std::invalid_argument as the fits do on bad input (T < 2, a non-finite D, v_max not
/// positive); the fits' own checks, for callers that fit later.
void ValidatePiecewiseLinearInput(std::span<const double> desired_deg, double v_max_deg_per_tick);

/// RMS distance between P and D over one period, deg.
double PwlRmsError(const PiecewiseLinear& pwl, std::span<const double> desired_deg);

}  // namespace leglab
