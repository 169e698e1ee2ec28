#include "leglab/experiments/walk_fit.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/app/parallel.h"
#include "leglab/core/format.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/model/paper.h"

namespace leglab::experiments {
namespace {

// The continuous unknowns, in the order of the fit's vector.
constexpr std::array<WalkUnknown, kWalkUnknowns> kUnknowns = {{
    {"desired.locus.ground_below_shoulder_mm", 77.0, 130.0,
     "77 mm: the cited front body height read as the shoulder's height above the ground (the "
     "least reading: the ball of the foot's centre is 14 mm higher still); 130 mm: just short "
     "of the straight leg's 133.9 mm (65.3 + 68.7 mm), beyond which no point of the locus, "
     "24 mm fore and aft and 28-49 mm outward of its centre, is reachable. Points of the range "
     "where the locus leaves the leg's workspace or joint limits are infeasible"},
    {"desired.locus.body_pitch_deg", 0.0, 17.1,
     "0: a level body (the heights measured to references that are not the shoulders); 17.1 "
     "deg: the cited front and rear body heights (77 and 112 mm) taken at the shoulders, 119 "
     "mm apart: asin(35 / 119), nose down"},
    {"desired.locus.skew", -0.35, 0.35,
     "the cited locus skew multiplier, 0.035, whose unit and sign convention are not given: as "
     "mm outward per mm forward, or ten times that if it multiplies a length in cm by one in "
     "mm, either sign"},
    {"desired.locus.ground_fraction", 0.5, 0.8,
     "0.5: the cited walk's (a trot keeps each diagonal pair down half the step at least); "
     "0.8: the flight then lasts 18 ticks (144 ms) for 49 mm forward and 42 mm up and down, "
     "asking the knee for about three times its top speed: a faster flight is no walk the "
     "cited one could have been tuned into"},
}};

// The discrete unknown: which of the cited offsets (28 and 49 mm) is forward.
struct OffsetReading {
  double forward_mm;
  double outward_mm;
};
constexpr std::array<OffsetReading, 2> kOffsetReadings = {{{49.0, 28.0}, {28.0, 49.0}}};
constexpr const char* kOffsetWhy =
    "the cited front locus offsets are 2.8 and 4.9 cm (the source's x and y); which one is "
    "forward of the shoulder and which outward is not certain, so both readings are tried";

// The numbers fitted: the paper's direct-method row, joint and foot.
std::array<WalkFitTarget, kWalkFitTargets> WalkFitTargets() {
  const paper::Table2Row& l2 = *paper::FindTable2Row("L2(Des,Dir)");
  const paper::Table2Row& linf = *paper::FindTable2Row("Linf(Des,Dir)");
  const paper::FootRow& foot = *paper::FindFootRow("direct");
  std::array<WalkFitTarget, kWalkFitTargets> t;
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string joint(kLegJointNames[j]);
    t[j] = {"L2(Des,Dir)." + joint + "_deg", l2.mean_deg[j]};
    t[3 + j] = {"Linf(Des,Dir)." + joint + "_deg", linf.mean_deg[j]};
  }
  t[6] = {"foot.direct.l2_cm", foot.l2_cm.mean};
  t[7] = {"foot.direct.linf_cm", foot.linf_cm.mean};
  return t;
}

void Apply(const FittedWalk& walk, ExperimentConfig& config) {
  LocusConfig& locus = config.track.locus;
  locus.forward_mm = kOffsetReadings[walk.offsets].forward_mm;
  locus.outward_mm = kOffsetReadings[walk.offsets].outward_mm;
  locus.ground_below_shoulder_mm = walk.x[0];
  locus.body_pitch_deg = walk.x[1];
  locus.shape.skew = walk.x[2];
  locus.shape.ground_fraction = walk.x[3];
}

// Sum of squared relative residuals: each of the eight numbers counts alike.
double Cost(const std::array<double, kWalkFitTargets>& values,
            const std::array<WalkFitTarget, kWalkFitTargets>& t) {
  double cost = 0.0;
  for (int i = 0; i < kWalkFitTargets; ++i) {
    const double r = (values[i] - t[i].paper) / t[i].paper;
    cost += r * r;
  }
  return cost;
}

// The direct method's row on `walk`: `base` runs the direct mode only.
WalkEvaluation Evaluate(const ExperimentConfig& base, const FittedWalk& walk,
                        const std::array<WalkFitTarget, kWalkFitTargets>& targets) {
  ExperimentConfig config = base;
  Apply(walk, config);
  WalkEvaluation e;
  TrackResult result;
  try {
    result = RunTrackExperiment(config);
  } catch (const InputError& error) {  // the locus leaves the workspace or the joint limits
    e.infeasible = error.what();
    return e;
  }
  const Table2 table = ComputeTable2(result);
  const Table2Row& l2 = *table.Find("L2(Des,Dir)");
  const Table2Row& linf = *table.Find("Linf(Des,Dir)");
  const FootRow& foot = *table.FindFoot("direct");
  for (int j = 0; j < kLegJoints; ++j) {
    e.values[j] = l2.joints[j].mean;
    e.values[3 + j] = linf.joints[j].mean;
  }
  e.values[6] = foot.l2_cm.mean;
  e.values[7] = foot.linf_cm.mean;
  e.feasible = true;
  e.cost = Cost(e.values, targets);
  return e;
}

// The fit's box, scaled to [0, 1] per unknown.
double ToUnit(int i, double v) {
  return (v - kUnknowns[i].min) / (kUnknowns[i].max - kUnknowns[i].min);
}
double FromUnit(int i, double u) {
  return kUnknowns[i].min + std::clamp(u, 0.0, 1.0) * (kUnknowns[i].max - kUnknowns[i].min);
}

// Grid points per unknown: ends included.
constexpr std::array<int, kUnknowns.size()> kGrid = {7, 4, 3, 4};
constexpr int kPolishIterations = 40;

struct FitResult {
  FittedWalk walk;
  WalkEvaluation fit_evaluation;  // at the cheap evaluation's steps
  long evaluations = 0;
  long feasible_evaluations = 0;
};

// Nelder-Mead in the unit box (points clamped into it), fixed start simplex and iteration
// count: the same bits on every run.
FittedWalk Polish(const ExperimentConfig& base, FittedWalk start,
                  const std::array<WalkFitTarget, kWalkFitTargets>& targets, long& evaluations) {
  constexpr int n = kUnknowns.size();
  using Point = std::array<double, n>;
  auto walk_at = [&](const Point& u) {
    FittedWalk w = start;
    for (int i = 0; i < n; ++i) w.x[i] = FromUnit(i, u[i]);
    return w;
  };
  auto f = [&](const Point& u) {
    ++evaluations;
    return Evaluate(base, walk_at(u), targets).cost;
  };
  std::array<Point, n + 1> simplex;
  std::array<double, n + 1> cost{};
  for (int i = 0; i < n; ++i) simplex[0][i] = ToUnit(i, start.x[i]);
  for (int k = 1; k <= n; ++k) {
    simplex[k] = simplex[0];
    const double step = 0.1;  // a tenth of each range
    simplex[k][k - 1] += simplex[0][k - 1] + step <= 1.0 ? step : -step;
  }
  for (int k = 0; k <= n; ++k) cost[k] = f(simplex[k]);
  auto lerp = [](const Point& a, const Point& b, double t) {
    Point p;
    for (int i = 0; i < n; ++i) p[i] = std::clamp(a[i] + t * (b[i] - a[i]), 0.0, 1.0);
    return p;
  };
  for (int it = 0; it < kPolishIterations; ++it) {
    std::array<int, n + 1> order{};
    for (int k = 0; k <= n; ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return cost[a] < cost[b]; });
    const int worst = order[n];
    Point centroid{};
    for (int k = 0; k < n; ++k) {
      for (int i = 0; i < n; ++i) centroid[i] += simplex[order[k]][i] / n;
    }
    const Point reflected = lerp(simplex[worst], centroid, 2.0);
    const double fr = f(reflected);
    if (fr < cost[order[0]]) {
      const Point expanded = lerp(simplex[worst], centroid, 3.0);
      const double fe = f(expanded);
      simplex[worst] = fe < fr ? expanded : reflected;
      cost[worst] = std::min(fe, fr);
    } else if (fr < cost[order[n - 1]]) {
      simplex[worst] = reflected;
      cost[worst] = fr;
    } else {
      const Point contracted = lerp(simplex[worst], centroid, 0.5);
      const double fc = f(contracted);
      if (fc < cost[worst]) {
        simplex[worst] = contracted;
        cost[worst] = fc;
      } else {  // shrink toward the best
        for (int k = 0; k <= n; ++k) {
          if (k == order[0]) continue;
          simplex[k] = lerp(simplex[order[0]], simplex[k], 0.5);
          cost[k] = f(simplex[k]);
        }
      }
    }
  }
  const auto best = std::min_element(cost.begin(), cost.end()) - cost.begin();
  return walk_at(simplex[best]);
}

// The grid's walks, every offset reading: kGrid points per unknown, ends included.
std::vector<FittedWalk> GridWalks() {
  std::vector<FittedWalk> grid;
  for (int o = 0; o < static_cast<int>(kOffsetReadings.size()); ++o) {
    for (int a = 0; a < kGrid[0]; ++a) {
      for (int b = 0; b < kGrid[1]; ++b) {
        for (int c = 0; c < kGrid[2]; ++c) {
          for (int d = 0; d < kGrid[3]; ++d) {
            FittedWalk w;
            w.offsets = o;
            const std::array<int, 4> idx = {a, b, c, d};
            for (int i = 0; i < 4; ++i) w.x[i] = FromUnit(i, idx[i] / (kGrid[i] - 1.0));
            grid.push_back(w);
          }
        }
      }
    }
  }
  return grid;
}

FitResult Fit(const ExperimentConfig& base,
              const std::array<WalkFitTarget, kWalkFitTargets>& targets) {
  // The grid, every offset reading; evaluated in parallel, each point writing only its own
  // slot, so the result does not depend on the thread count.
  const std::vector<FittedWalk> grid = GridWalks();
  std::vector<WalkEvaluation> scores(grid.size());
  ParallelFor(static_cast<int>(grid.size()), base.threads,
              [&](int i) { scores[i] = Evaluate(base, grid[i], targets); });
  FitResult fit;
  fit.evaluations = static_cast<long>(grid.size());
  fit.feasible_evaluations = std::count_if(scores.begin(), scores.end(),
                                           [](const WalkEvaluation& e) { return e.feasible; });
  // Polish the best grid point of each offset reading (in parallel), keep the better.
  std::vector<FittedWalk> starts;
  for (int o = 0; o < static_cast<int>(kOffsetReadings.size()); ++o) {
    long best = -1;
    for (size_t i = 0; i < grid.size(); ++i) {
      if (grid[i].offsets != o || !scores[i].feasible) continue;
      if (best < 0 || scores[i].cost < scores[best].cost) best = static_cast<long>(i);
    }
    if (best >= 0) starts.push_back(grid[best]);
  }
  if (starts.empty()) {
    throw InputError("fit_walk: no walk in the fit's ranges is reachable by this leg (first: " +
                     scores.front().infeasible + ")");
  }
  std::vector<FittedWalk> polished(starts.size());
  std::vector<long> counts(starts.size(), 0);
  ParallelFor(static_cast<int>(starts.size()), base.threads,
              [&](int i) { polished[i] = Polish(base, starts[i], targets, counts[i]); });
  for (long c : counts) fit.evaluations += c;
  bool first = true;
  for (const FittedWalk& w : polished) {
    const WalkEvaluation e = Evaluate(base, w, targets);
    ++fit.evaluations;
    if (first || e.cost < fit.fit_evaluation.cost) {
      fit.walk = w;
      fit.fit_evaluation = e;
      first = false;
    }
  }
  return fit;
}

}  // namespace

bool IsFittedWalkKey(std::string_view key) {
  bool fitted = key == "desired" || key == "desired.locus" || key == "desired.locus.forward_mm" ||
                key == "desired.locus.outward_mm";
  for (const WalkUnknown& u : kUnknowns) fitted = fitted || key == u.key;
  return fitted;
}

WalkFitReport FitWalk(const ExperimentConfig& config, int threads) {
  ExperimentConfig full = config;
  full.threads = 1;  // the fit runs evaluations in parallel instead
  ExperimentConfig cheap = full;
  cheap.track.warmup_steps = 1;
  cheap.track.steps = 2;
  cheap.threads = threads;

  WalkFitReport report;
  report.targets = WalkFitTargets();
  const FitResult fit = Fit(cheap, report.targets);
  report.check = Evaluate(full, fit.walk, report.targets);
  assert(report.check.feasible && "the fitted walk was feasible in the fit");
  report.walk = fit.walk;
  report.at_fit_steps = fit.fit_evaluation;
  report.evaluations = fit.evaluations;
  report.feasible_evaluations = fit.feasible_evaluations;
  report.fit_warmup_steps = cheap.track.warmup_steps;
  report.fit_steps = cheap.track.steps;
  report.check_warmup_steps = full.track.warmup_steps;
  report.check_steps = full.track.steps;
  return report;
}

std::string WalkFitJson(const WalkFitReport& report, const std::string& config_path,
                        const std::vector<std::string>& overrides) {
  const auto& targets = report.targets;
  const WalkEvaluation& check = report.check;
  nlohmann::ordered_json j;
  j["program"] = "fit_walk";
  j["config"] = config_path;
  j["overrides"] = overrides;
  nlohmann::ordered_json fitted_on = nlohmann::ordered_json::array();
  for (const WalkFitTarget& t : targets) fitted_on.push_back(t.name);
  j["fitted_on"] = fitted_on;
  const OffsetReading& o = kOffsetReadings[report.walk.offsets];
  nlohmann::ordered_json fitted;
  fitted["desired.locus.forward_mm"] = o.forward_mm;
  fitted["desired.locus.outward_mm"] = o.outward_mm;
  for (size_t i = 0; i < kUnknowns.size(); ++i) fitted[kUnknowns[i].key] = report.walk.x[i];
  j["fitted"] = fitted;
  nlohmann::ordered_json ranges;
  ranges["desired.locus.{forward_mm,outward_mm}"] = {{"choices", {{49.0, 28.0}, {28.0, 49.0}}},
                                                     {"why", kOffsetWhy}};
  for (const WalkUnknown& u : kUnknowns) {
    ranges[u.key] = {{"min", u.min}, {"max", u.max}, {"why", u.why}};
  }
  j["ranges"] = ranges;
  nlohmann::ordered_json residuals;
  for (int i = 0; i < kWalkFitTargets; ++i) {
    residuals[targets[i].name] = {
        {"paper", targets[i].paper},
        {"fitted", check.values[i]},
        {"residual", check.values[i] - targets[i].paper},
        {"relative", (check.values[i] - targets[i].paper) / targets[i].paper}};
  }
  j["residuals"] = residuals;
  j["cost"] = check.cost;
  j["fit"] = {{"warmup_steps", report.fit_warmup_steps},
              {"steps", report.fit_steps},
              {"evaluations", report.evaluations},
              {"grid_feasible", report.feasible_evaluations},
              {"cost_at_fit_steps", report.at_fit_steps.cost},
              {"checked_with",
               {{"warmup_steps", report.check_warmup_steps}, {"steps", report.check_steps}}}};
  return j.dump(2) + "\n";
}

std::string WalkFitMarkdown(const WalkFitReport& report) {
  const auto& targets = report.targets;
  const WalkEvaluation& check = report.check;
  const OffsetReading& o = kOffsetReadings[report.walk.offsets];
  std::ostringstream md;
  md << "# The walk fitted to the paper's direct-method row (fit_walk)\n\n"
     << "Fitted on: the direct method's joint L2 and L-infinity (Des vs Dir) and foot L2 "
        "and L-infinity, nothing else. Residuals from a run of "
     << report.check_warmup_steps << " + " << report.check_steps << " steps.\n\n"
     << "| unknown | range | fitted | why this range |\n|---|---|---|---|\n"
     << "| forward / outward (mm) | 49 / 28 or 28 / 49 | " << FormatFixed(o.forward_mm, 0) << " / "
     << FormatFixed(o.outward_mm, 0) << " | " << kOffsetWhy << " |\n";
  for (size_t i = 0; i < kUnknowns.size(); ++i) {
    md << "| `" << kUnknowns[i].key << "` | [" << FormatDouble(kUnknowns[i].min) << ", "
       << FormatDouble(kUnknowns[i].max) << "] | " << FormatFixed(report.walk.x[i], 3) << " | "
       << kUnknowns[i].why << " |\n";
  }
  md << "\n| number | paper | fitted walk | residual | relative |\n|---|---|---|---|---|\n";
  for (int i = 0; i < kWalkFitTargets; ++i) {
    md << "| " << targets[i].name << " | " << FormatDouble(targets[i].paper) << " | "
       << FormatFixed(check.values[i], 2) << " | "
       << FormatFixed(check.values[i] - targets[i].paper, 2) << " | "
       << FormatFixed(100.0 * (check.values[i] - targets[i].paper) / targets[i].paper, 0)
       << " % |\n";
  }
  md << "\nCost (sum of squared relative residuals): " << FormatFixed(check.cost, 4) << "; "
     << report.evaluations << " evaluations (" << report.feasible_evaluations
     << " of the grid's points reachable).\n";
  return md.str();
}

// walk_fit.json's fields (WalkFitJson), as dotted paths (`<...>`: a key named at run time).
constexpr ColumnDoc kWalkFitFields[] = {
    {"program", "", "fit_walk"},
    {"config", "", "the config file it ran with"},
    {"overrides", "", "the --set overrides, in order (a list)"},
    {"fitted_on", "", "the paper's numbers it fitted, by name (a list)"},
    {"fitted.<key>", "", "the fitted walk: each unknown's value, by its config key"},
    {"ranges.<key>.min", "", "an unknown's range searched: its least value"},
    {"ranges.<key>.max", "", "its greatest"},
    {"ranges.<key>.choices", "", "or the values it chose among (a list)"},
    {"ranges.<key>.why", "", "why that range"},
    {"residuals.<name>.paper", "", "each number fitted: the paper's"},
    {"residuals.<name>.fitted", "", "the fitted walk's"},
    {"residuals.<name>.residual", "", "their difference"},
    {"residuals.<name>.relative", "", "the difference over the paper's"},
    {"cost", "", "the fit's cost: the sum of the squared relative residuals"},
    {"fit.warmup_steps", "", "the warm-up steps of each evaluation"},
    {"fit.steps", "", "the measured steps of each evaluation"},
    {"fit.evaluations", "", "the walks it ran"},
    {"fit.grid_feasible", "", "the grid's points the foot could reach"},
    {"fit.cost_at_fit_steps", "", "the cost the fit found at those steps"},
    {"fit.checked_with.warmup_steps", "", "the final check's warm-up steps"},
    {"fit.checked_with.steps", "", "the final check's measured steps"},
};

std::span<const OutputDoc> WalkFitOutputs() {
  static const OutputDoc outputs[] = {
      {"walk_fit.json",
       "The fit of the walk's unknowns: the config and overrides it ran with, the numbers "
       "fitted on (fitted_on), the fitted walk (fitted), each unknown's range and why (ranges), "
       "the residuals per number and the cost.",
       kWalkFitFields},
      {"walk_fit.md", "The same as Markdown tables (also what fit_walk prints).", {}},
      {"fit_walk_config.yaml", "The keys fit_walk ran with, merged.", {}},
  };
  return outputs;
}

}  // namespace leglab::experiments
