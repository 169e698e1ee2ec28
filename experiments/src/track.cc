#include "leglab/experiments/track.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "leglab/controller/direct_controller.h"
#include "leglab/model/metrics.h"

namespace leglab::experiments {
namespace {

// Calls fn(i) for i = 0..n-1 on up to `workers` threads; each i writes only its own results,
// so the outcome does not depend on the schedule.
template <typename Fn>
void ParallelFor(int n, int workers, Fn fn) {
  workers = std::max(1, std::min(workers, n));
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    for (int i; (i = next++) < n;) {
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int w = 1; w < workers; ++w) threads.emplace_back(work);
  work();
  for (std::thread& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

int Workers() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

// Per-step values of `per_tick` (steps * period) reduced by `reduce`.
template <typename Reduce>
std::vector<double> PerStep(const std::vector<double>& per_tick, int period, Reduce reduce) {
  std::vector<double> out;
  for (size_t s = 0; s * period < per_tick.size(); ++s) {
    out.push_back(reduce(std::span<const double>(per_tick).subspan(s * period, period)));
  }
  return out;
}

ModeRun RunMode(const ExperimentConfig& config, const TrackResult& r, const std::string& mode,
                int shift) {
  ControllerSpec spec = config.controller;
  spec.mode = mode;
  spec.shift_ticks = shift;
  auto controller = MakeController(spec, r.desired.angles_deg, r.models);
  ModeRun run{mode, shift, {}, {}};
  run.run = RunTracking(config.sim, *controller, r.desired.angles_deg, config.track.warmup_steps,
                        config.track.steps);
  run.foot_error_cm = FootErrorsCm(run.run, r.desired, LegGeometry::Ers210aFrontLeft());
  return run;
}

double MeanFootL2(const ModeRun& run, int period) {
  return MeanAndStd(
             PerStep(run.foot_error_cm, period, [](std::span<const double> v) { return Rms(v); }))
      .mean;
}

}  // namespace

TrackResult RunTrackExperiment(const ExperimentConfig& config) {
  const LegGeometry geometry = LegGeometry::Ers210aFrontLeft();
  TrackResult r;
  r.desired = LoadDesiredMotion(config.track, geometry);
  r.period = static_cast<int>(r.desired.angles_deg.size());
  r.steps = config.track.steps;
  MakePlant(config.sim);  // bad robot input fails here, before any run
  if (config.model) {
    r.models.fill(*config.model);
  } else {
    const auto identified = IdentifyLeg(config);
    for (int j = 0; j < kLegJoints; ++j) r.models[j] = identified[j].fit.params;
    r.models_identified = true;
  }
  // The piecewise-linear approximations model_based follows (it fits the same ones), drawn in
  // every trace as pwl_deg.
  if (config.controller.pwl_segments > r.period) {
    throw InputError("config: controller.pwl_segments must be at most the " +
                     std::to_string(r.period) + " ticks of a step, got " +
                     std::to_string(config.controller.pwl_segments));
  }
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> joint(r.period);
    for (int t = 0; t < r.period; ++t) joint[t] = r.desired.angles_deg[t][j];
    r.approximations[j] = FitPiecewiseLinear(joint, r.models[j].v_max_deg_per_tick,
                                             {.segments = config.controller.pwl_segments});
  }

  for (const std::string& mode : config.modes) {
    if (mode == "time_shift" && config.track.search_shift) {
      std::vector<ModeRun> candidates(r.period);
      ParallelFor(r.period, Workers(), [&](int k) { candidates[k] = RunMode(config, r, mode, k); });
      int best = 0;
      for (int k = 0; k < r.period; ++k) {
        r.shift_search_foot_l2_cm.push_back(MeanFootL2(candidates[k], r.period));
        if (r.shift_search_foot_l2_cm[k] < r.shift_search_foot_l2_cm[best]) best = k;
      }
      r.runs.push_back(std::move(candidates[best]));
    } else {
      r.runs.push_back(RunMode(config, r, mode, config.controller.shift_ticks));
    }
  }
  return r;
}

namespace {

struct Stat {
  MeanStd l2, linf;
};

Stat JointStat(const std::vector<double>& target_cycle, const TrackingRun& run, int joint,
               int period) {
  std::vector<double> l2, linf;
  for (size_t s = 0; s * period < run.measured_deg.size(); ++s) {
    std::vector<double> actual(period);
    for (int t = 0; t < period; ++t) actual[t] = run.measured_deg[s * period + t][joint];
    l2.push_back(RmsDistance(target_cycle, actual));
    linf.push_back(MaxAbsDistance(target_cycle, actual));
  }
  return {MeanAndStd(l2), MeanAndStd(linf)};
}

Stat FootStat(const ModeRun& run, int period) {
  return {MeanAndStd(PerStep(run.foot_error_cm, period, [](auto v) { return Rms(v); })),
          MeanAndStd(PerStep(run.foot_error_cm, period, [](auto v) { return MaxAbs(v); }))};
}

nlohmann::ordered_json Json(const MeanStd& s) { return {{"mean", s.mean}, {"std", s.std}}; }

std::string Cell(const MeanStd& s) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2f (± %.2f)", s.mean, s.std);
  return buffer;
}

// Short labels of the paper's trajectories.
std::string Label(const std::string& mode) {
  if (mode == "direct") return "Dir";
  if (mode == "model_based") return "MB";
  if (mode == "time_shift") return "TS";
  return mode;
}

struct PaperRow {
  const char* key;
  double values[3];
};
constexpr PaperRow kPaperTable2[] = {
    {"L2(Des,Dir)", {31.0, 29.0, 20.1}}, {"Linf(Des,Dir)", {57.2, 59.5, 42.6}},
    {"L2(Des,MB)", {9.1, 10.4, 5.6}},    {"Linf(Des,MB)", {29.4, 24.5, 11.1}},
    {"L2(Pwl,MB)", {2.7, 2.7, 2.6}},     {"Linf(Pwl,MB)", {6.4, 6.0, 6.2}}};

}  // namespace

std::string WriteTable2(const TrackResult& r, const OutputDir& out) {
  const int period = r.period;
  std::array<std::vector<double>, kLegJoints> desired, pwl;
  for (int j = 0; j < kLegJoints; ++j) {
    pwl[j] = r.approximations[j].Sample();
    for (int t = 0; t < period; ++t) desired[j].push_back(r.desired.angles_deg[t][j]);
  }

  nlohmann::ordered_json json;
  json["steps"] = r.steps;
  std::ostringstream md;
  md << "# Table 2: distances between angle trajectories (deg)\n\n"
     << "Mean (± sample std) over " << r.steps << " steps of " << period
     << " ticks; paper values in brackets.\n\n| Comparison | Rotator | Abductor | Knee |\n"
     << "|---|---|---|---|\n";
  auto add_row = [&](const std::string& key, const std::vector<double>* target, const ModeRun& run,
                     bool linf) {
    md << "| " << key;
    for (int j = 0; j < kLegJoints; ++j) {
      const Stat s =
          JointStat(*(target == &desired[0] ? &desired[j] : &pwl[j]), run.run, j, period);
      const MeanStd& v = linf ? s.linf : s.l2;
      json["joints"][kJointNames[j]][key] = Json(v);
      md << " | " << Cell(v);
      for (const PaperRow& p : kPaperTable2) {
        if (key == p.key) md << " [" << p.values[j] << "]";
      }
    }
    md << " |\n";
  };
  for (const ModeRun& run : r.runs) {
    const std::string label = Label(run.mode);
    add_row("L2(Des," + label + ")", &desired[0], run, false);
    add_row("Linf(Des," + label + ")", &desired[0], run, true);
    if (run.mode == "model_based") {
      add_row("L2(Pwl,MB)", &pwl[0], run, false);
      add_row("Linf(Pwl,MB)", &pwl[0], run, true);
    }
  }

  md << "\n# Foot: Euclidean distance between desired and actual foot positions (cm)\n\n"
     << "| Method | L2 | L-infinity | Paper L2 | Paper L-infinity |\n|---|---|---|---|---|\n";
  for (const ModeRun& run : r.runs) {
    const Stat s = FootStat(run, period);
    nlohmann::ordered_json entry;
    if (run.mode == "time_shift") entry["k"] = run.shift_ticks;
    entry["L2"] = Json(s.l2);
    entry["Linf"] = Json(s.linf);
    json["foot_cm"][run.mode] = entry;
    const char* paper = run.mode == "direct"        ? "3.23 (± 0.01) | 4.61 (± 0.05)"
                        : run.mode == "model_based" ? "1.21 (± 0.04) | 2.34 (± 0.12)"
                        : run.mode == "time_shift"  ? "1.55 (± 0.04) | 3.57 (± 0.08)"
                                                    : "|";
    md << "| " << run.mode
       << (run.mode == "time_shift" ? " (k = " + std::to_string(run.shift_ticks) + ")" : "")
       << " | " << Cell(s.l2) << " | " << Cell(s.linf) << " | " << paper << " |\n";
  }
  md << "\nModel " << (r.models_identified ? "identified on the plant" : "from model.* keys")
     << ": ";
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = r.models[j];
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "%s v_max %.2f, theta_0 %.2f, l %d, a %d%s",
                  kJointNames[j], p.v_max_deg_per_tick, p.theta0_deg, p.lag_ticks, p.accel_ticks,
                  j + 1 < kLegJoints ? "; " : ".\n");
    md << buffer;
    json["model"][kJointNames[j]] = {{"v_max_deg_per_tick", p.v_max_deg_per_tick},
                                     {"theta0_deg", p.theta0_deg},
                                     {"lag_ticks", p.lag_ticks},
                                     {"accel_ticks", p.accel_ticks},
                                     {"identified", r.models_identified},
                                     {"pwl_segments", r.approximations[j].num_segments()}};
  }
  WriteTextFile(out.Path("table2.json"), json.dump(2) + '\n');
  WriteTextFile(out.Path("table2.md"), md.str());

  const LegGeometry geometry = LegGeometry::Ers210aFrontLeft();
  for (const ModeRun& run : r.runs) {
    // The identified model's cyclic steady state under this mode's request cycle.
    std::array<std::vector<double>, kLegJoints> model;
    for (int j = 0; j < kLegJoints; ++j) {
      std::vector<double> cycle(period);
      for (int t = 0; t < period; ++t) cycle[t] = run.run.request_deg[t][j];
      model[j] = CyclicSteadyState(r.models[j], cycle);
    }
    CsvWriter trace(out.Path("trace_" + run.mode + ".csv"),
                    {"step", "tick", "joint", "desired_deg", "pwl_deg", "request_deg", "actual_deg",
                     "model_deg"});
    CsvWriter foot(out.Path("foot_" + run.mode + ".csv"),
                   {"step", "tick", "desired_x_cm", "desired_y_cm", "desired_z_cm", "actual_x_cm",
                    "actual_y_cm", "actual_z_cm"});
    for (size_t i = 0; i < run.run.measured_deg.size(); ++i) {
      const long step = static_cast<long>(i / period), tick = static_cast<long>(i % period);
      for (int j = 0; j < kLegJoints; ++j) {
        trace.Cell(step).Cell(tick).Cell(std::string(kJointNames[j]));
        trace.Cell(desired[j][tick]).Cell(pwl[j][tick]).Cell(run.run.request_deg[i][j]);
        trace.Cell(run.run.measured_deg[i][j]).Cell(model[j][tick]);
        trace.EndRow();
      }
      const LegAngles& q = run.run.measured_deg[i];
      const Eigen::Vector3d actual =
          ForwardKinematics(geometry, Eigen::Vector3d(q[0], q[1], q[2]) * (M_PI / 180.0)) / 10.0;
      const Eigen::Vector3d want = r.desired.foot_mm[tick] / 10.0;
      foot.Cell(step).Cell(tick).Cell(want.x()).Cell(want.y()).Cell(want.z());
      foot.Cell(actual.x()).Cell(actual.y()).Cell(actual.z());
      foot.EndRow();
    }
    trace.Close();
    foot.Close();
  }
  if (!r.shift_search_foot_l2_cm.empty()) {
    CsvWriter search(out.Path("shift_search.csv"), {"k", "foot_l2_cm"});
    for (size_t k = 0; k < r.shift_search_foot_l2_cm.size(); ++k) {
      search.Cell(static_cast<long>(k)).Cell(r.shift_search_foot_l2_cm[k]);
      search.EndRow();
    }
    search.Close();
  }
  return md.str();
}

}  // namespace leglab::experiments
