#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/app/output_docs.h"
#include "leglab/core/plant.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/tables.h"
#include "leglab/model/joint_model.h"

/// The tables as files: Markdown for people, JSON and CSV for scripts. Formatting only; every
/// number comes from tables.h (and the paper's from leglab/model/paper.h).
namespace leglab::experiments {

/// Table 1 as Markdown, beside the paper's values.
std::string Table1Markdown(const Table1& table);

/// Table 1 as JSON: joints.<joint>.{v_max_deg_per_tick, theta0_deg, lag_ticks, accel_ticks,
/// fit_rms_deg}, the paper's values, and the plant it was identified on.
std::string Table1Json(const Table1& table, const ExperimentConfig& config);

/// `identify`'s outputs into `out`: table1.json, table1.md and step_<joint>_<theta>.csv
/// (tick,request_deg,actual_deg,model_deg). Returns the Markdown table.
std::string WriteIdentifyOutputs(const std::array<JointIdentification, kLegJoints>& joints,
                                 const ExperimentConfig& config, const OutputDir& out);

/// Table 2 and the foot table as Markdown, the paper's values in brackets.
std::string Table2Markdown(const Table2& table);

/// Table 2 as JSON: steps, joints.<joint>.<row key>.{mean, std},
/// foot_cm.<mode>.{[k,] L2, Linf}, model.<joint>, and on the test stand
/// stand.{carried_weight_n, stance_ticks, modes.<mode>.{slip_mm_per_step, slip_mm, max_slip_mm,
/// stance_fz_n, peak_fz_n, loaded_ticks}}, and `config`'s plant as in table1.json
/// (plant.robot: the robot file; plant.stand on the test stand).
std::string Table2Json(const Table2& table, const ExperimentConfig& config);

/// The file-name prefixes `track` writes (and so replaces in --out): table2., trace_, foot_,
/// each searched mode's search file, each learning mode's <mode>_learning, and each of
/// `external_names`' (ExternalMode::name) <name>_learning (its trace_ and foot_ files are
/// trace_'s and foot_'s).
std::vector<std::string> TrackOutputPrefixes(std::span<const std::string> external_names = {});

/// The file that holds a run's merged keys: `<program>_config.yaml`.
std::string ConfigFileName(const std::string& program);

/// Writes config.merged_yaml into `out` as ConfigFileName(program), after a comment naming what
/// it is, so that a results folder says which settings made it.
void WriteConfigFile(const std::string& program, const ExperimentConfig& config,
                     const OutputDir& out);

/// `track`'s outputs into `out`: table2.json, table2.md, trace_<mode>.csv, foot_<mode>.csv
/// (step,tick,desired_{x,y,z}_cm,actual_{x,y,z}_cm,contact_fz_n,contact_fx_n,contact_fy_n,
/// carriage_z_mm: the stand's instruments last, zeros in the air) and
/// each search's CSV (time_shift's shift_search.csv), and for every mode that is not
/// feed-forward <mode>_learning.csv (step,joint,l2_deg,foot_l2_cm; warm-up steps negative).
/// Returns the Markdown tables.
std::string WriteTrackOutputs(const TrackResult& result, const Table2& table,
                              const ExperimentConfig& config, const OutputDir& out);

/// The columns of step_<joint>_<theta>.csv, one row per recorded tick.
inline constexpr std::array<ColumnDoc, 4> kStepColumns{{
    {"tick", "", "the recorded tick (8 ms), from 0"},
    {"request_deg", "deg", "the square wave's request"},
    {"actual_deg", "deg", "the joint's measured angle"},
    {"model_deg", "deg", "the identified model's cyclic steady state under the request cycle"},
}};

/// The columns of trace_<mode>.csv, one row per measured tick and joint.
inline constexpr std::array<ColumnDoc, 8> kTraceColumns{{
    {"step", "", "the measured step, from 0"},
    {"tick", "", "the tick within the step (8 ms)"},
    {"joint", "", "rotator, abductor or knee"},
    {"desired_deg", "deg", "D: the desired angle"},
    {"pwl_deg", "deg", "P: the mode's piecewise-linear approximation of D"},
    {"request_deg", "deg", "the angle the mode requested"},
    {"actual_deg", "deg", "the measured angle"},
    {"model_deg", "deg",
     "the mode's model's cyclic steady state under the first measured step's requests (NaN "
     "where it has none)"},
}};

/// The columns of foot_<mode>.csv, one row per measured tick: the foot in the body frame (x
/// forward, y left, z up; FootMm), then the stand's instruments as PlantTelemetry declares
/// them (kContactForceColumns, kCarriageColumn; zeros in the air).
inline constexpr std::array<ColumnDoc, 12> kFootColumns = [] {
  std::array<ColumnDoc, 12> columns{{
      {"step", "", "the measured step, from 0"},
      {"tick", "", "the tick within the step (8 ms)"},
      {"desired_x_cm", "cm", "the desired foot position, forward"},
      {"desired_y_cm", "cm", "the desired foot position, left"},
      {"desired_z_cm", "cm", "the desired foot position, up"},
      {"actual_x_cm", "cm", "the foot's position from the measured angles, forward"},
      {"actual_y_cm", "cm", "the foot's position from the measured angles, left"},
      {"actual_z_cm", "cm", "the foot's position from the measured angles, up"},
  }};
  for (size_t i = 0; i < kContactForceColumns.size(); ++i) {
    columns[8 + i] = kContactForceColumns[i].doc;
  }
  columns[11] = kCarriageColumn.doc;
  return columns;
}();

/// The columns of <mode>_learning.csv, one row per step (warm-up steps negative) and joint.
inline constexpr std::array<ColumnDoc, 4> kLearningColumns{{
    {"step", "", "the step; the warm-up's are negative"},
    {"joint", "", "rotator, abductor or knee"},
    {"l2_deg", "deg", "the joint's RMS error over the step"},
    {"foot_l2_cm", "cm", "the foot's RMS distance from its desired path over the step"},
}};

/// The columns of per_step.csv, one row per mode and step (warm-up steps negative).
inline constexpr std::array<ColumnDoc, 6> kPerStepColumns{{
    {"mode", "", "the controller mode"},
    {"step", "", "the step; the warm-up's are negative"},
    {"rotator_l2_deg", "deg", "the rotator's RMS error over the step"},
    {"abductor_l2_deg", "deg", "the abductor's RMS error over the step"},
    {"knee_l2_deg", "deg", "the knee's RMS error over the step"},
    {"foot_l2_cm", "cm", "the foot's RMS distance from its desired path over the step"},
}};

/// The columns of model_estimates.csv (a mode's estimated model after every step) and of
/// plant_models.csv (identify's model of the plant before and after each plant change): the
/// first column says when, then one joint's model per row.
/// The model's four columns are its keys as joint_model.h declares them.
inline constexpr std::array<ColumnDoc, 7> kModelEstimateColumns = [] {
  const JointModelNames& n = kJointModelNames;
  const JointModelDocs& d = kJointModelKeys;
  const auto column = [](std::string_view name, const KeyDoc& doc) {
    return ColumnDoc{name, doc.unit, doc.description};
  };
  return std::array<ColumnDoc, 7>{{
      {"step", "", "the step after which the mode estimated the model"},
      {"joint", "", "rotator, abductor or knee"},
      column(n.v_max_deg_per_tick, d.v_max_deg_per_tick),
      column(n.theta0_deg, d.theta0_deg),
      column(n.lag_ticks, d.lag_ticks),
      column(n.accel_ticks, d.accel_ticks),
      {"fit_rms_deg", "deg", "the fit's RMS residual"},
  }};
}();
inline constexpr std::array<ColumnDoc, 7> kPlantModelColumns = [] {
  std::array<ColumnDoc, 7> columns = kModelEstimateColumns;
  columns[0] = {"from_step", "",
                "the measured step from which the plant is so (0: from the start)"};
  return columns;
}();

/// The columns of a searched mode's search file (time_shift's shift_search.csv), one row per
/// candidate.
inline constexpr std::array<ColumnDoc, 2> kSearchColumns{{
    {"<parameter>", "",
     "the candidate's parameter (time_shift: k, ticks ahead; a mode without one: `candidate`, its "
     "index)"},
    {"foot_l2_cm", "cm", "the candidate's foot L2 distance, mean over the measured steps"},
}};

/// What identify and track write, each file once (the files of identify's logs section are
/// FitServoLogs'): what their `--list-outputs` prints.
std::span<const OutputDoc> IdentifyOutputs();
std::span<const OutputDoc> TrackOutputs();

/// The column names of trace_<mode>.csv (kTraceColumns) and foot_<mode>.csv (kFootColumns).
const std::vector<std::string>& TraceColumns();
const std::vector<std::string>& FootColumns();

/// The rows of trace_<mode>.csv (TraceColumns: a row per measured tick and joint) and
/// foot_<mode>.csv (FootColumns: a row per measured tick) of `run` into `trace` and `foot`: what
/// WriteModeOutputs writes, cell for cell (step and tick as long, joint as text, the rest as
/// double). The sinks' columns must be those.
void ModeTraceRows(const ModeRun& run, const TrackResult& result, RowSink& trace, RowSink& foot);

/// One mode's part of WriteTrackOutputs: trace_<mode>.csv, foot_<mode>.csv and, unless it is
/// feed-forward, <mode>_learning.csv.
void WriteModeOutputs(const ModeRun& run, const TrackResult& result, const OutputDir& out);

/// The rest of WriteTrackOutputs: table2.json, table2.md and each search's CSV. Returns the
/// Markdown tables.
std::string WriteTrackTables(const TrackResult& result, const Table2& table,
                             const ExperimentConfig& config, const OutputDir& out);

}  // namespace leglab::experiments
