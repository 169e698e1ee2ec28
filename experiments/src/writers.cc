#include "leglab/experiments/writers.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "leglab/core/format.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/paper.h"

namespace leglab::experiments {
namespace {

using Json = nlohmann::ordered_json;

// The model_deg column: the model's cyclic steady state under a request cycle, or NaN ("nan"
// in the CSV) on every tick when the model has none (with v_max >= 2 theta_0 eq. 3 can swing
// for ever, SettlesOnEveryCycle; identified models never do, kMaxFittedSpeedRatio): a diagnostic
// column that cannot be computed is marked, not an error that loses the run.
std::vector<double> ModelColumn(const JointModelParams& params, const std::vector<double>& cycle) {
  try {
    return CyclicSteadyState(params, cycle);
  } catch (const std::runtime_error&) {
    return std::vector<double>(cycle.size(), std::numeric_limits<double>::quiet_NaN());
  }
}

std::string ThetaLabel(double theta) {
  return theta == std::round(theta) ? std::to_string(static_cast<long>(theta))
                                    : FormatDouble(theta);
}

// A joint model's values under its keys' names (VisitKeys), integers as integers.
Json ModelJson(const JointModelParams& p) {
  Json json = Json::object();
  const auto visit = [](KeyVisitor& v, JointModelParams& m) { VisitKeys(v, m, kAnyJointModel); };
  for (const KeyValue& k : KeyValues(p, visit)) {
    json[k.key] = k.integer ? Json(static_cast<long>(k.value)) : Json(k.value);
  }
  return json;
}

Json StatJson(const MeanStd& s) { return {{"mean", s.mean}, {"std", s.std}}; }

std::string Cell(const MeanStd& s) {
  return FormatFixed(s.mean, 2) + " (± " + FormatFixed(s.std, 2) + ")";
}

}  // namespace

std::string Table1Markdown(const Table1& table) {
  const JointModelParams& paper = paper::kTable1;
  std::ostringstream md;
  md << "# Table 1: model parameters\n\n"
     << "Identified from the simulated leg's step tests (eq. 1, theta_test";
  for (double theta : table.theta_test_deg) md << ' ' << ThetaLabel(theta);
  md << " deg), beside the paper's values.\n\n"
     << "| Parameter | Description | Paper | Rotator | Abductor | Knee |\n"
     << "|---|---|---|---|---|---|\n";
  auto row = [&](const char* symbol, const char* description, const std::string& paper_value,
                 auto value_of) {
    md << "| " << symbol << " | " << description << " | " << paper_value;
    for (const IdentificationResult& joint : table.joints) md << " | " << value_of(joint);
    md << " |\n";
  };
  row("v_max", "Maximum angular speed (deg/t_u)", FormatFixed(paper.v_max_deg_per_tick, 1),
      [](const IdentificationResult& j) { return FormatFixed(j.params.v_max_deg_per_tick, 2); });
  row("theta_0", "Angle difference threshold (deg)", FormatFixed(paper.theta0_deg, 1),
      [](const IdentificationResult& j) { return FormatFixed(j.params.theta0_deg, 2); });
  row("l", "Lag time (t_u)", std::to_string(paper.lag_ticks),
      [](const IdentificationResult& j) { return std::to_string(j.params.lag_ticks); });
  row("a", "Acceleration time (t_u)", std::to_string(paper.accel_ticks),
      [](const IdentificationResult& j) { return std::to_string(j.params.accel_ticks); });
  row("", "Fit RMS residual (deg)", "",
      [](const IdentificationResult& j) { return FormatFixed(j.rms_residual_deg, 3); });
  md << "\nt_u = 8 ms.\n";
  return md.str();
}

namespace {

// The plant a table was made on: the robot file, its servo and sensor, the stand (on it) and
// the model (a model plant); the same block in table1.json and table2.json.
Json PlantJson(const ExperimentConfig& config) {
  Json plant = {{"robot", config.robot_yaml},
                {"delay_ms", config.sim.servo.delay_ms},
                {"max_speed_deg_s", config.sim.servo.max_speed_deg_s},
                {"gain_per_s", config.sim.servo.gain_per_s},
                {"smoothing_ms", config.sim.servo.smoothing_ms},
                {"max_torque_nm", config.sim.servo.max_torque_nm},
                {"noise_deg", config.sim.sensor.noise_deg},
                {"seed", config.sim.seed}};
  if (config.sim.stand.enabled && config.plant == PlantKind::kSim) {
    const sim::StandConfig& stand = config.sim.stand;
    plant["stand"] = {{"load_kg", stand.load_kg},
                      {"stop_below_shoulder_mm", stand.stop_below_shoulder_mm},
                      {"friction", stand.friction},
                      {"contact_stiffness_n_per_m", stand.contact_stiffness_n_per_m},
                      {"contact_damping_n_s_per_m", stand.contact_damping_n_s_per_m},
                      {"foot_radius_mm", stand.foot_radius_mm},
                      {"ground_below_shoulder_mm", stand.ground_below_shoulder_mm},
                      {"sled_stiffness_n_per_m", stand.sled_stiffness_n_per_m},
                      {"sled_damping_n_s_per_m", stand.sled_damping_n_s_per_m}};
  }
  if (config.plant == PlantKind::kModel) {
    plant["kind"] = "model";
    plant["model"] = ModelJson(config.plant_model);
  }
  return plant;
}

}  // namespace

std::string Table1Json(const Table1& table, const ExperimentConfig& config) {
  Json json;
  for (int j = 0; j < kLegJoints; ++j) {
    Json joint = ModelJson(table.joints[j].params);
    joint["fit_rms_deg"] = table.joints[j].rms_residual_deg;
    json["joints"][std::string(kLegJointNames[j])] = joint;
  }
  json["paper"] = ModelJson(paper::kTable1);
  json["plant"] = PlantJson(config);
  return json.dump(2) + '\n';
}

std::string WriteIdentifyOutputs(const std::array<JointIdentification, kLegJoints>& joints,
                                 const ExperimentConfig& config, const OutputDir& out) {
  const Table1 table = ComputeTable1(joints, config.identify);
  WriteTextFile(out.Path("table1.json"), Table1Json(table, config));
  std::string md = Table1Markdown(table);
  WriteTextFile(out.Path("table1.md"), md);
  const int period = config.identify.t_step_ticks;
  for (const JointIdentification& joint : joints) {
    for (const StepTestRun& run : joint.runs) {
      const JointRecording& r = run.recording;
      // The model column: the identified model's cyclic steady state under the request cycle.
      const std::vector<double> model =
          ModelColumn(joint.fit.params,
                      std::vector<double>(r.request_deg.begin(), r.request_deg.begin() + period));
      CsvWriter csv(out.Path("step_" + std::string(kLegJointNames[run.joint]) + "_" +
                             ThetaLabel(run.theta_test_deg) + ".csv"),
                    ColumnNames(kStepColumns));
      for (size_t t = 0; t < r.request_deg.size(); ++t) {
        csv.Cell(static_cast<long>(t))
            .Cell(r.request_deg[t])
            .Cell(r.measured_deg[t])
            .Cell(model[t % period]);
        csv.EndRow();
      }
      csv.Close();
    }
  }
  return md;
}

std::string Table2Markdown(const Table2& table) {
  std::ostringstream md;
  md << "# Table 2: distances between angle trajectories (deg)\n\n"
     << "Mean (± sample std) over " << table.steps << " steps of " << table.period
     << " ticks; paper values in brackets. Floor: the cyclic trajectory nearest the desired "
        "one that a joint with the model's top speed and acceleration time could follow at all "
        "(a bound for every policy that respects the model).\n\n"
     << "| Comparison | Rotator | Abductor | Knee |\n"
     << "|---|---|---|---|\n";
  for (const Table2Row& row : table.rows) {
    const paper::Table2Row* paper_row = paper::FindTable2Row(row.key);
    md << "| " << row.key;
    for (int j = 0; j < kLegJoints; ++j) {
      md << " | " << Cell(row.joints[j]);
      if (paper_row) md << " [" << paper_row->mean_deg[j] << "]";
    }
    md << " |\n";
  }
  md << "\n# Foot: Euclidean distance between desired and actual foot positions (cm)\n\n"
     << "| Method | L2 | L-infinity | Paper L2 | Paper L-infinity |\n|---|---|---|---|---|\n";
  for (const FootRow& row : table.foot) {
    md << "| " << row.mode;
    for (const auto& [name, value] : row.parameters) {
      md << " (" << name << " = " << value << ")";
    }
    md << " | " << Cell(row.l2_cm) << " | " << Cell(row.linf_cm) << " | ";
    if (const paper::FootRow* paper_row = paper::FindFootRow(row.mode)) {
      md << Cell(paper_row->l2_cm) << " | " << Cell(paper_row->linf_cm);
    } else {
      md << "|";
    }
    md << " |\n";
  }
  if (table.stand) {
    const StandTable& stand = *table.stand;
    md << "\n# The stand: the floor under the foot\n\n"
       << "Carried weight " << FormatFixed(stand.carried_weight_n, 2)
       << " N (load and leg). Stance: the ticks the foot carries more than 0.1 N; ground phase: "
          "the "
       << stand.stance_ticks.size()
       << " ticks the desired foot is on the ground. Slip: how far the ball of the foot slid "
          "along the belt while loaded, per step (rolling excluded).\n\n"
       << "| Method | stance Fz (N) | stance Fz / weight | ground-phase Fz (N) | peak Fz (N) | "
          "stance ticks | slip per step (mm) | max slip (mm) |\n"
          "|---|---|---|---|---|---|---|---|\n";
    for (const StandRow& row : stand.modes) {
      md << "| " << row.mode << " | " << Cell(row.stance_fz_n) << " | "
         << FormatFixed(row.stance_fz_n.mean / stand.carried_weight_n, 3) << " | "
         << Cell(row.ground_phase_fz_n) << " | " << FormatFixed(row.peak_fz_n, 2) << " | "
         << FormatFixed(row.loaded_ticks, 1) << " | " << Cell(row.slip_stat_mm) << " | "
         << FormatFixed(row.max_slip_mm, 3) << " |\n";
    }
  }
  auto models = [&md](const std::array<JointModelParams, kLegJoints>& params) {
    for (int j = 0; j < kLegJoints; ++j) {
      const JointModelParams& p = params[j];
      // FormatFixed() grows with the number: a model's line is never cut.
      md << kLegJointNames[j] << " v_max " << FormatFixed(p.v_max_deg_per_tick, 2) << ", theta_0 "
         << FormatFixed(p.theta0_deg, 2) << ", l " << p.lag_ticks << ", a " << p.accel_ticks
         << (j + 1 < kLegJoints ? "; " : ".\n");
    }
  };
  md << "\nModel " << (table.models_identified ? "identified on the plant" : "from model.* keys")
     << ": ";
  models(table.models);
  if (table.walk_models) {
    md << "Model fitted to the walk (the modes with `model: walk`): ";
    models(*table.walk_models);
  }
  return md.str();
}

std::string Table2Json(const Table2& table, const ExperimentConfig& config) {
  Json json;
  json["steps"] = table.steps;
  json["plant"] = PlantJson(config);
  for (const Table2Row& row : table.rows) {
    for (int j = 0; j < kLegJoints; ++j) {
      json["joints"][std::string(kLegJointNames[j])][row.key] = StatJson(row.joints[j]);
    }
  }
  for (const FootRow& row : table.foot) {
    Json entry;
    for (const auto& [name, value] : row.parameters) entry[std::string(name)] = value;
    entry["L2"] = StatJson(row.l2_cm);
    entry["Linf"] = StatJson(row.linf_cm);
    json["foot_cm"][row.mode] = entry;
  }
  for (int j = 0; j < kLegJoints; ++j) {
    Json model = ModelJson(table.models[j]);
    model["identified"] = table.models_identified;
    model["pwl_segments"] = table.pwl_segments[j];
    json["model"][std::string(kLegJointNames[j])] = model;
    if (table.walk_models) {
      json["walk_model"][std::string(kLegJointNames[j])] = ModelJson((*table.walk_models)[j]);
    }
  }
  if (table.stand) {
    const StandTable& stand = *table.stand;
    Json entry;
    entry["carried_weight_n"] = stand.carried_weight_n;
    entry["ground_phase_ticks"] = stand.stance_ticks.size();
    for (const StandRow& row : stand.modes) {
      entry["modes"][row.mode] = {{"slip_mm_per_step", row.slip_mm},
                                  {"slip_mm", StatJson(row.slip_stat_mm)},
                                  {"max_slip_mm", row.max_slip_mm},
                                  {"stance_fz_n", StatJson(row.stance_fz_n)},
                                  {"ground_phase_fz_n", StatJson(row.ground_phase_fz_n)},
                                  {"peak_fz_n", row.peak_fz_n},
                                  {"loaded_ticks", row.loaded_ticks},
                                  {"sled_travel_x_mm", StatJson(row.sled_travel_x_mm)},
                                  {"sled_travel_y_mm", StatJson(row.sled_travel_y_mm)}};
    }
    json["stand"] = entry;
  }
  return json.dump(2) + '\n';
}

std::string ConfigFileName(const std::string& program) { return program + "_config.yaml"; }

void WriteConfigFile(const std::string& program, const ExperimentConfig& config,
                     const OutputDir& out) {
  WriteTextFile(out.Path(ConfigFileName(program)),
                "# The keys " + program +
                    " ran with: its config, the files it extends, the robot file and the --set "
                    "overrides, merged.\n" +
                    config.merged_yaml);
}

std::vector<std::string> TrackOutputPrefixes(std::span<const std::string> external_names) {
  std::vector<std::string> prefixes = {"table2.",          "trace_",          "foot_",
                                       "per_step.",        "model_estimates", "plant_models.",
                                       "track_config.yaml"};
  for (const ControllerModeInfo& mode : ControllerModes()) {
    if (mode.searchable) prefixes.push_back(std::string(mode.search_file) + ".");
    if (!mode.feed_forward) prefixes.push_back(std::string(mode.name) + "_learning.");
  }
  // An external mode is never feed-forward (ModeInfo): it writes a learning curve.
  for (const std::string& name : external_names) prefixes.push_back(name + "_learning.");
  return prefixes;
}

const std::vector<std::string>& TraceColumns() {
  static const std::vector<std::string> columns = ColumnNames(kTraceColumns);
  return columns;
}

const std::vector<std::string>& FootColumns() {
  static const std::vector<std::string> columns = ColumnNames(kFootColumns);
  return columns;
}

// The fields of table1.json and table2.json, as dotted paths (`<...>`: a key named at run time).
constexpr ColumnDoc kPlantFields[] = {
    {"plant.<setting>", "",
     "the plant it ran on: robot (its file), the servo's delay_ms, max_speed_deg_s, gain_per_s, "
     "smoothing_ms and max_torque_nm, the sensor's noise_deg and the seed, as the config names "
     "them"},
    {"plant.stand.<setting>", "",
     "on the test stand, its settings as the config names them (robot.yaml's stand.*)"},
    {"plant.kind", "", "with plant: model, `model`"},
    {"plant.model.<value>", "", "with plant: model, the joint model it ran (as model.*)"},
};
constexpr ColumnDoc kTable1Fields[] = {
    {"joints.<joint>.v_max_deg_per_tick", "deg/tick", "v_max identified: the top speed"},
    {"joints.<joint>.theta0_deg", "deg", "theta_0 identified: the error at the top speed"},
    {"joints.<joint>.lag_ticks", "ticks", "l identified: ticks before a request acts"},
    {"joints.<joint>.accel_ticks", "ticks", "a identified: ticks to reach a new speed"},
    {"joints.<joint>.fit_rms_deg", "deg", "the fit's RMS residual over the step tests"},
    {"paper.<value>", "", "the paper's Table 1 model, the same four values"},
    kPlantFields[0],
    kPlantFields[1],
    kPlantFields[2],
    kPlantFields[3],
};
constexpr ColumnDoc kTable2Fields[] = {
    {"steps", "", "the measured steps the statistics are over"},
    {"joints.<joint>.<row>.<stat>", "deg",
     "Table 2: the row's norm (L2 or Linf of one trajectory against another, e.g. L2(Des,MB)) "
     "over a step, its mean or std over the measured steps"},
    {"foot_cm.<mode>.L2.<stat>", "cm",
     "the foot's RMS distance from its desired path over a step, its mean or std; `floor` is "
     "the joints' floors put together"},
    {"foot_cm.<mode>.Linf.<stat>", "cm", "the foot's greatest distance, likewise"},
    {"foot_cm.<mode>.<parameter>", "",
     "a mode's own parameters, as it declares them (time_shift's k: the shift, ticks)"},
    {"model.<joint>.<value>", "", "the model the modes ran with: its four values (as model.*)"},
    {"model.<joint>.pwl_segments", "", "its piecewise-linear approximation's segments"},
    {"model.<joint>.identified", "", "true when identify found the model on the plant"},
    {"walk_model.<joint>.<value>", "", "with a walk-fitted model, its four values"},
    {"stand.carried_weight_n", "N", "on the test stand, the weight the foot carries at rest"},
    {"stand.ground_phase_ticks", "ticks", "the ticks of a step the locus has the foot down"},
    {"stand.modes.<mode>.stance_fz_n.<stat>", "N",
     "the floor's normal force over the stance, mean over a step, its mean or std over the "
     "steps"},
    {"stand.modes.<mode>.ground_phase_fz_n.<stat>", "N", "the same over the ground phase"},
    {"stand.modes.<mode>.peak_fz_n", "N", "the largest normal force"},
    {"stand.modes.<mode>.loaded_ticks", "ticks", "the ticks a step the foot is loaded, mean"},
    {"stand.modes.<mode>.slip_mm.<stat>", "mm", "the foot's slip per step, mean or std"},
    {"stand.modes.<mode>.slip_mm_per_step", "mm", "the foot's slip, step by step (a list)"},
    {"stand.modes.<mode>.max_slip_mm", "mm", "the most a step slipped"},
    {"stand.modes.<mode>.sled_travel_x_mm.<stat>", "mm",
     "the sled's travel forward over a step, mean or std"},
    {"stand.modes.<mode>.sled_travel_y_mm.<stat>", "mm", "the same to the left"},
    kPlantFields[0],
    kPlantFields[1],
    kPlantFields[2],
    kPlantFields[3],
};

std::span<const OutputDoc> IdentifyOutputs() {
  static const OutputDoc step_tests[] = {
      {"table1.json",
       "Without a logs section, Table 1: each joint's identified model, the paper's values and "
       "the plant it was identified on.",
       kTable1Fields},
      {"table1.md", "Without a logs section: Table 1 as Markdown, beside the paper's values.", {}},
      {"step_<joint>_<theta>.csv",
       "Without a logs section: one step test of eq. 1 (joint rotator, abductor or knee; step "
       "height theta in deg) as "
       "recorded, beside the identified model.",
       kStepColumns},
      {"identify_config.yaml",
       "The keys identify ran with: its config, the files it extends, the robot file and the "
       "--set overrides, merged.",
       {}},
  };
  static const std::vector<OutputDoc> outputs = [] {
    std::vector<OutputDoc> all(std::begin(step_tests), std::end(step_tests));
    const std::span<const OutputDoc> logs = LogFitOutputs();
    all.insert(all.end(), logs.begin(), logs.end());
    return all;
  }();
  return outputs;
}

std::span<const OutputDoc> TrackOutputs() {
  static const OutputDoc outputs[] = {
      {"table2.json",
       "Table 2 and the foot table, the models the modes ran with, on the test stand the stand's "
       "numbers per mode, and the plant.",
       kTable2Fields},
      {"table2.md", "Table 2 and the foot table as Markdown, the paper's values in brackets.", {}},
      {"trace_<mode>.csv", "Each joint's angles, tick by tick, under one mode.", kTraceColumns},
      {"foot_<mode>.csv", "The foot's path, tick by tick, under one mode.", kFootColumns},
      {"<mode>_learning.csv",
       "The error step by step of a mode that is not feed-forward (it learns or adapts).",
       kLearningColumns},
      {"per_step.csv", "Every mode's error step by step.", kPerStepColumns},
      {"model_estimates.csv",
       "The models a mode that estimates its model (adaptive) held after every step (a second "
       "such mode's in `model_estimates_<mode>.csv`).",
       kModelEstimateColumns},
      {"plant_models.csv", "With plant_changes: the plant identified before and after each.",
       kPlantModelColumns},
      {"shift_search.csv", "time_shift's candidates, each scored (track.search_shift).",
       kSearchColumns},
      {"track_config.yaml", "The keys track ran with, merged.", {}},
  };
  return outputs;
}

void ModeTraceRows(const ModeRun& run, const TrackResult& r, RowSink& trace, RowSink& foot) {
  const int period = r.period;
  // The mode's own context: its P and its model (the walk-fitted one for `model: walk`).
  const ControllerContext& context = ContextFor(r, run);
  std::array<std::vector<double>, kLegJoints> pwl;
  for (int j = 0; j < kLegJoints; ++j) pwl[j] = context.Approximation(j).Sample();
  std::array<std::vector<double>, kLegJoints> model;
  for (int j = 0; j < kLegJoints; ++j) {
    std::vector<double> cycle(period);
    for (int t = 0; t < period; ++t) cycle[t] = run.run.request_deg[t][j];
    model[j] = ModelColumn(context.models[j], cycle);
  }
  const std::array<std::string, kLegJoints> joint_names = {std::string(kLegJointNames[0]),
                                                           std::string(kLegJointNames[1]),
                                                           std::string(kLegJointNames[2])};
  for (size_t i = 0; i < run.run.measured_deg.size(); ++i) {
    const long step = static_cast<long>(i / period), tick = static_cast<long>(i % period);
    for (int j = 0; j < kLegJoints; ++j) {
      trace.Cell(step).Cell(tick).Cell(joint_names[j]);
      trace.Cell(r.context.desired[tick][j]).Cell(pwl[j][tick]).Cell(run.run.request_deg[i][j]);
      trace.Cell(run.run.measured_deg[i][j]).Cell(model[j][tick]);
      trace.EndRow();
    }
    const Eigen::Vector3d actual = FootMm(r.robot.geometry, run.run.measured_deg[i]) / 10.0;
    const Eigen::Vector3d want = r.desired.foot_mm[tick] / 10.0;
    foot.Cell(step).Cell(tick).Cell(want.x()).Cell(want.y()).Cell(want.z());
    foot.Cell(actual.x()).Cell(actual.y()).Cell(actual.z());
    // The stand's instruments (zeros in the air), appended so that readers of the first
    // eight columns keep working.
    const PlantTelemetry m = i < run.run.telemetry.size() ? run.run.telemetry[i] : PlantTelemetry{};
    for (const TelemetryColumn& c : kContactForceColumns) foot.Cell(c.value(m));
    foot.Cell(kCarriageColumn.value(m));
    foot.EndRow();
  }
}

namespace {

// The cells of one joint's model in model_estimates.csv and plant_models.csv.
void ModelCells(CsvWriter& csv, int joint, const IdentificationResult& fit) {
  csv.Cell(std::string(kLegJointNames[joint])).Cell(fit.params.v_max_deg_per_tick);
  csv.Cell(fit.params.theta0_deg).Cell(static_cast<long>(fit.params.lag_ticks));
  csv.Cell(static_cast<long>(fit.params.accel_ticks)).Cell(fit.rms_residual_deg);
  csv.EndRow();
}

// trace_<mode>.csv (each joint's desired, P, request, actual and model angle per tick) and
// foot_<mode>.csv (the foot's desired and actual path, and the stand's instruments).
void WriteTraceAndFoot(const ModeRun& run, const TrackResult& r, const OutputDir& out) {
  const std::string mode(ModeInfo(run).name);
  CsvWriter trace(out.Path("trace_" + mode + ".csv"), TraceColumns());
  CsvWriter foot(out.Path("foot_" + mode + ".csv"), FootColumns());
  ModeTraceRows(run, r, trace, foot);
  trace.Close();
  foot.Close();
}

// <mode>_learning.csv, for a learning mode: every step's error, warm-up included (negative steps).
void WriteLearningCurve(const ModeRun& run, const TrackResult& r, const OutputDir& out) {
  CsvWriter csv(out.Path(std::string(ModeInfo(run).name) + "_learning.csv"),
                ColumnNames(kLearningColumns));
  for (const LearningStep& step : LearningCurve(run, r)) {
    for (int j = 0; j < kLegJoints; ++j) {
      csv.Cell(step.step).Cell(std::string(kLegJointNames[j])).Cell(step.l2_deg[j]);
      csv.Cell(step.foot_l2_cm);
      csv.EndRow();
    }
  }
  csv.Close();
}

// per_step.csv: every mode's error every step, warm-up included (negative steps): one table, a
// mode's rows appended as its run finishes.
void AppendPerStep(const ModeRun& run, const TrackResult& r, const OutputDir& out) {
  CsvWriter csv(out.Path("per_step.csv"), ColumnNames(kPerStepColumns), /*append=*/true);
  for (const LearningStep& step : LearningCurve(run, r)) {
    csv.Cell(std::string(ModeInfo(run).name)).Cell(step.step);
    for (int j = 0; j < kLegJoints; ++j) csv.Cell(step.l2_deg[j]);
    csv.Cell(step.foot_l2_cm);
    csv.EndRow();
  }
  csv.Close();
}

// The models a mode estimated after every step (the first such mode's in
// model_estimates.csv, any other's in model_estimates_<mode>.csv).
void WriteModelEstimates(const ModeRun& run, const OutputDir& out) {
  const bool first = !std::filesystem::exists(out.Path("model_estimates.csv"));
  CsvWriter csv(out.Path(first ? std::string("model_estimates.csv")
                               : "model_estimates_" + std::string(ModeInfo(run).name) + ".csv"),
                ColumnNames(kModelEstimateColumns));
  for (const StepModelEstimates& step : run.run.model_estimates) {
    for (int j = 0; j < kLegJoints; ++j) {
      csv.Cell(step.step);
      ModelCells(csv, j, step.joints[j]);
    }
  }
  csv.Close();
}

}  // namespace

void WriteModeOutputs(const ModeRun& run, const TrackResult& r, const OutputDir& out) {
  WriteTraceAndFoot(run, r, out);
  if (!ModeInfo(run).feed_forward) WriteLearningCurve(run, r, out);
  AppendPerStep(run, r, out);
  if (!run.run.model_estimates.empty()) WriteModelEstimates(run, out);
}

std::string WriteTrackTables(const TrackResult& r, const Table2& table,
                             const ExperimentConfig& config, const OutputDir& out) {
  WriteTextFile(out.Path("table2.json"), Table2Json(table, config));
  std::string md = Table2Markdown(table);
  WriteTextFile(out.Path("table2.md"), md);
  // The plant's model as identify finds it before and after each change.
  if (!r.plant_models.empty()) {
    CsvWriter csv(out.Path("plant_models.csv"), ColumnNames(kPlantModelColumns));
    for (const PlantIdentification& plant : r.plant_models) {
      for (int j = 0; j < kLegJoints; ++j) {
        csv.Cell(static_cast<long>(plant.from_step));
        ModelCells(csv, j, plant.joints[j]);
      }
    }
    csv.Close();
  }
  for (const ModeSearch& search : r.searches) {
    const ControllerModeInfo& mode = ModeOf(search.best);
    const auto parameters = ModeParameters(search.best);
    // kSearchColumns, its first column named after the searched parameter.
    std::vector<std::string> columns = ColumnNames(kSearchColumns);
    columns[0] = parameters.empty() ? "candidate" : std::string(parameters[0].first);
    CsvWriter csv(out.Path(std::string(mode.search_file) + ".csv"), columns);
    for (size_t k = 0; k < search.candidates.size(); ++k) {
      const auto p = ModeParameters(search.candidates[k]);
      csv.Cell(p.empty() ? static_cast<long>(k) : p[0].second).Cell(search.foot_l2_cm[k]);
      csv.EndRow();
    }
    csv.Close();
  }
  return md;
}

std::string WriteTrackOutputs(const TrackResult& r, const Table2& table,
                              const ExperimentConfig& config, const OutputDir& out) {
  for (const ModeRun& run : r.runs) WriteModeOutputs(run, r, out);
  return WriteTrackTables(r, table, config, out);
}

}  // namespace leglab::experiments
