// Cost of the online planner's tick (ServoPlanner::Request) against one tick of the model
// itself, on the XL330's fitted models and a shipped log's requests as the desired motion:
//
//   BM_ModelTick                   one StepServoModel tick of the extended model;
//   BM_PlannerTick/model_based     one Request, the extended model, its horizon as preview;
//   BM_PlannerTick/optimal         one Request, the receding horizon (its default preview);
//   BM_PaperPlannerTick            one Request, the paper's model, model-based.
//
// After them, optimal's Requests one by one (median, 99th percentile and largest, and the
// ticks that reached the budget) at its default budget (half the tick) and on its iteration
// cap alone, with its default preview and with a preview of 250 ticks, 250 held after it and a
// hand-over of 2 (l + 1), the setting nearest the batch optimum (docs/results/servos.md).
//
// Each planner case runs along the desired motion, measuring what the model predicts, and
// starts over at its end. Then the four side by side in interleaved rounds (the machine is
// shared and noisy): each one's time per tick, as a share of the servo's tick and as a
// multiple of a model tick. Usage: servo_planner_benchmark [--benchmark_* flags] [--rounds=N]
//
// The models are identify's fit of the shipped logs (xl330_model.h).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "leglab/servo/servo_model.h"
#include "leglab/servo/servo_plan_io.h"
#include "leglab/servo/servo_planner.h"
#include "rounds_flag.h"
#include "xl330_model.h"

namespace {

using namespace leglab;

constexpr double kTickS = benchmarks::kXl330TickS;
constexpr const ServoModelParams& kExtended = benchmarks::kXl330Extended;
constexpr const JointModelParams& kPaper = benchmarks::kXl330Paper;

struct Case {
  std::vector<double> desired;
  ServoDrive drive;
  ServoLimits limits;
};

// The sin_time_square log at kp 400 (the XL330's fastest motion) as the desired motion.
const Case& TheCase() {
  static const Case c = [] {
    const std::string log = std::string(LEGLAB_SOURCE_DIR) +
                            "/data/servo_logs/dynamixel-xl330/"
                            "sin_time_square_kp400_2026-01-15_10h29m37.json";
    const DesiredServoMotion motion = ReadDesiredMotion(log);
    return Case{ResampleDesired(motion, kTickS, log), *motion.drive,
                ServoLimits{-180.0, 180.0, kExtended.v_max_deg_s}};
  }();
  return c;
}

ServoPlanner MakePlanner(PlanMethod method, bool paper, ServoPlannerOptions options = {}) {
  const Case& c = TheCase();
  options.method = method;
  if (paper) {
    return {kPaper, kTickS, {c.limits.min_deg, c.limits.max_deg, 565.3989375207187}, options};
  }
  return {kExtended, c.drive, kTickS, c.limits, options};
}

// Runs `ticks` Requests along the desired motion from where `t` is, starting over at its end.
void PlannerTicks(ServoPlanner& planner, size_t& t, int ticks) {
  const std::span<const double> desired(TheCase().desired);
  const auto window = static_cast<size_t>(planner.PreviewTicks()) + 1;
  for (int i = 0; i < ticks; ++i) {
    if (t == desired.size()) {
      planner.Reset(desired[0]);
      t = 0;
    }
    benchmark::DoNotOptimize(planner.Request(
        desired.subspan(t, std::min(window, desired.size() - t)), planner.ExpectedDeg()));
    ++t;
  }
}

void ModelTicks(ServoModelState& state, size_t& t, int ticks) {
  const std::vector<double>& desired = TheCase().desired;
  for (int i = 0; i < ticks; ++i) {
    benchmark::DoNotOptimize(
        StepServoModel(kExtended, TheCase().drive, kTickS, state, desired[t++ % desired.size()]));
  }
}

void BM_ModelTick(benchmark::State& state) {
  ServoModelState model = ServoRestState(kExtended, TheCase().desired[0]);
  size_t t = 0;
  for (auto _ : state) ModelTicks(model, t, 1);
}
BENCHMARK(BM_ModelTick);

void BM_PlannerTick(benchmark::State& state) {
  ServoPlanner planner =
      MakePlanner(state.range(0) == 0 ? PlanMethod::kModelBased : PlanMethod::kOptimal, false);
  planner.Reset(TheCase().desired[0]);
  size_t t = 0;
  for (auto _ : state) PlannerTicks(planner, t, 1);
  state.SetLabel(state.range(0) == 0 ? "model_based" : "optimal");
}
BENCHMARK(BM_PlannerTick)->Arg(0)->Arg(1);

void BM_PaperPlannerTick(benchmark::State& state) {
  ServoPlanner planner = MakePlanner(PlanMethod::kModelBased, true);
  planner.Reset(TheCase().desired[0]);
  size_t t = 0;
  for (auto _ : state) PlannerTicks(planner, t, 1);
}
BENCHMARK(BM_PaperPlannerTick);

using leglab::benchmarks::Median;

template <typename F>
double MicrosecondsPerTick(const F& run, int ticks) {
  const auto start = std::chrono::steady_clock::now();
  run(ticks);
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
             .count() /
         ticks;
}

void ReportSideBySide(int rounds) {
  const int ticks = static_cast<int>(TheCase().desired.size());
  ServoModelState model = ServoRestState(kExtended, TheCase().desired[0]);
  ServoPlanner based = MakePlanner(PlanMethod::kModelBased, false);
  ServoPlanner optimal = MakePlanner(PlanMethod::kOptimal, false);
  ServoPlanner paper = MakePlanner(PlanMethod::kModelBased, true);
  size_t t_model = 0, t_based = 0, t_optimal = 0, t_paper = 0;
  for (ServoPlanner* p : {&based, &optimal, &paper}) p->Reset(TheCase().desired[0]);
  std::vector<double> model_us, based_us, optimal_us, paper_us;
  for (int round = 0; round < rounds; ++round) {
    const auto one = [&](int which) {
      switch (which) {
        case 0:
          model_us.push_back(
              MicrosecondsPerTick([&](int n) { ModelTicks(model, t_model, n); }, ticks));
          break;
        case 1:
          based_us.push_back(
              MicrosecondsPerTick([&](int n) { PlannerTicks(based, t_based, n); }, ticks));
          break;
        case 2:
          optimal_us.push_back(
              MicrosecondsPerTick([&](int n) { PlannerTicks(optimal, t_optimal, n); }, ticks));
          break;
        default:
          paper_us.push_back(
              MicrosecondsPerTick([&](int n) { PlannerTicks(paper, t_paper, n); }, ticks));
      }
    };
    for (int k = 0; k < 4; ++k) one((k + round) % 4);  // a different order each round
  }
  const double tick_us = kTickS * 1e6;
  const double m = Median(model_us);
  std::printf(
      "per tick, medians of %d interleaved rounds of %d ticks (the servo's tick %.0f us):\n",
      rounds, ticks, tick_us);
  std::printf("  model tick             %8.3f us\n", m);
  const auto line = [&](const char* what, const std::vector<double>& us) {
    const double x = Median(us);
    std::printf("  %-22s %8.3f us  %6.3f %% of the tick  %7.1f model ticks\n", what, x,
                100.0 * x / tick_us, x / m);
  };
  line("model_based (extended)", based_us);
  line("optimal (extended)", optimal_us);
  line("model_based (paper)", paper_us);
}

// The p-th quantile (0..1) of `xs` (nearest rank), which it sorts.
double Quantile(std::vector<double>& xs, double p) {
  std::sort(xs.begin(), xs.end());
  const auto rank = static_cast<size_t>(std::lround(p * static_cast<double>(xs.size() - 1)));
  return xs[std::min(rank, xs.size() - 1)];
}

// Each optimal Request timed on its own, `passes` times along the motion.
void ReportOptimalTicks(int passes) {
  struct Setting {
    const char* what;
    int preview_ticks, hold_ticks, handover_ticks;
    double budget_s;
  };
  const int handover = 2 * (kExtended.lag_ticks + 1);
  const Setting settings[] = {
      {"default preview, budget half the tick", -1, 0, -1, -1.0},
      {"default preview, the cap alone", -1, 0, -1, 0.0},
      {"preview 250, hold 250, budget half the tick", 250, 250, handover, -1.0},
      {"preview 250, hold 250, the cap alone", 250, 250, handover, 0.0}};
  const std::span<const double> desired(TheCase().desired);
  const double budget_us = kTickS / 2.0 * 1e6;
  std::printf("optimal's Requests one by one, %d passes of %zu ticks (budget %.0f us):\n", passes,
              desired.size(), budget_us);
  for (const Setting& s : settings) {
    ServoPlannerOptions options;
    options.preview_ticks = s.preview_ticks;
    options.hold_ticks = s.hold_ticks;
    options.handover_ticks = s.handover_ticks;
    options.budget_s = s.budget_s;
    ServoPlanner planner = MakePlanner(PlanMethod::kOptimal, false, options);
    const auto window = static_cast<size_t>(planner.PreviewTicks()) + 1;
    std::vector<double> us;
    us.reserve(desired.size() * static_cast<size_t>(passes));
    for (int pass = 0; pass < passes; ++pass) {
      planner.Reset(desired[0]);
      for (size_t t = 0; t < desired.size(); ++t) {
        const auto span = desired.subspan(t, std::min(window, desired.size() - t));
        const double measured = planner.ExpectedDeg();
        const auto start = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(planner.Request(span, measured));
        us.push_back(
            std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                .count());
      }
    }
    const auto reached =
        std::count_if(us.begin(), us.end(), [&](double x) { return x >= budget_us; });
    std::printf(
        "  %-44s preview %3d: median %7.1f us, p99 %7.1f, max %7.1f; %5.1f %% of ticks at "
        "or over the budget\n",
        s.what, planner.PreviewTicks(), Quantile(us, 0.5), Quantile(us, 0.99), Quantile(us, 1.0),
        100.0 * static_cast<double>(reached) / static_cast<double>(us.size()));
  }
}

void Report(int rounds) {
  ReportSideBySide(rounds);
  ReportOptimalTicks(3);
}

}  // namespace

int main(int argc, char** argv) { return leglab::benchmarks::RunThenReport(argc, argv, 9, Report); }
