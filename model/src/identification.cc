#include "leglab/model/identification.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>

#include "leglab/model/levenberg_marquardt.h"
#include "leglab/model/nelder_mead.h"
#include "paper_sensitivity_lanes.h"

namespace leglab {
namespace {

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("identification: " + what);
}

// For each tick j, the last tick of the run of equal requests that contains it. A step test's
// requests are constant for half a step, so eq. 3's window of a requests holds one or two
// distinct values: summing f once per run instead of once per request makes a tick cost O(1)
// instead of O(a). (Only the rounding of the sum changes: count * f instead of f + ... + f.)
std::vector<int> RunEnds(std::span<const double> requests_deg) {
  const auto n = static_cast<long>(requests_deg.size());
  std::vector<int> end(requests_deg.size());
  for (long t = n - 1; t >= 0; --t) {
    end[t] =
        (t + 1 < n && requests_deg[t] == requests_deg[t + 1]) ? end[t + 1] : static_cast<int>(t);
  }
  return end;
}

// Runs eq. 3 over ticks warmup..N-1 from M(warmup - 1) = `start_angle_deg` (the requests
// before `warmup` as its memory) and propagates, alongside the angle, its forward sensitivities
// to ln v_max, ln theta_0 and the start angle. Calls on_tick(t, M(t), dM/d ln v_max,
// dM/d ln theta_0, dM/d start) for every tick.
//
// Differentiating M(t) = M(t-1) + (1/a) sum_i f(R(t-i) - M(t-1)), with f = v_max clamp(x /
// theta_0, -1, 1): df/d ln v_max = f everywhere; df/d ln theta_0 = -f and df/dx = v_max /
// theta_0 where f is linear, both 0 where it saturates. So, with K the number of unsaturated
// terms and F_lin their sum,
//   s_v(t) = s_v(t-1) (1 - K v_max / (a theta_0)) + (1/a) sum_i f,
//   s_theta(t) = s_theta(t-1) (1 - K v_max / (a theta_0)) - F_lin / a,
//   s_start(t) = s_start(t-1) (1 - K v_max / (a theta_0)),   s_start(warmup - 1) = 1.
// At a kink (x = +-theta_0 exactly) these are the derivatives from the saturated side.
template <typename OnTick>
void SweepWithSensitivities(const JointModelParams& p, std::span<const double> request_deg,
                            std::span<const int> run_end, int warmup, double start_angle_deg,
                            OnTick&& on_tick) {
  const double v_max = p.v_max_deg_per_tick;
  const double theta0 = p.theta0_deg;
  const double gain = v_max / theta0;
  // One multiplication instead of a division on the chain from tick to tick.
  const double inv_a = 1.0 / p.accel_ticks;
  const long n = static_cast<long>(request_deg.size());
  double angle = start_angle_deg;
  double d_v = 0.0;
  double d_theta = 0.0;
  double d_start = 1.0;
  for (long t = warmup; t < n; ++t) {
    // The window R(t-l-a) .. R(t-l-1), a run of equal requests at a time.
    double speed_sum = 0.0;
    double linear_sum = 0.0;
    double unsaturated = 0.0;
    const long last = t - p.lag_ticks - 1;
    for (long j = last - p.accel_ticks + 1; j <= last;) {
      const long end = std::min<long>(run_end[j], last);
      const auto count = static_cast<double>(end - j + 1);
      const double x = request_deg[j] - angle;
      if (x >= theta0) {
        speed_sum += count * v_max;
      } else if (x <= -theta0) {
        speed_sum -= count * v_max;
      } else {
        const double f = count * (x * gain);
        speed_sum += f;
        linear_sum += f;
        unsaturated += count;
      }
      j = end + 1;
    }
    const double decay = 1.0 - unsaturated * gain * inv_a;
    d_v = d_v * decay + speed_sum * inv_a;
    d_theta = d_theta * decay - linear_sum * inv_a;
    d_start *= decay;
    angle += speed_sum * inv_a;
    on_tick(t, angle, d_v, d_theta, d_start);
  }
}

// Whether the fit may go to a point: exp of the fit's logarithms gave a model at all (a joint
// that hardly moves drives ln v_max towards -infinity, or ln theta_0 towards +infinity, where
// exp underflows to 0 or overflows), and one that settles with a margin (v_max <=
// kMaxFittedSpeedRatio theta_0). Any other point scores +infinity: no step or polish takes the
// fit there, and where the unconstrained optimum lies beyond the ratio the fit stops at it.
bool Admissible(const JointModelParams& p) {
  return std::isnormal(p.v_max_deg_per_tick) && std::isnormal(p.theta0_deg) &&
         p.v_max_deg_per_tick <= kMaxFittedSpeedRatio * p.theta0_deg;
}

// One recording, ready for the fit.
struct Prepared {
  const JointRecording* recording;
  std::vector<int> run_end;
};

// The least-squares fit of v_max and theta_0 (on their logarithms, so they stay positive) for
// fixed l and a, and optionally each recording's start offset: x = (ln v_max, ln theta_0,
// offset_0, ...). Owns its work space, so that an evaluation allocates nothing.
class ContinuousFit {
 public:
  // Not copied: lanes_ refers to swept_.
  ContinuousFit(const ContinuousFit&) = delete;
  ContinuousFit& operator=(const ContinuousFit&) = delete;

  ContinuousFit(std::span<const Prepared> recordings, int warmup, bool fit_starts)
      : recordings_(recordings),
        warmup_(warmup),
        fit_starts_(fit_starts),
        n_(2 + (fit_starts ? static_cast<int>(recordings.size()) : 0)),
        solver_(n_) {
    // Where requests change about every tick (a servo's log), the sweeps in lanes; where they
    // are held (a step test), the scalar sweep's one visit per run is cheaper. Lanes on AVX2
    // only: GCC's baseline code for them is slower than the scalar sweep (fit_lanes_benchmark).
    // The same bits either way.
    size_t ticks = 0, runs = 0;
    for (const Prepared& r : recordings) {
      swept_.push_back({r.recording, r.run_end});
      ticks += r.run_end.size();
      for (size_t t = 0; t < r.run_end.size(); ++t) runs += r.run_end[t] == static_cast<int>(t);
    }
    if (ticks < 2 * runs && instructions_ == LaneInstructions::kAvx2) {
      lanes_.emplace(swept_, warmup);
    }
  }

  // Sum of squared errors of the prediction at x, and into `jtj` and `jte` the Gauss-Newton
  // normal equations J^T J and J^T e (J = dM/dx, e = measured - M).
  double Evaluate(const JointModelParams& lag_accel, const Eigen::VectorXd& x, Eigen::MatrixXd& jtj,
                  Eigen::VectorXd& jte) const {
    JointModelParams p = lag_accel;
    p.v_max_deg_per_tick = std::exp(x[0]);
    p.theta0_deg = std::exp(x[1]);
    jtj.setZero();
    jte.setZero();
    if (!Admissible(p)) return std::numeric_limits<double>::infinity();
    if (lanes_) {
      lanes_->Accumulate(p,
                         fit_starts_ ? std::span<const double>(x.data() + 2, recordings_.size())
                                     : std::span<const double>(),
                         fit_starts_, equations_, instructions_);
    }
    double sum = 0.0;
    for (size_t k = 0; k < recordings_.size(); ++k) {
      const long s = 2 + static_cast<long>(k);
      const PaperNormalEquations q = lanes_        ? equations_[k]
                                     : fit_starts_ ? Accumulate<true>(p, k, x[s])
                                                   : Accumulate<false>(p, k, 0.0);
      // The recording's weight (exactly 1 by default: w * v == v, the same bits).
      const double w = recordings_[k].recording->weight;
      sum += w * q.squared_error;
      jtj(0, 0) += w * q.vv, jtj(0, 1) += w * q.vt, jtj(1, 1) += w * q.tt;
      jte(0) += w * q.ve, jte(1) += w * q.te;
      if (fit_starts_) {
        jtj(0, s) = w * q.vs, jtj(1, s) = w * q.ts, jtj(s, s) = w * q.ss;
        jte(s) = w * q.se;
      }
    }
    jtj.triangularView<Eigen::StrictlyLower>() = jtj.transpose();
    return sum;
  }

  // Sum of squared errors of the prediction at x alone.
  double SquaredError(const JointModelParams& lag_accel, const double* x) const {
    JointModelParams p = lag_accel;
    p.v_max_deg_per_tick = std::exp(x[0]);
    p.theta0_deg = std::exp(x[1]);
    if (!Admissible(p)) return std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (size_t k = 0; k < recordings_.size(); ++k) {
      const JointRecording& r = *recordings_[k].recording;
      const double offset = fit_starts_ ? x[2 + k] : 0.0;
      const double w = r.weight;
      SweepWithSensitivities(p, r.request_deg, recordings_[k].run_end, warmup_,
                             r.measured_deg[warmup_ - 1] + offset,
                             [&](long t, double angle, double, double, double) {
                               const double e = r.measured_deg[t] - angle;
                               sum += w * e * e;  // (w * e) * e: e * e itself when w is 1
                             });
    }
    return sum;
  }

  // Levenberg-Marquardt on x at fixed (l, a) = `lag_accel` (see LevenbergMarquardt): a run
  // from x, resumed, or run to the end.
  LevenbergMarquardt::Run Start(const JointModelParams& lag_accel, const Eigen::VectorXd& x) {
    return solver_.Start(Objective(lag_accel), x);
  }
  void Continue(const JointModelParams& lag_accel, LevenbergMarquardt::Run& run,
                double relative_tolerance, int max_iterations) {
    solver_.Continue(Objective(lag_accel), run, relative_tolerance, max_iterations);
  }
  double Minimise(const JointModelParams& lag_accel, Eigen::VectorXd& x, double relative_tolerance,
                  int max_iterations) {
    return solver_.Minimise(Objective(lag_accel), x, relative_tolerance, max_iterations);
  }

 private:
  // Sweeps recording k. The start-offset terms only when `kStarts`: fewer accumulators keep
  // the tick loop in registers.
  template <bool kStarts>
  PaperNormalEquations Accumulate(const JointModelParams& p, size_t k, double offset) const {
    const JointRecording& r = *recordings_[k].recording;
    double sum = 0, vv = 0, vt = 0, tt = 0, vs = 0, ts = 0, ss = 0, ve = 0, te = 0, se = 0;
    SweepWithSensitivities(p, r.request_deg, recordings_[k].run_end, warmup_,
                           r.measured_deg[warmup_ - 1] + offset,
                           [&](long t, double angle, double d_v, double d_theta, double d_s) {
                             const double e = r.measured_deg[t] - angle;
                             sum += e * e;
                             vv += d_v * d_v, vt += d_v * d_theta, tt += d_theta * d_theta;
                             ve += d_v * e, te += d_theta * e;
                             if constexpr (kStarts) {
                               vs += d_v * d_s, ts += d_theta * d_s, ss += d_s * d_s;
                               se += d_s * e;
                             }
                           });
    return {sum, vv, vt, tt, vs, ts, ss, ve, te, se};
  }

  // Evaluate at fixed (l, a), as LevenbergMarquardt takes it (J^T e is -J^T r, r = M - measured).
  LeastSquaresObjective Objective(const JointModelParams& lag_accel) const {
    return [this, &lag_accel](const Eigen::VectorXd& x, Eigen::MatrixXd& jtj,
                              Eigen::VectorXd& jte) { return Evaluate(lag_accel, x, jtj, jte); };
  }

  std::span<const Prepared> recordings_;
  int warmup_;
  bool fit_starts_;
  int n_;
  LevenbergMarquardt solver_;
  std::vector<SweptRecording> swept_;
  std::optional<PaperSensitivityLanes> lanes_;
  LaneInstructions instructions_ = BestLaneInstructions();
  mutable std::vector<PaperNormalEquations> equations_;  // Evaluate's work space
};

// One candidate of the fit: the parameters and their squared error.
struct Candidate {
  JointModelParams params;
  double squared_error = std::numeric_limits<double>::infinity();
};

}  // namespace

std::vector<double> PredictRecording(const JointModelParams& p, const JointRecording& r,
                                     int warmup) {
  ValidateJointModelParams(p);
  const long n = static_cast<long>(r.request_deg.size());
  if (r.measured_deg.size() != r.request_deg.size()) Fail("request and measured lengths differ");
  if (warmup < p.lag_ticks + p.accel_ticks || warmup < 1 || warmup > n) {
    Fail("the warm-up must cover l + a ticks and fit in the recording");
  }
  std::vector<double> predicted(r.measured_deg.begin(), r.measured_deg.begin() + warmup);
  JointModelState start{r.measured_deg[warmup - 1], {}};
  for (int i = 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    start.past_requests_deg.push_back(r.request_deg[warmup - i]);
  }
  const std::vector<double> tail =
      SimulateJointModel(p, std::span(r.request_deg).subspan(warmup), start);
  predicted.insert(predicted.end(), tail.begin(), tail.end());
  return predicted;
}

PredictionSensitivities PredictRecordingSensitivities(const JointModelParams& p,
                                                      const JointRecording& r, int warmup,
                                                      double start_offset_deg) {
  ValidateJointModelParams(p);
  const long n = static_cast<long>(r.request_deg.size());
  if (r.measured_deg.size() != r.request_deg.size()) Fail("request and measured lengths differ");
  if (warmup < p.lag_ticks + p.accel_ticks || warmup < 1 || warmup > n) {
    Fail("the warm-up must cover l + a ticks and fit in the recording");
  }
  PredictionSensitivities s;
  const auto ticks = static_cast<size_t>(n - warmup);
  s.angle_deg.reserve(ticks);
  s.d_log_v_max.reserve(ticks);
  s.d_log_theta0.reserve(ticks);
  s.d_start_offset.reserve(ticks);
  SweepWithSensitivities(p, r.request_deg, RunEnds(r.request_deg), warmup,
                         r.measured_deg[warmup - 1] + start_offset_deg,
                         [&](long, double angle, double d_v, double d_theta, double d_start) {
                           s.angle_deg.push_back(angle);
                           s.d_log_v_max.push_back(d_v);
                           s.d_log_theta0.push_back(d_theta);
                           s.d_start_offset.push_back(d_start);
                         });
  return s;
}

namespace {

// The mean over the cycles of `run`'s measured angle at each tick of the cycle (AverageCycles'
// checks of the run).
std::vector<double> CycleMean(const JointRecording& run, int period_ticks) {
  if (const std::string problem = KeyValueProblem(period_ticks, kCyclePeriodDoc);
      !problem.empty()) {
    Fail("the period must be " + problem + ", got " + std::to_string(period_ticks));
  }
  if (run.request_deg.size() != run.measured_deg.size()) {
    Fail("request and measured lengths differ");
  }
  const size_t period = static_cast<size_t>(period_ticks);
  if (run.request_deg.empty() || run.request_deg.size() % period != 0) {
    Fail("the run is not whole cycles of " + std::to_string(period_ticks) + " ticks");
  }
  const size_t cycles = run.request_deg.size() / period;
  std::vector<double> mean(period, 0.0);
  for (size_t k = 0; k < cycles; ++k) {
    for (size_t t = 0; t < period; ++t) {
      if (run.request_deg[k * period + t] != run.request_deg[t]) {
        Fail("the requests differ between cycles at tick " + std::to_string(k * period + t));
      }
      mean[t] += run.measured_deg[k * period + t];
    }
  }
  for (double& m : mean) m /= static_cast<double>(cycles);
  return mean;
}

}  // namespace

double CycleScatter(const JointRecording& run, int period_ticks) {
  const std::vector<double> mean = CycleMean(run, period_ticks);
  double sum = 0.0;
  for (size_t i = 0; i < run.measured_deg.size(); ++i) {
    const double d = run.measured_deg[i] - mean[i % mean.size()];
    sum += d * d;
  }
  return run.weight * sum;
}

JointRecording AverageCycles(const JointRecording& run, int period_ticks, int warmup_ticks,
                             int played_cycles) {
  if (warmup_ticks < 0) Fail("the warm-up must not be negative");
  if (played_cycles < 1) Fail("at least one cycle must be played");
  const std::vector<double> mean = CycleMean(run, period_ticks);
  const size_t period = mean.size();
  const size_t cycles = run.request_deg.size() / period;
  JointRecording averaged;
  const size_t length =
      static_cast<size_t>(warmup_ticks) + static_cast<size_t>(played_cycles) * period;
  averaged.request_deg.resize(length);
  averaged.measured_deg.resize(length);
  // Tick i plays the cycle's tick (i - warmup) mod period.
  const size_t shift = period - static_cast<size_t>(warmup_ticks) % period;
  for (size_t i = 0; i < length; ++i) {
    const size_t t = (i + shift) % period;
    averaged.request_deg[i] = run.request_deg[t];
    averaged.measured_deg[i] = mean[t];
  }
  averaged.weight = run.weight * static_cast<double>(cycles) / static_cast<double>(played_cycles);
  return averaged;
}

namespace {

// The fit's search rules; docs/design/identification.md has the evidence for each.
// Pass 2 refits this many (l, a), the best of pass 1.
constexpr size_t kRefined = 4;
// Pass 1's first round runs every (l, a) until a step gains less than this fraction of the error.
constexpr double kScreenTolerance = 1e-2;
// Pass 1's second round stops once the kRefined-th best finished candidate is below the next
// one's screened error by more than this fraction: what finishing may still gain.
constexpr double kScreenMargin = 0.05;
// Pass 1's ranking needs only this relative tolerance: the ranking's gaps are percents.
constexpr double kRankTolerance = 1e-5;
// Pass 2's Levenberg-Marquardt runs to this relative tolerance before the polish.
constexpr double kRefineTolerance = 1e-9;
// The polish's first simplex: this step in ln v_max and ln theta_0, and in each start offset.
constexpr double kPolishStepLog = 1e-3;
constexpr double kPolishStepDeg = 1e-2;
// A candidate whose LM error is above the best polished one by more than this fraction is not
// polished: the polish gains less than that on a kink's valley floor.
constexpr double kPolishMargin = 0.05;

// Checks the recordings and prepares them for the fit. Returns the fastest measured change from
// one tick to the next in `fastest`, deg per tick, the fit's starting top speed.
std::vector<Prepared> PrepareRecordings(std::span<const JointRecording> recordings, int warmup,
                                        double& fastest) {
  fastest = 0.0;
  std::vector<Prepared> prepared;
  for (size_t k = 0; k < recordings.size(); ++k) {
    const JointRecording& r = recordings[k];
    if (r.request_deg.size() != r.measured_deg.size()) {
      Fail("recording " + std::to_string(k) + ": request and measured lengths differ");
    }
    if (!std::isfinite(r.weight) || !(r.weight > 0.0)) {
      Fail("recording " + std::to_string(k) + " has a weight that is not finite and > 0");
    }
    if (static_cast<long>(r.request_deg.size()) <= warmup) {
      Fail("recording " + std::to_string(k) + " is shorter than the warm-up of " +
           std::to_string(warmup + 1) + " ticks");
    }
    for (size_t t = 0; t < r.request_deg.size(); ++t) {
      if (!std::isfinite(r.request_deg[t]) || !std::isfinite(r.measured_deg[t])) {
        Fail("recording " + std::to_string(k) + " has a non-finite sample at tick " +
             std::to_string(t));
      }
      if (t > 0) fastest = std::max(fastest, std::abs(r.measured_deg[t] - r.measured_deg[t - 1]));
    }
    prepared.push_back({&r, RunEnds(r.request_deg)});
  }
  if (!(fastest > 0.0)) Fail("the joint never moved: nothing to identify");
  return prepared;
}

// One (l, a) of pass 1: its runs from the two starts, and the lower of their errors.
struct Screened {
  JointModelParams lag_accel;
  std::array<LevenbergMarquardt::Run, 2> runs;
  double error = 0.0;
};

// Pass 1's first round: every (l, a) of the options' ranges from both starts (v_max the
// fastest change, theta_0 1.5 and 4 times that), to kScreenTolerance.
std::vector<Screened> Screen(ContinuousFit& rank_fit, const IdentificationOptions& o,
                             double fastest) {
  std::vector<Screened> screened;
  Eigen::VectorXd x(2);
  for (int lag = o.lag_min_ticks; lag <= o.lag_max_ticks; ++lag) {
    for (int accel = o.accel_min_ticks; accel <= o.accel_max_ticks; ++accel) {
      Screened c;
      c.lag_accel = {0.0, 0.0, lag, accel};
      const double theta_factors[2] = {1.5, 4.0};
      for (int k = 0; k < 2; ++k) {
        x << std::log(fastest), std::log(fastest * theta_factors[k]);
        c.runs[k] = rank_fit.Start(c.lag_accel, x);
        rank_fit.Continue(c.lag_accel, c.runs[k], kScreenTolerance, 100);
      }
      c.error = std::min(c.runs[0].error, c.runs[1].error);
      screened.push_back(std::move(c));
    }
  }
  return screened;
}

// A finished candidate of pass 1, with its index in the (l, a) order for ties.
using Ranked = std::pair<Candidate, size_t>;

// Pass 1's second round: best screened first, runs the candidates on to kRankTolerance
// (Continue: exactly the steps of one run at that tolerance) until the kRefined-th best
// finished one is below the next one's screened error by more than kScreenMargin. Returns the
// finished candidates, the best min(kRefined, size) first in order of error, then index.
std::vector<Ranked> Rank(ContinuousFit& rank_fit, std::vector<Screened>& screened) {
  std::vector<size_t> order(screened.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return screened[a].error < screened[b].error ||
           (screened[a].error == screened[b].error && a < b);
  });
  std::vector<Ranked> ranked;
  std::vector<double> finished_errors;
  for (const size_t i : order) {
    Screened& c = screened[i];
    if (finished_errors.size() >= kRefined) {
      std::nth_element(finished_errors.begin(), finished_errors.begin() + (kRefined - 1),
                       finished_errors.end());
      if (finished_errors[kRefined - 1] < (1.0 - kScreenMargin) * c.error) break;
    }
    Candidate best_here;
    for (LevenbergMarquardt::Run& run : c.runs) {
      rank_fit.Continue(c.lag_accel, run, kRankTolerance, 100);
      if (run.error < best_here.squared_error) {
        best_here = {{std::exp(run.x[0]), std::exp(run.x[1]), c.lag_accel.lag_ticks,
                      c.lag_accel.accel_ticks},
                     run.error};
      }
    }
    finished_errors.push_back(best_here.squared_error);
    ranked.emplace_back(best_here, i);
  }
  const auto by_error = [](const Ranked& a, const Ranked& b) {
    return a.first.squared_error < b.first.squared_error ||
           (a.first.squared_error == b.first.squared_error && a.second < b.second);
  };
  const size_t refined = std::min(kRefined, ranked.size());
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<long>(refined), ranked.end(),
                    by_error);
  return ranked;
}

// A candidate of pass 2 after its Levenberg-Marquardt run.
struct Refined {
  std::vector<double> point;  // (ln v_max, ln theta_0, each recording's start offset)
  double error = 0.0;         // where LM stopped (orders the polish)
};

// Pass 2's Levenberg-Marquardt, with the start offsets (from 0), from each of the first
// `refined` ranked candidates, to kRefineTolerance.
std::vector<Refined> Refine(ContinuousFit& refine_fit, std::span<const Ranked> ranked,
                            size_t refined, size_t recordings) {
  std::vector<Refined> refined_fits(refined);
  Eigen::VectorXd with_starts = Eigen::VectorXd::Zero(2 + static_cast<long>(recordings));
  for (size_t i = 0; i < refined; ++i) {
    with_starts.setZero();
    with_starts[0] = std::log(ranked[i].first.params.v_max_deg_per_tick);
    with_starts[1] = std::log(ranked[i].first.params.theta0_deg);
    refined_fits[i].error =
        refine_fit.Minimise(ranked[i].first.params, with_starts, kRefineTolerance, 100);
    refined_fits[i].point.assign(with_starts.begin(), with_starts.end());
  }
  return refined_fits;
}

// Pass 2's polish: Nelder-Mead from each refined candidate, best LM error first, skipping those
// kPolishMargin above the best polished. Returns the best polished candidate; ties go to the
// earlier in pass 1's order.
Candidate Polish(const ContinuousFit& refine_fit, std::span<const Ranked> ranked,
                 std::vector<Refined>& refined_fits) {
  const size_t refined = refined_fits.size();
  std::vector<size_t> polish_order(refined);
  std::iota(polish_order.begin(), polish_order.end(), size_t{0});
  std::stable_sort(polish_order.begin(), polish_order.end(), [&](size_t a, size_t b) {
    return refined_fits[a].error < refined_fits[b].error;
  });
  Candidate best;
  size_t best_index = refined;
  for (const size_t i : polish_order) {
    if (best.squared_error < (1.0 - kPolishMargin) * refined_fits[i].error) break;
    std::vector<double>& point = refined_fits[i].point;
    std::vector<double> steps(point.size(), kPolishStepDeg);
    steps[0] = steps[1] = kPolishStepLog;
    const double error = NelderMead(
        [&](const std::vector<double>& y) {
          return refine_fit.SquaredError(ranked[i].first.params, y.data());
        },
        point, steps, 2000);
    if (error < best.squared_error || (error == best.squared_error && i < best_index)) {
      best.params = ranked[i].first.params;
      best.params.v_max_deg_per_tick = std::exp(point[0]);
      best.params.theta0_deg = std::exp(point[1]);
      best.squared_error = error;
      best_index = i;
    }
  }
  return best;
}

// The scored ticks, each recording's counted `weight` times (integers: exact in a double).
double ScoredTicks(std::span<const JointRecording> recordings, int warmup) {
  double count = 0.0;
  for (const JointRecording& r : recordings) {
    count += r.weight * static_cast<double>(static_cast<long>(r.request_deg.size()) - warmup);
  }
  return count;
}

}  // namespace

IdentificationResult IdentifyJointModel(std::span<const JointRecording> recordings,
                                        const IdentificationOptions& o) {
  if (recordings.empty()) Fail("no recordings");
  if (o.lag_min_ticks < 0 || o.lag_max_ticks < o.lag_min_ticks) Fail("bad lag range");
  if (o.accel_min_ticks < 1 || o.accel_max_ticks < o.accel_min_ticks) Fail("bad accel range");
  const int warmup = o.lag_max_ticks + o.accel_max_ticks;
  double fastest = 0.0;
  const std::vector<Prepared> prepared = PrepareRecordings(recordings, warmup, fastest);

  // Pass 1: every (l, a), v_max and theta_0 from two starts, the model started from the
  // measured angle; it only ranks the (l, a). Pass 2: the best few again, also fitting where
  // each recording's prediction starts (a prediction started from one noisy sample at top speed
  // never recovers from that sample's error), by LM and then a Nelder-Mead polish, because the
  // optimum usually sits on a kink of the objective, where LM's steps stall; see
  // docs/design/identification.md.
  ContinuousFit rank_fit(prepared, warmup, false);
  std::vector<Screened> screened = Screen(rank_fit, o, fastest);
  const std::vector<Ranked> ranked = Rank(rank_fit, screened);
  ContinuousFit refine_fit(prepared, warmup, true);
  std::vector<Refined> refined_fits =
      Refine(refine_fit, ranked, std::min(kRefined, ranked.size()), recordings.size());
  const Candidate best = Polish(refine_fit, ranked, refined_fits);

  IdentificationResult result;
  result.params = best.params;
  result.rms_residual_deg = std::sqrt(best.squared_error / ScoredTicks(recordings, warmup));
  return result;
}

}  // namespace leglab
