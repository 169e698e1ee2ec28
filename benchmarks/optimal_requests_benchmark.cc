// One damped Gauss-Newton step of OptimizeRequests on an 88-tick walking cycle, from the
// requests (steady state, sensitivity, then the step), two ways:
//
//   BM_DenseStep       the T x T normal matrix S^T W S (SteadyStateNormalMatrix, its O(T^2 a)
//                      recursion) and Eigen's LDLT of S^T W S + c I: what every solve did
//                      before, and what the optimal cycle's solves still do (the gradient
//                      S^T W e, which both need, is formed once outside the timing);
//   BM_StructuredStep  StructuredDampedStep: the cyclic banded system of the sensitivity's
//                      structure (what ILC's per-step updates do, structured_solve).
//
// Then the two side by side in interleaved rounds (the machine is shared and noisy), with the
// largest difference between the two steps.
// Usage: optimal_requests_benchmark [--benchmark_* flags] [--rounds=N]

#include <benchmark/benchmark.h>

#include "rounds_flag.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <vector>

#include "leglab/model/joint_model.h"
#include "leglab/model/optimal_requests.h"
#include "leglab/model/paper.h"

namespace {

using namespace leglab;

struct Case {
  JointModelParams params = paper::kTable1;
  std::vector<double> requests;
  std::vector<double> desired;
  std::vector<double> weights;
  std::vector<int> free;
  double damping = 0.0;
};

// The walking-like cycle of the optimal-requests tests (D = 40 sin + 15 sin 2, T = 88),
// requested 4 ticks early, weights that vary by tick as the foot objective's do, every request
// free, damping 1e-3 of the normal matrix's largest diagonal entry (the solver's start).
Case MakeCase() {
  Case c;
  const int n = 88;
  for (int t = 0; t < n; ++t) {
    const double phase = 2.0 * std::numbers::pi * t / n;
    c.desired.push_back(40.0 * std::sin(phase) + 15.0 * std::sin(2.0 * phase + 1.0));
    c.weights.push_back(1.0 + 0.5 * std::cos(phase));
  }
  for (int t = 0; t < n; ++t) c.requests.push_back(c.desired[(t + 4) % n]);
  c.free.resize(n);
  std::iota(c.free.begin(), c.free.end(), 0);
  const Eigen::MatrixXd normal = SteadyStateNormalMatrix(c.params, c.requests, c.weights);
  c.damping = 1e-3 * normal.diagonal().maxCoeff();
  return c;
}

// S^T W e, the gradient's half, outside the timing (MinimiseStage forms it either way).
Eigen::VectorXd Gradient(const Case& c) {
  const auto n = static_cast<Eigen::Index>(c.requests.size());
  const std::vector<double> m = CyclicSteadyState(c.params, c.requests, 1e-13);
  const Eigen::MatrixXd s = SteadyStateSensitivity(c.params, c.requests);
  Eigen::VectorXd residual(n);
  for (Eigen::Index t = 0; t < n; ++t) residual[t] = c.weights[t] * (m[t] - c.desired[t]);
  return s.transpose() * residual;
}

// The steady state and sensitivity with the normal matrix (SteadyStateNormalMatrix), then
// the LDLT of the damped matrix.
Eigen::VectorXd DenseStep(const Case& c, const Eigen::VectorXd& gradient) {
  Eigen::MatrixXd normal = SteadyStateNormalMatrix(c.params, c.requests, c.weights);
  normal.diagonal().array() += c.damping;
  return -normal.ldlt().solve(gradient);
}

Eigen::VectorXd StructuredStep(const Case& c) {
  return StructuredDampedStep(c.params, c.requests, c.desired, c.weights, c.free, c.damping);
}

void BM_DenseStep(benchmark::State& state) {
  const Case c = MakeCase();
  const Eigen::VectorXd gradient = Gradient(c);
  for (auto _ : state) benchmark::DoNotOptimize(DenseStep(c, gradient).data());
}
BENCHMARK(BM_DenseStep)->Unit(benchmark::kMicrosecond);

void BM_StructuredStep(benchmark::State& state) {
  const Case c = MakeCase();
  for (auto _ : state) benchmark::DoNotOptimize(StructuredStep(c).data());
}
BENCHMARK(BM_StructuredStep)->Unit(benchmark::kMicrosecond);

using leglab::benchmarks::Median;

template <typename F>
double MicrosecondsPerCall(const F& f, int calls) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < calls; ++i) benchmark::DoNotOptimize(f().data());
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
             .count() /
         calls;
}

void ReportSideBySide(int rounds) {
  const Case c = MakeCase();
  const Eigen::VectorXd gradient = Gradient(c);
  const Eigen::VectorXd dense = DenseStep(c, gradient);
  const Eigen::VectorXd structured = StructuredStep(c);
  std::vector<double> dense_us, structured_us, ratios;
  for (int round = 0; round < rounds; ++round) {
    double d = 0.0, s = 0.0;
    auto time_dense = [&] { d = MicrosecondsPerCall([&] { return DenseStep(c, gradient); }, 200); };
    auto time_structured = [&] { s = MicrosecondsPerCall([&] { return StructuredStep(c); }, 200); };
    if (round % 2 == 0) {
      time_dense(), time_structured();
    } else {
      time_structured(), time_dense();
    }
    dense_us.push_back(d), structured_us.push_back(s), ratios.push_back(d / s);
  }
  std::printf(
      "one damped step, T = 88: dense %.1f us, structured %.1f us (medians of %d interleaved "
      "rounds of 200 calls); dense/structured %.2f; steps differ by at most %.2g deg (largest "
      "entry %.3g deg)\n",
      Median(dense_us), Median(structured_us), rounds, Median(ratios),
      (dense - structured).cwiseAbs().maxCoeff(), dense.cwiseAbs().maxCoeff());
}

}  // namespace

int main(int argc, char** argv) {
  return leglab::benchmarks::RunThenReport(argc, argv, 5, ReportSideBySide);
}
