#include "leglab/model/piecewise_linear.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

#include "leglab/model/joint_model.h"
#include "leglab/model/metrics.h"

namespace leglab {
namespace {

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("piecewise-linear fit: " + what);
}

void ValidateInput(std::span<const double> desired, double v_max) {
  if (desired.size() < 2) Fail("the desired trajectory needs at least 2 samples");
  for (size_t t = 0; t < desired.size(); ++t) {
    if (!std::isfinite(desired[t])) Fail("desired sample " + std::to_string(t) + " is not finite");
  }
  if (const std::string problem = KeyValueProblem(v_max, kAnyJointModel.v_max_deg_per_tick);
      !problem.empty()) {
    Fail("v_max must be " + problem + ", got " + FormatNumber(v_max, NumberStyle::kReadable));
  }
}

// One slope bound: values[to] - values[from] <= bound.
struct DifferenceBound {
  int from;
  int to;
  double bound;
};

// Minimises 0.5 p'Hp + g'p subject to the difference bounds, by the primal active-set method
// (Nocedal & Wright, Algorithm 16.3) from the feasible start `p` (all differences zero). The
// bounds are positive, so that start is strictly feasible; a blocking bound is never a
// combination of the active ones, so the working set's rows stay independent.
//
// Each iteration's equality-constrained step solves the KKT system [H A'; A 0] [s; mu] =
// [-(Hp + g); 0] (A the working set's rows, e_to - e_from) by its Schur complement: H is
// symmetric positive definite (a breakpoint's own tick weighs only its value), so with H^-1,
// formed with the normal equations (once a breakpoint set, PwlFitCache), u = H^-1 (Hp + g), (A H^-1
// A') mu = -A u and s = -(u + H^-1 A' mu). A H^-1 A' is m x m and its entries are four of H^-1's
// each: O(n^2 + n m + m^3) an iteration instead of a dense (n + m) x (n + m) factorisation. The
// same iterates as that factorisation in exact arithmetic.
Eigen::VectorXd SolveSlopeQp(const Eigen::MatrixXd& hessian, const Eigen::MatrixXd& inverse,
                             const Eigen::VectorXd& gradient0,
                             const std::vector<DifferenceBound>& bounds, Eigen::VectorXd p) {
  const int n = static_cast<int>(p.size());
  const int num_bounds = static_cast<int>(bounds.size());
  std::vector<int> active;
  std::vector<char> is_active(bounds.size(), 0);
  auto row_times = [&](int j, const auto& x) { return x[bounds[j].to] - x[bounds[j].from]; };
  const int max_iterations = 20 * (num_bounds + n) + 100;
  // Work space kept across iterations.
  Eigen::VectorXd u(n), step(n), residual(n);
  Eigen::MatrixXd schur;
  Eigen::VectorXd multipliers;
  Eigen::LLT<Eigen::MatrixXd> llt;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    const int m = static_cast<int>(active.size());
    residual.noalias() = hessian * p;
    residual += gradient0;
    u.noalias() = inverse * residual;
    step = -u;
    multipliers.resize(m);
    if (m > 0) {
      schur.resize(m, m);
      for (int r = 0; r < m; ++r) {
        const DifferenceBound& a = bounds[active[r]];
        for (int c = 0; c <= r; ++c) {
          const DifferenceBound& b = bounds[active[c]];
          schur(r, c) = schur(c, r) = inverse(a.to, b.to) - inverse(a.to, b.from) -
                                      inverse(a.from, b.to) + inverse(a.from, b.from);
        }
        multipliers[r] = -row_times(active[r], u);
      }
      llt.compute(schur);
      multipliers = llt.solve(multipliers);
      for (int r = 0; r < m; ++r) {  // s -= H^-1 A' mu, A's row r being e_to - e_from
        const DifferenceBound& a = bounds[active[r]];
        step -= multipliers[r] * (inverse.col(a.to) - inverse.col(a.from));
      }
    }

    if (step.lpNorm<Eigen::Infinity>() <= 1e-13 * (1.0 + p.lpNorm<Eigen::Infinity>())) {
      // Stationary on the working set: optimal unless a multiplier is negative.
      if (m == 0 || multipliers.minCoeff() >= -1e-12) return p;
      Eigen::Index worst = 0;
      multipliers.minCoeff(&worst);
      is_active[active[worst]] = 0;
      active.erase(active.begin() + worst);
      continue;
    }
    double alpha = 1.0;
    int blocking = -1;
    for (int j = 0; j < num_bounds; ++j) {
      if (is_active[j]) continue;
      const double rate = row_times(j, step);
      if (rate <= 0.0) continue;
      const double room = std::max(0.0, bounds[j].bound - row_times(j, p));
      if (room / rate < alpha) {
        alpha = room / rate;
        blocking = j;
      }
    }
    p += alpha * step;
    if (blocking >= 0) {
      active.push_back(blocking);
      is_active[blocking] = 1;
    }
  }
  // Each iteration adds or drops one bound and the objective never rises, so this is a bug.
  throw std::logic_error("piecewise-linear fit: the slope QP did not converge");
}

}  // namespace

struct PwlFitCache::NormalEquations {
  Eigen::MatrixXd hessian;    // A^T A
  Eigen::MatrixXd inverse;    // (A^T A)^-1, for the slope QP's steps
  Eigen::VectorXd gradient0;  // -A^T D
};

namespace {

// The fit's checks of the breakpoints (FitPiecewiseLinearAt's contract).
void ValidateBreakpoints(const std::vector<int>& breakpoints, int period) {
  if (breakpoints.empty()) Fail("at least one breakpoint is needed");
  const KeyDoc in_period = WithRange(kPwlBreakpointDoc, 0, period - 1);
  for (size_t k = 0; k < breakpoints.size(); ++k) {
    if (const std::string problem = KeyValueProblem(breakpoints[k], in_period); !problem.empty()) {
      Fail("breakpoint " + std::to_string(k) + " must be " + problem + ", got " +
           std::to_string(breakpoints[k]));
    }
    if (k > 0 && breakpoints[k] <= breakpoints[k - 1]) {
      Fail("breakpoints must strictly increase, breakpoint " + std::to_string(k) + " does not");
    }
  }
}

// P = A p with A's rows the hat-function weights of each tick: A^T A and -A^T D. A row of A has
// its non-zeros in two adjacent columns (k and k + 1 mod n), so A^T A is summed tick by tick
// from 2 x 2 pieces, O(T) instead of the dense product's O(T n^2), summed in the product's order
// so that it gives the product's bits (see docs/design/optimal-requests.md).
PwlFitCache::NormalEquations FormNormalEquations(std::span<const double> desired,
                                                 const PiecewiseLinear& pwl) {
  const int period = pwl.period_ticks;
  const int n = pwl.num_segments();
  PwlFitCache::NormalEquations normal{Eigen::MatrixXd::Zero(n, n), {}, {}};
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(period, n);
  // The segment of each tick walked in order (as Sample): before the first breakpoint, the
  // wrapping last one.
  int k = n - 1;
  int following = 0;
  double length = pwl.SegmentLength(k);
  for (int t = 0; t < period; ++t) {
    if (following < n && pwl.breakpoints_tick[following] <= t) {
      while (following < n && pwl.breakpoints_tick[following] <= t) k = following++;
      length = pwl.SegmentLength(k);
    }
    long offset = t - pwl.breakpoints_tick[k];
    if (offset < 0) offset += period;
    const double lambda = static_cast<double>(offset) / length;
    const int next = (k + 1) % n;
    basis(t, k) += 1.0 - lambda;
    basis(t, next) += lambda;
    const double wk = basis(t, k);
    const double wn = basis(t, next);
    normal.hessian(k, k) += wk * wk;
    if (next != k) {  // one segment: its single column holds both weights
      normal.hessian(k, next) += wk * wn;
      normal.hessian(next, k) += wn * wk;
      normal.hessian(next, next) += wn * wn;
    }
  }
  const Eigen::Map<const Eigen::VectorXd> d(desired.data(), period);
  normal.gradient0 = -basis.transpose() * d;
  normal.inverse = normal.hessian.llt().solve(Eigen::MatrixXd::Identity(n, n));
  return normal;
}

// FitPiecewiseLinearAt, with the normal equations from `cache` when given.
// The caller has validated `desired` and `v_max` (ValidateInput).
PiecewiseLinear FitAt(std::span<const double> desired, double v_max, std::vector<int> breakpoints,
                      PwlFitCache* cache) {
  const int period = static_cast<int>(desired.size());
  ValidateBreakpoints(breakpoints, period);
  std::shared_ptr<const PwlFitCache::NormalEquations> shared;
  if (cache != nullptr) shared = cache->Get(desired, breakpoints);
  PiecewiseLinear pwl{period, std::move(breakpoints), {}};
  const int n = pwl.num_segments();
  PwlFitCache::NormalEquations own;
  if (shared == nullptr) own = FormNormalEquations(desired, pwl);
  const PwlFitCache::NormalEquations& normal = shared != nullptr ? *shared : own;

  std::vector<DifferenceBound> bounds;
  if (n >= 2) {
    for (int k = 0; k < n; ++k) {
      const double bound = v_max * pwl.SegmentLength(k);
      bounds.push_back({k, (k + 1) % n, bound});
      bounds.push_back({(k + 1) % n, k, bound});
    }
  }
  const Eigen::Map<const Eigen::VectorXd> d(desired.data(), period);
  const Eigen::VectorXd start = Eigen::VectorXd::Constant(n, d.mean());
  const Eigen::VectorXd p =
      SolveSlopeQp(normal.hessian, normal.inverse, normal.gradient0, bounds, start);
  pwl.values_deg.assign(p.data(), p.data() + n);
  return pwl;
}

// The positions of `breakpoints` taken modulo T, sorted; empty if two coincide.
std::vector<int> Normalized(std::vector<int> breakpoints, int period) {
  for (int& b : breakpoints) b = ((b % period) + period) % period;
  std::sort(breakpoints.begin(), breakpoints.end());
  if (std::adjacent_find(breakpoints.begin(), breakpoints.end()) != breakpoints.end()) return {};
  return breakpoints;
}

std::vector<int> EvenlySpaced(int segments, int period, int phase) {
  std::vector<int> breakpoints(segments);
  for (int k = 0; k < segments; ++k) {
    breakpoints[k] = phase + static_cast<int>(static_cast<long>(k) * period / segments);
  }
  return Normalized(breakpoints, period);
}

struct Candidate {
  PiecewiseLinear pwl;
  double rms_deg = std::numeric_limits<double>::infinity();
};

Candidate Evaluate(std::span<const double> desired, double v_max, std::vector<int> breakpoints,
                   PwlFitCache* cache) {
  Candidate c;
  c.pwl = FitAt(desired, v_max, std::move(breakpoints), cache);
  c.rms_deg = PwlRmsError(c.pwl, desired);
  return c;
}

// Evaluate, remembered: the descents from different phases keep meeting the same breakpoints,
// and a fit depends on nothing else (see docs/design/optimal-requests.md).
class EvaluationMemo {
 public:
  EvaluationMemo(std::span<const double> desired, double v_max, PwlFitCache* cache)
      : desired_(desired), v_max_(v_max), cache_(cache) {}
  const Candidate& operator()(const std::vector<int>& breakpoints) {
    auto it = fits_.find(breakpoints);
    if (it == fits_.end()) {
      it = fits_.emplace(breakpoints, Evaluate(desired_, v_max_, breakpoints, cache_)).first;
    }
    return it->second;
  }

 private:
  std::span<const double> desired_;
  double v_max_;
  PwlFitCache* cache_;
  std::map<std::vector<int>, Candidate> fits_;
};

// Coordinate descent from `start`: moves one breakpoint at a time by a shrinking step while
// the error falls.
Candidate Descend(EvaluationMemo& evaluate, Candidate best, int spacing, int period) {
  const int segments = best.pwl.num_segments();
  for (int step = std::max(1, spacing / 2); step >= 1; step /= 2) {
    bool improved = true;
    while (improved) {
      improved = false;
      for (int k = 0; k < segments; ++k) {
        for (int direction : {-1, 1}) {
          std::vector<int> moved = best.pwl.breakpoints_tick;
          moved[k] += direction * step;
          moved = Normalized(moved, period);
          if (moved.empty()) continue;
          const Candidate& c = evaluate(moved);
          if (c.rms_deg < best.rms_deg - 1e-12) {
            best = c;
            improved = true;
            break;
          }
        }
      }
    }
  }
  return best;
}

// The best of the descents that start from every phase of evenly spaced breakpoints.
Candidate FitWithSegments(std::span<const double> desired, double v_max, int segments,
                          PwlFitCache* cache) {
  const int period = static_cast<int>(desired.size());
  const int spacing = std::max(1, period / segments);
  EvaluationMemo evaluate(desired, v_max, cache);
  Candidate best;
  for (int phase = 0; phase < spacing; ++phase) {
    Candidate start = evaluate(EvenlySpaced(segments, period, phase));
    if (segments > 1) start = Descend(evaluate, std::move(start), spacing, period);
    if (start.rms_deg < best.rms_deg) best = std::move(start);
  }
  return best;
}

// t modulo the period in [0, period): ((t % period) + period) % period, without its two integer
// divisions for a t already in range (every call of the fits' inner loops).
long InCycle(long t, long period) {
  return t >= 0 && t < period ? t : ((t % period) + period) % period;
}

}  // namespace

int PiecewiseLinear::SegmentLength(int k) const {
  assert(k >= 0 && k < num_segments());
  const int next =
      k + 1 < num_segments() ? breakpoints_tick[k + 1] : breakpoints_tick[0] + period_ticks;
  return next - breakpoints_tick[k];
}

double PiecewiseLinear::Slope(int k) const {
  const double next = values_deg[(k + 1) % num_segments()];
  return (next - values_deg[k]) / SegmentLength(k);
}

int PiecewiseLinear::SegmentAt(long t) const {
  const long r = InCycle(t, period_ticks);
  const auto it = std::upper_bound(breakpoints_tick.begin(), breakpoints_tick.end(), r);
  return it == breakpoints_tick.begin() ? num_segments() - 1
                                        : static_cast<int>(it - breakpoints_tick.begin()) - 1;
}

double PiecewiseLinear::At(long t) const {
  const long r = InCycle(t, period_ticks);
  const int k = SegmentAt(r);
  long offset = r - breakpoints_tick[k];
  if (offset < 0) offset += period_ticks;
  return values_deg[k] + Slope(k) * static_cast<double>(offset);
}

std::vector<double> PiecewiseLinear::Sample() const {
  // At(t) for t = 0 .. T-1, walking the segments in order instead of searching for each tick's
  // (the same segment, offset and slope, so the same bits).
  std::vector<double> samples(period_ticks);
  if (period_ticks <= 0) return samples;
  const int n = num_segments();
  int k = n - 1;  // before the first breakpoint: the wrapping last segment
  int next = 0;
  double slope = Slope(k);
  for (int t = 0; t < period_ticks; ++t) {
    if (next < n && breakpoints_tick[next] <= t) {
      while (next < n && breakpoints_tick[next] <= t) k = next++;
      slope = Slope(k);
    }
    long offset = static_cast<long>(t) - breakpoints_tick[k];
    if (offset < 0) offset += period_ticks;
    samples[t] = values_deg[k] + slope * static_cast<double>(offset);
  }
  return samples;
}

PiecewiseLinear FitPiecewiseLinearAt(std::span<const double> desired, double v_max,
                                     std::vector<int> breakpoints) {
  ValidateInput(desired, v_max);
  return FitAt(desired, v_max, std::move(breakpoints), nullptr);
}

std::shared_ptr<const PwlFitCache::NormalEquations> PwlFitCache::Get(
    std::span<const double> desired, const std::vector<int>& breakpoints) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (desired_.empty()) desired_.assign(desired.begin(), desired.end());
  if (!std::equal(desired_.begin(), desired_.end(), desired.begin(), desired.end())) return nullptr;
  auto it = entries_.find(breakpoints);
  if (it == entries_.end()) {
    const PiecewiseLinear pwl{static_cast<int>(desired.size()), breakpoints, {}};
    it = entries_
             .emplace(breakpoints,
                      std::make_shared<const NormalEquations>(FormNormalEquations(desired, pwl)))
             .first;
  }
  return it->second;
}

void VisitKeys(KeyVisitor& v, PwlFitOptions& options) {
  v.Key("segments", options.segments,
        WithDescription(WithRange(kPwlSegmentsDoc, 0, kPwlSegmentsDoc.max),
                        "segments of the fit; 0 fits the fewest that meet tolerance_deg"));
  v.Key("tolerance_deg", options.tolerance_deg,
        {.min = 0,
         .min_open = true,
         .unit = "deg",
         .description = "tolerance mode: the largest acceptable RMS error to D"});
  v.Key("max_segments", options.max_segments,
        WithDescription(kPwlSegmentsDoc, "tolerance mode: give up beyond this many segments"));
}

PiecewiseLinear FitPiecewiseLinear(std::span<const double> desired, double v_max,
                                   const PwlFitOptions& options, PwlFitCache* cache) {
  ValidateInput(desired, v_max);
  const int period = static_cast<int>(desired.size());
  if (std::string problem =
          KeysProblem(options, [](KeyVisitor& v, PwlFitOptions& o) { VisitKeys(v, o); });
      !problem.empty()) {
    Fail(problem);
  }
  if (options.segments != 0) {
    const KeyDoc in_period = WithRange(kPwlSegmentsDoc, 1, period);
    if (const std::string problem = KeyValueProblem(options.segments, in_period);
        !problem.empty()) {
      Fail("segments must be " + problem + " (the ticks of the cycle), got " +
           std::to_string(options.segments));
    }
    return FitWithSegments(desired, v_max, options.segments, cache).pwl;
  }
  const int max_segments = std::min(options.max_segments, period);
  double best_rms = std::numeric_limits<double>::infinity();
  for (int segments = 1; segments <= max_segments; ++segments) {
    Candidate c = FitWithSegments(desired, v_max, segments, cache);
    if (c.rms_deg <= options.tolerance_deg) return c.pwl;
    best_rms = std::min(best_rms, c.rms_deg);
  }
  std::ostringstream msg;
  msg << "no fit within " << options.tolerance_deg << " deg RMS with up to " << max_segments
      << " segments (best " << best_rms << " deg): the trajectory may be faster than v_max allows";
  Fail(msg.str());
}

void ValidatePiecewiseLinearInput(std::span<const double> desired, double v_max) {
  ValidateInput(desired, v_max);
}

double PwlRmsError(const PiecewiseLinear& pwl, std::span<const double> desired) {
  const std::vector<double> samples = pwl.Sample();
  return RmsDistance(samples, desired);
}

}  // namespace leglab
