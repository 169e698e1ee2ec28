#include "leglab/experiments/tables.h"

#include <algorithm>
#include <array>
#include <span>

namespace leglab::experiments {
namespace {

// Per-step values of `per_tick` (steps * period) reduced by `reduce`.
template <typename Reduce>
std::vector<double> PerStep(const std::vector<double>& per_tick, int period, Reduce reduce) {
  std::vector<double> out;
  for (size_t s = 0; s * period < per_tick.size(); ++s) {
    out.push_back(reduce(std::span<const double>(per_tick).subspan(s * period, period)));
  }
  return out;
}

// L2 or Linf per step between a joint's target cycle and its measured angles.
MeanStd JointDistance(const std::vector<double>& target_cycle, const TrackingRun& run, int joint,
                      int period, bool linf) {
  std::vector<double> per_step;
  for (size_t s = 0; s * period < run.measured_deg.size(); ++s) {
    std::vector<double> actual(period);
    for (int t = 0; t < period; ++t) actual[t] = run.measured_deg[s * period + t][joint];
    per_step.push_back(linf ? MaxAbsDistance(target_cycle, actual)
                            : RmsDistance(target_cycle, actual));
  }
  return MeanAndStd(per_step);
}

}  // namespace

Table1 ComputeTable1(const std::array<JointIdentification, kLegJoints>& joints,
                     const IdentifyConfig& identify) {
  Table1 table;
  for (int j = 0; j < kLegJoints; ++j) table.joints[j] = joints[j].fit;
  table.theta_test_deg = identify.theta_test_deg;
  return table;
}

const Table2Row* Table2::Find(std::string_view key) const {
  for (const Table2Row& row : rows) {
    if (row.key == key) return &row;
  }
  return nullptr;
}

const FootRow* Table2::FindFoot(std::string_view mode) const {
  for (const FootRow& row : foot) {
    if (row.mode == mode) return &row;
  }
  return nullptr;
}

Table2 BeginTable2(const TrackResult& r) {
  Table2 table;
  table.steps = r.steps;
  table.period = r.period;
  table.models = r.context.models;
  table.models_identified = r.models_identified;
  if (r.walk_context) table.walk_models = r.walk_context->models;
  std::array<std::vector<double>, kLegJoints> desired;
  for (int j = 0; j < kLegJoints; ++j) {
    for (int t = 0; t < r.period; ++t) desired[j].push_back(r.context.desired[t][j]);
    table.pwl_segments[j] = r.context.ApproximationSegments();
  }
  // The floor: the same trajectory every step, so one value and no spread.
  std::array<Table2Row, 2> floor_rows{Table2Row{"L2(Des,Floor)", {}},
                                      Table2Row{"Linf(Des,Floor)", {}}};
  std::vector<double> foot_errors(r.period);
  for (int t = 0; t < r.period; ++t) {
    const LegAngles q{r.floor_deg[0][t], r.floor_deg[1][t], r.floor_deg[2][t]};
    foot_errors[t] = (FootMm(r.robot.geometry, q) - r.desired.foot_mm[t]).norm() / 10.0;
  }
  for (int j = 0; j < kLegJoints; ++j) {
    floor_rows[0].joints[j] = {RmsDistance(desired[j], r.floor_deg[j]), 0.0};
    floor_rows[1].joints[j] = {MaxAbsDistance(desired[j], r.floor_deg[j]), 0.0};
  }
  table.rows.assign(floor_rows.begin(), floor_rows.end());
  if (r.stand_weight_n > 0.0) {
    StandTable stand;
    stand.carried_weight_n = r.stand_weight_n;
    double ground_z = r.desired.foot_mm[0].z();
    for (const Eigen::Vector3d& p : r.desired.foot_mm) ground_z = std::min(ground_z, p.z());
    for (int t = 0; t < r.period; ++t) {
      if (r.desired.foot_mm[t].z() <= ground_z + 0.01) stand.stance_ticks.push_back(t);
    }
    table.stand = std::move(stand);
  }
  table.foot.push_back({"floor", {}, {Rms(foot_errors), 0.0}, {MaxAbs(foot_errors), 0.0}});
  return table;
}

void AddModeToTable2(Table2& table, const ModeRun& run, const TrackResult& r) {
  std::array<std::vector<double>, kLegJoints> desired, pwl;
  const ControllerModeInfo mode = ModeInfo(run);
  const bool follows = mode.follows_approximation;
  for (int j = 0; j < kLegJoints; ++j) {
    // The mode's own P, for a mode that follows one (P is fitted on first use).
    if (follows) pwl[j] = ContextFor(r, run).Approximation(j).Sample();
    for (int t = 0; t < r.period; ++t) desired[j].push_back(r.context.desired[t][j]);
  }
  auto add_rows = [&](const std::string& target, const std::array<std::vector<double>, 3>& cycle) {
    const std::string label(mode.label);
    for (const bool linf : {false, true}) {
      Table2Row row{std::string(linf ? "Linf(" : "L2(") + target + "," + label + ")", {}};
      for (int j = 0; j < kLegJoints; ++j) {
        row.joints[j] = JointDistance(cycle[j], run.run, j, r.period, linf);
      }
      table.rows.push_back(std::move(row));
    }
  };
  add_rows("Des", desired);
  if (follows) add_rows("Pwl", pwl);
  auto rms = [](std::span<const double> v) { return Rms(v); };
  auto max_abs = [](std::span<const double> v) { return MaxAbs(v); };
  // An external mode has no registered options to report.
  table.foot.push_back({std::string(mode.name),
                        run.external.empty() ? ModeParameters(run.spec)
                                             : std::vector<std::pair<std::string_view, long>>{},
                        MeanAndStd(PerStep(run.foot_error_cm, r.period, rms)),
                        MeanAndStd(PerStep(run.foot_error_cm, r.period, max_abs))});
  if (table.stand) table.stand->modes.push_back(ComputeStandRow(run, *table.stand, r.period));
}

StandRow ComputeStandRow(const ModeRun& run, const StandTable& stand, int period) {
  StandRow row;
  row.mode = std::string(ModeInfo(run).name);
  const std::vector<PlantTelemetry>& m = run.run.telemetry;
  std::vector<double> stance_fz;
  std::vector<double> ground_phase_fz;
  std::array<std::vector<double>, 2> sled_travel;  // x, y
  double loaded = 0.0;
  double slip_before = run.run.telemetry_before.slip_mm;
  for (size_t s = 0; (s + 1) * period <= m.size(); ++s) {
    const size_t first = s * period;
    const double slip_after = m[first + period - 1].slip_mm;
    row.slip_mm.push_back(slip_after - slip_before);
    slip_before = slip_after;
    double fz = 0.0;
    for (const int t : stand.stance_ticks) fz += m[first + t].contact_force_n[2];
    ground_phase_fz.push_back(
        stand.stance_ticks.empty() ? 0.0 : fz / static_cast<double>(stand.stance_ticks.size()));
    // The plant's own stance: the ticks its foot was loaded.
    double loaded_fz = 0.0;
    int loaded_here = 0;
    std::array<double, 2> sled_low{m[first].sled_x_mm, m[first].sled_y_mm};
    std::array<double, 2> sled_high = sled_low;
    for (int t = 0; t < period; ++t) {
      const std::array<double, 2> sled{m[first + t].sled_x_mm, m[first + t].sled_y_mm};
      for (int axis = 0; axis < 2; ++axis) {
        sled_low[axis] = std::min(sled_low[axis], sled[axis]);
        sled_high[axis] = std::max(sled_high[axis], sled[axis]);
      }
      const double f = m[first + t].contact_force_n[2];
      row.peak_fz_n = std::max(row.peak_fz_n, f);
      if (f > kLoadedFzN) {
        loaded_fz += f;
        ++loaded_here;
      }
    }
    loaded += loaded_here;
    for (int axis = 0; axis < 2; ++axis) {
      sled_travel[axis].push_back(sled_high[axis] - sled_low[axis]);
    }
    stance_fz.push_back(loaded_here > 0 ? loaded_fz / loaded_here : 0.0);
  }
  row.slip_stat_mm = MeanAndStd(row.slip_mm);
  for (const double s : row.slip_mm) row.max_slip_mm = std::max(row.max_slip_mm, s);
  row.stance_fz_n = MeanAndStd(stance_fz);
  row.ground_phase_fz_n = MeanAndStd(ground_phase_fz);
  row.sled_travel_x_mm = MeanAndStd(sled_travel[0]);
  row.sled_travel_y_mm = MeanAndStd(sled_travel[1]);
  row.loaded_ticks = row.slip_mm.empty() ? 0.0 : loaded / static_cast<double>(row.slip_mm.size());
  return row;
}

Table2 ComputeTable2(const TrackResult& r) {
  Table2 table = BeginTable2(r);
  for (const ModeRun& run : r.runs) AddModeToTable2(table, run, r);
  return table;
}

std::vector<LearningStep> LearningCurve(const ModeRun& run, const TrackResult& r) {
  std::vector<LegAngles> all = run.run.warmup_measured_deg;
  all.insert(all.end(), run.run.measured_deg.begin(), run.run.measured_deg.end());
  const long warmup = static_cast<long>(run.run.warmup_measured_deg.size()) / r.period;
  std::vector<LearningStep> curve;
  for (size_t s = 0; (s + 1) * r.period <= all.size(); ++s) {
    LearningStep step;
    step.step = static_cast<long>(s) - warmup;
    std::vector<double> foot(r.period);
    for (int j = 0; j < kLegJoints; ++j) {
      std::vector<double> desired(r.period), actual(r.period);
      for (int t = 0; t < r.period; ++t) {
        desired[t] = r.context.desired[t][j];
        actual[t] = all[s * r.period + t][j];
      }
      step.l2_deg[j] = RmsDistance(desired, actual);
    }
    for (int t = 0; t < r.period; ++t) {
      foot[t] =
          (FootMm(r.robot.geometry, all[s * r.period + t]) - r.desired.foot_mm[t]).norm() / 10.0;
    }
    step.foot_l2_cm = Rms(foot);
    curve.push_back(step);
  }
  return curve;
}

}  // namespace leglab::experiments
