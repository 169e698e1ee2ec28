// Cost of the joint-model fit (IdentifyJointModel) against the fit it replaced.
//
//   BM_PreviousFit  the previous fit, kept here only for this comparison: every (l, a) by
//                   Nelder-Mead on ln v_max, ln theta_0 from two starts (400 iterations), the
//                   best four refitted with the start offsets (Nelder-Mead, 2000 iterations);
//   BM_Fit          leglab::IdentifyJointModel: Levenberg-Marquardt on forward sensitivities,
//                   runs of equal requests summed once, a short Nelder-Mead polish in pass 2.
//
// Both fit the same recordings: the step tests of eq. 1 (40 and 110 deg, 8 cycles of 88 ticks,
// what `identify` records) run through the joint model with the identified leg's parameters
// and Gaussian noise of the shipped sensor's size (0.1 deg). Then, because the machine is
// shared and noisy, the two are timed side by side in interleaved rounds and the last lines
// give both results and the median ratio
//   previous/new fit time ratio = (time of the previous fit) / (time of IdentifyJointModel).
// Usage: identification_benchmark [--benchmark_* flags] [--rounds=N]

#include <benchmark/benchmark.h>

#include "rounds_flag.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/trajectories.h"

namespace previous {
// The previous model/src/identification.cc (main at baec711), unchanged but for the names.
using leglab::IdentificationOptions;
using leglab::IdentificationResult;
using leglab::JointModelParams;
using leglab::JointModelState;
using leglab::JointRecording;
using leglab::SimulateJointModel;
namespace {

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("identification: " + what);
}

// The model's open-loop prediction of ticks warmup..N-1: started at tick warmup - 1 from the
// measured angle there plus `start_offset_deg`, remembering the recorded requests before it.
std::vector<double> PredictTail(const JointModelParams& p, const JointRecording& r, int warmup,
                                double start_offset_deg) {
  JointModelState start{r.measured_deg[warmup - 1] + start_offset_deg, {}};
  for (int i = 1; i <= p.lag_ticks + p.accel_ticks; ++i) {
    start.past_requests_deg.push_back(r.request_deg[warmup - i]);
  }
  return SimulateJointModel(p, std::span(r.request_deg).subspan(warmup), start);
}

// Sum of squared prediction errors over ticks >= warmup.
double SquaredError(const JointModelParams& p, const JointRecording& r, int warmup,
                    double start_offset_deg) {
  const std::vector<double> predicted = PredictTail(p, r, warmup, start_offset_deg);
  double sum = 0.0;
  for (size_t k = 0; k < predicted.size(); ++k) {
    const double e = r.measured_deg[warmup + k] - predicted[k];
    sum += e * e;
  }
  return sum;
}

// Minimises f over R^n from `x` by Nelder-Mead (standard coefficients), with initial steps
// `step`; stops when the simplex is smaller than 1e-9 in every coordinate. Returns f at the
// best vertex, which it writes into `x`.
template <typename F>
double NelderMead(const F& f, std::vector<double>& x, const std::vector<double>& step,
                  int max_iterations) {
  const size_t n = x.size();
  std::vector<std::vector<double>> simplex(n + 1, x);
  for (size_t i = 0; i < n; ++i) simplex[i + 1][i] += step[i];
  std::vector<double> value(n + 1);
  for (size_t i = 0; i <= n; ++i) value[i] = f(simplex[i]);
  std::vector<size_t> order(n + 1);
  std::vector<double> centroid(n), trial(n);
  auto along = [&](double t, size_t worst) {
    std::vector<double> point(n);
    for (size_t d = 0; d < n; ++d) point[d] = centroid[d] + t * (simplex[worst][d] - centroid[d]);
    return point;
  };
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    std::iota(order.begin(), order.end(), size_t{0});
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return value[a] < value[b]; });
    const size_t best = order[0], worst = order[n], second_worst = order[n - 1];
    double size = 0.0;
    for (size_t i = 1; i <= n; ++i) {
      for (size_t d = 0; d < n; ++d) {
        size = std::max(size, std::abs(simplex[order[i]][d] - simplex[best][d]));
      }
    }
    if (size < 1e-9) break;
    std::fill(centroid.begin(), centroid.end(), 0.0);
    for (size_t i = 0; i < n; ++i) {
      for (size_t d = 0; d < n; ++d) centroid[d] += simplex[order[i]][d] / static_cast<double>(n);
    }
    const std::vector<double> reflected = along(-1.0, worst);
    const double reflected_value = f(reflected);
    if (reflected_value < value[best]) {
      std::vector<double> expanded = along(-2.0, worst);
      const double expanded_value = f(expanded);
      if (expanded_value < reflected_value) {
        simplex[worst] = std::move(expanded), value[worst] = expanded_value;
      } else {
        simplex[worst] = reflected, value[worst] = reflected_value;
      }
    } else if (reflected_value < value[second_worst]) {
      simplex[worst] = reflected, value[worst] = reflected_value;
    } else {
      const bool outside = reflected_value < value[worst];
      std::vector<double> contracted = along(outside ? -0.5 : 0.5, worst);
      const double contracted_value = f(contracted);
      if (contracted_value < (outside ? reflected_value : value[worst])) {
        simplex[worst] = std::move(contracted), value[worst] = contracted_value;
      } else {  // shrink towards the best vertex
        for (size_t i = 1; i <= n; ++i) {
          for (size_t d = 0; d < n; ++d) {
            simplex[order[i]][d] = 0.5 * (simplex[order[i]][d] + simplex[best][d]);
          }
          value[order[i]] = f(simplex[order[i]]);
        }
      }
    }
  }
  const size_t best =
      static_cast<size_t>(std::min_element(value.begin(), value.end()) - value.begin());
  x = simplex[best];
  return value[best];
}

// One candidate of the fit: the parameters, each recording's start offset, and the error.
struct Candidate {
  JointModelParams params;
  std::vector<double> start_offsets_deg;
  double squared_error = std::numeric_limits<double>::infinity();
};

// Fits v_max and theta_0 (on their logarithms, so they stay positive) with l and a fixed and,
// when `fit_starts`, each recording's start offset too; from `guess`.
Candidate FitContinuous(const Candidate& guess, std::span<const JointRecording> recordings,
                        int warmup, bool fit_starts) {
  const size_t starts = fit_starts ? recordings.size() : 0;
  auto unpack = [&](const std::vector<double>& x, Candidate* c) {
    c->params.v_max_deg_per_tick = std::exp(x[0]);
    c->params.theta0_deg = std::exp(x[1]);
    for (size_t k = 0; k < starts; ++k) c->start_offsets_deg[k] = x[2 + k];
  };
  Candidate c = guess;
  c.start_offsets_deg.resize(recordings.size(), 0.0);
  auto objective = [&](const std::vector<double>& x) {
    Candidate trial = c;
    unpack(x, &trial);
    double sum = 0.0;
    for (size_t k = 0; k < recordings.size(); ++k) {
      sum += SquaredError(trial.params, recordings[k], warmup, trial.start_offsets_deg[k]);
    }
    return sum;
  };
  std::vector<double> x = {std::log(guess.params.v_max_deg_per_tick),
                           std::log(guess.params.theta0_deg)};
  std::vector<double> step = {std::log(1.2), std::log(1.3)};
  for (size_t k = 0; k < starts; ++k) {
    x.push_back(c.start_offsets_deg[k]);
    step.push_back(0.1);  // degrees: about the size of sensor noise
  }
  c.squared_error = NelderMead(objective, x, step, fit_starts ? 2000 : 400);
  unpack(x, &c);
  return c;
}

}  // namespace

IdentificationResult PreviousIdentifyJointModel(std::span<const JointRecording> recordings,
                                                const IdentificationOptions& o = {}) {
  if (recordings.empty()) Fail("no recordings");
  if (o.lag_min_ticks < 0 || o.lag_max_ticks < o.lag_min_ticks) Fail("bad lag range");
  if (o.accel_min_ticks < 1 || o.accel_max_ticks < o.accel_min_ticks) Fail("bad accel range");
  const int warmup = o.lag_max_ticks + o.accel_max_ticks;

  // A starting top speed from the data: the fastest measured change, and theta_0 from it.
  double fastest = 0.0;
  for (size_t k = 0; k < recordings.size(); ++k) {
    const JointRecording& r = recordings[k];
    if (r.request_deg.size() != r.measured_deg.size()) {
      Fail("recording " + std::to_string(k) + ": request and measured lengths differ");
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
  }
  if (!(fastest > 0.0)) Fail("the joint never moved: nothing to identify");

  // Pass 1: every (l, a), v_max and theta_0 from two starts, the model started from the
  // measured angle. Pass 2: the best few again, also fitting where each recording's
  // prediction starts (one noisy sample would otherwise bias the fit: while the joint runs at
  // top speed nothing in the model pulls a wrong start back).
  constexpr size_t kRefined = 4;
  std::vector<Candidate> ranked;
  for (int lag = o.lag_min_ticks; lag <= o.lag_max_ticks; ++lag) {
    for (int accel = o.accel_min_ticks; accel <= o.accel_max_ticks; ++accel) {
      Candidate best_here;
      for (double theta_factor : {1.5, 4.0}) {
        Candidate guess{{fastest, fastest * theta_factor, lag, accel}, {}, 0.0};
        Candidate c = FitContinuous(guess, recordings, warmup, false);
        if (c.squared_error < best_here.squared_error) best_here = std::move(c);
      }
      ranked.push_back(std::move(best_here));
    }
  }
  const auto by_error = [](const Candidate& a, const Candidate& b) {
    return a.squared_error < b.squared_error;
  };
  const size_t refined = std::min(kRefined, ranked.size());
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<long>(refined), ranked.end(),
                    by_error);
  Candidate best;
  for (size_t i = 0; i < refined; ++i) {
    Candidate c = FitContinuous(ranked[i], recordings, warmup, true);
    if (c.squared_error < best.squared_error) best = std::move(c);
  }
  long count = 0;
  for (const JointRecording& r : recordings) {
    count += static_cast<long>(r.request_deg.size()) - warmup;
  }
  IdentificationResult result;
  result.params = best.params;
  result.rms_residual_deg = std::sqrt(best.squared_error / static_cast<double>(count));
  return result;
}

}  // namespace previous

namespace {

using leglab::IdentificationResult;
using leglab::JointModelParams;
using leglab::JointRecording;

// The step tests `identify` runs (eq. 1, 40 and 110 deg, 8 recorded cycles after the model has
// settled), through the joint model with the identified knee's parameters, plus Gaussian
// sensor noise of 0.1 deg (robots/ers210a/robot.yaml), seed 1.
std::vector<JointRecording> Recordings() {
  const JointModelParams truth{2.5, 5.65, 4, 6};
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::vector<JointRecording> recordings;
  for (double theta : {40.0, 110.0}) {
    const std::vector<double> cycle = leglab::StepTestRequests(theta);
    std::vector<double> requests;
    for (int k = 0; k < 13; ++k) requests.insert(requests.end(), cycle.begin(), cycle.end());
    const std::vector<double> angles =
        leglab::SimulateJointModel(truth, requests, leglab::RestState(truth, 0.0));
    const long settled = 5 * static_cast<long>(cycle.size());
    JointRecording r;
    r.request_deg.assign(requests.begin() + settled, requests.end());
    r.measured_deg.assign(angles.begin() + settled, angles.end());
    for (double& m : r.measured_deg) m += noise(rng);
    recordings.push_back(std::move(r));
  }
  return recordings;
}

void BM_PreviousFit(benchmark::State& state) {
  const std::vector<JointRecording> recordings = Recordings();
  for (auto _ : state) {
    benchmark::DoNotOptimize(previous::PreviousIdentifyJointModel(recordings));
  }
}
BENCHMARK(BM_PreviousFit)->Unit(benchmark::kMillisecond);

void BM_Fit(benchmark::State& state) {
  const std::vector<JointRecording> recordings = Recordings();
  for (auto _ : state) {
    benchmark::DoNotOptimize(leglab::IdentifyJointModel(recordings));
  }
}
BENCHMARK(BM_Fit)->Unit(benchmark::kMillisecond);

template <typename Fit>
double TimeFit(const Fit& fit, IdentificationResult* result) {
  const auto start = std::chrono::steady_clock::now();
  *result = fit();
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  return elapsed.count();
}

using leglab::benchmarks::Median;

void Print(const char* name, const IdentificationResult& r) {
  std::printf("%s fit: v_max %.17g deg/tick, theta_0 %.17g deg, l %d, a %d, rms %.17g deg\n", name,
              r.params.v_max_deg_per_tick, r.params.theta0_deg, r.params.lag_ticks,
              r.params.accel_ticks, r.rms_residual_deg);
}

// Interleaved rounds, alternating which fit goes first, each round's ratio from timings a
// second apart so that load changes on the machine hit both.
void ReportSideBySideRatio(int rounds) {
  const std::vector<JointRecording> recordings = Recordings();
  auto previous_fit = [&] { return previous::PreviousIdentifyJointModel(recordings); };
  auto new_fit = [&] { return leglab::IdentifyJointModel(recordings); };
  IdentificationResult previous_result;
  IdentificationResult new_result;
  std::vector<double> ratios;
  std::vector<double> previous_ms;
  std::vector<double> new_ms;
  for (int round = 0; round < rounds; ++round) {
    double previous_s = 0.0;
    double new_s = 0.0;
    if (round % 2 == 0) {
      previous_s = TimeFit(previous_fit, &previous_result);
      new_s = TimeFit(new_fit, &new_result);
    } else {
      new_s = TimeFit(new_fit, &new_result);
      previous_s = TimeFit(previous_fit, &previous_result);
    }
    ratios.push_back(previous_s / new_s);
    previous_ms.push_back(previous_s * 1e3);
    new_ms.push_back(new_s * 1e3);
  }
  Print("previous", previous_result);
  Print("new     ", new_result);
  std::printf("previous fit: %.1f ms (median), new fit: %.1f ms (median), %d interleaved rounds\n",
              Median(previous_ms), Median(new_ms), rounds);
  std::printf("previous/new fit time ratio: %.1f\n", Median(ratios));
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = leglab::benchmarks::TakeRoundsFlag(argc, argv, 7);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) {
    return 1;
  }
  try {  // the fits throw only on bad recordings, which these are not
    benchmark::RunSpecifiedBenchmarks();
    ReportSideBySideRatio(rounds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "identification_benchmark: %s\n", e.what());
    return 1;
  }
  benchmark::Shutdown();
  return 0;
}
