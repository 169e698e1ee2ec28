#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/tables.h"

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

/// The columns of trace_<mode>.csv: step, tick, joint, and the joint's desired_deg, pwl_deg,
/// request_deg, actual_deg and model_deg (its model's cyclic steady state under the requests of
/// the first measured step; NaN where it has none).
const std::vector<std::string>& TraceColumns();

/// The columns of foot_<mode>.csv: step, tick, the foot's desired and actual position
/// ({desired,actual}_{x,y,z}_cm), and the stand's instruments (contact_fz_n, contact_fx_n,
/// contact_fy_n, carriage_z_mm; zeros in the air).
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
