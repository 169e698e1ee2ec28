// fit_walk: recovers the walk behind the paper's Table 2 from its direct-method row alone
// (issue 12). The paper names only the walk's origin (the UT Austin Villa 2003 half-ellipse)
// and its step time; the unknowns of the desired trajectory (where the locus sits below the
// shoulder, the body's pitch, the locus skew, which cited offset is forward, the ground
// fraction) are fitted, each inside a range justified from the cited walk and the ERS-210A's
// geometry, to the direct method's eight numbers: joint L2 and L-infinity of Des vs Dir and
// the foot's L2 and L-infinity. Nothing else of Table 2 is used: the time-shift and
// model-based rows stay held out. The plant is the config's (as shipped), t_step its
// track.t_step_ticks (88). Writes walk_fit.json and walk_fit.md into --out.
//
// The fit is deterministic: a fixed grid over the ranges, then a Nelder-Mead polish (fixed
// start simplex, fixed iteration count) from the best grid point of each offset reading.
// Each evaluation runs the direct mode alone for one warm-up and two measured steps (the
// direct method's error is periodic after one step) with the model fixed (direct does not
// use it); the fitted walk is then run with the config's own warmup_steps and steps, and the
// residuals reported are that run's.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "leglab/experiments/output.h"
#include "leglab/experiments/parallel.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/model/paper.h"

namespace {

using namespace leglab;
using namespace leglab::experiments;

// One continuous unknown of the walk: its config key, the range the fit may use and why.
struct Unknown {
  const char* key;
  double min;
  double max;
  const char* why;
};

// The continuous unknowns, in the order of the fit's vector.
constexpr std::array<Unknown, 4> kUnknowns = {{
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
constexpr int kTargets = 8;
struct Target {
  std::string name;
  double paper;
};

std::array<Target, kTargets> Targets() {
  const paper::Table2Row& l2 = *paper::FindTable2Row("L2(Des,Dir)");
  const paper::Table2Row& linf = *paper::FindTable2Row("Linf(Des,Dir)");
  const paper::FootRow& foot = *paper::FindFootRow("direct");
  std::array<Target, kTargets> t;
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string joint(kLegJointNames[j]);
    t[j] = {"L2(Des,Dir)." + joint + "_deg", l2.mean_deg[j]};
    t[3 + j] = {"Linf(Des,Dir)." + joint + "_deg", linf.mean_deg[j]};
  }
  t[6] = {"foot.direct.l2_cm", foot.l2_cm.mean};
  t[7] = {"foot.direct.linf_cm", foot.linf_cm.mean};
  return t;
}

// A walk: the offset reading and the continuous unknowns.
struct Walk {
  int offsets = 0;
  std::array<double, kUnknowns.size()> x{};
};

void Apply(const Walk& walk, ExperimentConfig& config) {
  LocusConfig& locus = config.track.locus;
  locus.forward_mm = kOffsetReadings[walk.offsets].forward_mm;
  locus.outward_mm = kOffsetReadings[walk.offsets].outward_mm;
  locus.ground_below_shoulder_mm = walk.x[0];
  locus.body_pitch_deg = walk.x[1];
  locus.shape.skew = walk.x[2];
  locus.shape.ground_fraction = walk.x[3];
}

struct Evaluation {
  bool feasible = false;
  std::string infeasible;  // why not (the unreachable point)
  std::array<double, kTargets> values{};
  double cost = std::numeric_limits<double>::infinity();
};

// Sum of squared relative residuals: each of the eight numbers counts alike.
double Cost(const std::array<double, kTargets>& values, const std::array<Target, kTargets>& t) {
  double cost = 0.0;
  for (int i = 0; i < kTargets; ++i) {
    const double r = (values[i] - t[i].paper) / t[i].paper;
    cost += r * r;
  }
  return cost;
}

// The direct method's row on `walk`: `base` runs the direct mode only.
Evaluation Evaluate(const ExperimentConfig& base, const Walk& walk,
                    const std::array<Target, kTargets>& targets) {
  ExperimentConfig config = base;
  Apply(walk, config);
  Evaluation e;
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
  Walk walk;
  Evaluation fit_evaluation;  // at the cheap evaluation's steps
  long evaluations = 0;
  long feasible_evaluations = 0;
};

// Nelder-Mead in the unit box (points clamped into it), fixed start simplex and iteration
// count: the same bits on every run.
Walk Polish(const ExperimentConfig& base, Walk start, const std::array<Target, kTargets>& targets,
            long& evaluations) {
  constexpr int n = kUnknowns.size();
  using Point = std::array<double, n>;
  auto walk_at = [&](const Point& u) {
    Walk w = start;
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

FitResult Fit(const ExperimentConfig& base, const std::array<Target, kTargets>& targets) {
  // The grid, every offset reading; evaluated in parallel, each point writing only its own
  // slot, so the result does not depend on the thread count.
  std::vector<Walk> grid;
  for (int o = 0; o < static_cast<int>(kOffsetReadings.size()); ++o) {
    for (int a = 0; a < kGrid[0]; ++a) {
      for (int b = 0; b < kGrid[1]; ++b) {
        for (int c = 0; c < kGrid[2]; ++c) {
          for (int d = 0; d < kGrid[3]; ++d) {
            Walk w;
            w.offsets = o;
            const std::array<int, 4> idx = {a, b, c, d};
            for (int i = 0; i < 4; ++i) w.x[i] = FromUnit(i, idx[i] / (kGrid[i] - 1.0));
            grid.push_back(w);
          }
        }
      }
    }
  }
  std::vector<Evaluation> scores(grid.size());
  ParallelFor(static_cast<int>(grid.size()), base.threads,
              [&](int i) { scores[i] = Evaluate(base, grid[i], targets); });
  FitResult fit;
  fit.evaluations = static_cast<long>(grid.size());
  fit.feasible_evaluations =
      std::count_if(scores.begin(), scores.end(), [](const Evaluation& e) { return e.feasible; });
  // Polish the best grid point of each offset reading (in parallel), keep the better.
  std::vector<Walk> starts;
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
  std::vector<Walk> polished(starts.size());
  std::vector<long> counts(starts.size(), 0);
  ParallelFor(static_cast<int>(starts.size()), base.threads,
              [&](int i) { polished[i] = Polish(base, starts[i], targets, counts[i]); });
  for (long c : counts) fit.evaluations += c;
  bool first = true;
  for (const Walk& w : polished) {
    const Evaluation e = Evaluate(base, w, targets);
    ++fit.evaluations;
    if (first || e.cost < fit.fit_evaluation.cost) {
      fit.walk = w;
      fit.fit_evaluation = e;
      first = false;
    }
  }
  return fit;
}

std::string Fixed(double v, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << v;
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  return RunProgram(
      "fit_walk", "Fit the walk's unknowns (issue 12) to the paper's direct-method row of Table 2",
      argc, argv, [](const ProgramArgs& args, const ExperimentConfig& config) {
        if (!config.track.desired_csv.empty()) {
          throw InputError(
              "desired.csv: fit_walk fits the half-elliptical locus; remove "
              "desired.csv from the config");
        }
        // A --set of a fitted key would be silently replaced by the fit: refuse it.
        for (const std::string& o : args.overrides) {
          const std::string key = o.substr(0, o.find('='));
          bool fitted = key == "desired" || key == "desired.locus" ||
                        key == "desired.locus.forward_mm" || key == "desired.locus.outward_mm";
          for (const Unknown& u : kUnknowns) fitted = fitted || key == u.key;
          if (fitted) {
            throw InputError("--set " + key +
                             ": fit_walk fits this key; set it in the config of a "
                             "track run instead");
          }
        }
        OutputDir out(args.out_dir, {"walk_fit."});
        // The direct mode alone, its model fixed (direct never uses it: no identification).
        std::vector<std::string> overrides = args.overrides;
        overrides.insert(overrides.end(),
                         {"controller.modes=[direct]", "track.search_shift=false",
                          "model={v_max_deg_per_tick: 2.5, theta0_deg: 7.0, lag_ticks: 4, "
                          "accel_ticks: 6}"});
        ExperimentConfig full = LoadExperimentConfig(args.config_path, overrides);
        full.threads = 1;  // the fit runs evaluations in parallel instead
        ExperimentConfig cheap = full;
        cheap.track.warmup_steps = 1;
        cheap.track.steps = 2;
        cheap.threads = config.threads;

        const std::array<Target, kTargets> targets = Targets();
        const FitResult fit = Fit(cheap, targets);
        const Evaluation check = Evaluate(full, fit.walk, targets);
        assert(check.feasible && "the fitted walk was feasible in the fit");

        nlohmann::ordered_json j;
        j["program"] = "fit_walk";
        j["config"] = args.config_path;
        j["overrides"] = args.overrides;
        nlohmann::ordered_json fitted_on = nlohmann::ordered_json::array();
        for (const Target& t : targets) fitted_on.push_back(t.name);
        j["fitted_on"] = fitted_on;
        const OffsetReading& o = kOffsetReadings[fit.walk.offsets];
        nlohmann::ordered_json fitted;
        fitted["desired.locus.forward_mm"] = o.forward_mm;
        fitted["desired.locus.outward_mm"] = o.outward_mm;
        for (size_t i = 0; i < kUnknowns.size(); ++i) fitted[kUnknowns[i].key] = fit.walk.x[i];
        j["fitted"] = fitted;
        nlohmann::ordered_json ranges;
        ranges["desired.locus.{forward_mm,outward_mm}"] = {
            {"choices", {{49.0, 28.0}, {28.0, 49.0}}}, {"why", kOffsetWhy}};
        for (const Unknown& u : kUnknowns) {
          ranges[u.key] = {{"min", u.min}, {"max", u.max}, {"why", u.why}};
        }
        j["ranges"] = ranges;
        nlohmann::ordered_json residuals;
        for (int i = 0; i < kTargets; ++i) {
          residuals[targets[i].name] = {
              {"paper", targets[i].paper},
              {"fitted", check.values[i]},
              {"residual", check.values[i] - targets[i].paper},
              {"relative", (check.values[i] - targets[i].paper) / targets[i].paper}};
        }
        j["residuals"] = residuals;
        j["cost"] = check.cost;
        j["fit"] = {{"warmup_steps", cheap.track.warmup_steps},
                    {"steps", cheap.track.steps},
                    {"evaluations", fit.evaluations},
                    {"grid_feasible", fit.feasible_evaluations},
                    {"cost_at_fit_steps", fit.fit_evaluation.cost},
                    {"checked_with",
                     {{"warmup_steps", full.track.warmup_steps}, {"steps", full.track.steps}}}};

        std::ostringstream md;
        md << "# The walk fitted to the paper's direct-method row (fit_walk)\n\n"
           << "Fitted on: the direct method's joint L2 and L-infinity (Des vs Dir) and foot L2 "
              "and L-infinity, nothing else. Residuals from a run of "
           << full.track.warmup_steps << " + " << full.track.steps << " steps.\n\n"
           << "| unknown | range | fitted | why this range |\n|---|---|---|---|\n"
           << "| forward / outward (mm) | 49 / 28 or 28 / 49 | " << Fixed(o.forward_mm, 0) << " / "
           << Fixed(o.outward_mm, 0) << " | " << kOffsetWhy << " |\n";
        for (size_t i = 0; i < kUnknowns.size(); ++i) {
          md << "| `" << kUnknowns[i].key << "` | [" << FormatDouble(kUnknowns[i].min) << ", "
             << FormatDouble(kUnknowns[i].max) << "] | " << Fixed(fit.walk.x[i], 3) << " | "
             << kUnknowns[i].why << " |\n";
        }
        md << "\n| number | paper | fitted walk | residual | relative |\n|---|---|---|---|---|\n";
        for (int i = 0; i < kTargets; ++i) {
          md << "| " << targets[i].name << " | " << FormatDouble(targets[i].paper) << " | "
             << Fixed(check.values[i], 2) << " | " << Fixed(check.values[i] - targets[i].paper, 2)
             << " | " << Fixed(100.0 * (check.values[i] - targets[i].paper) / targets[i].paper, 0)
             << " % |\n";
        }
        md << "\nCost (sum of squared relative residuals): " << Fixed(check.cost, 4) << "; "
           << fit.evaluations << " evaluations (" << fit.feasible_evaluations << " of the grid's "
           << "points reachable).\n";
        WriteTextFile(out.Path("walk_fit.json"), j.dump(2) + "\n");
        WriteTextFile(out.Path("walk_fit.md"), md.str());
        out.Commit();
        std::cout << md.str();
      });
}
