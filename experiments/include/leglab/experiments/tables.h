#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "leglab/core/leg.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/track.h"
#include "leglab/model/metrics.h"

/// The paper's tables computed as plain data: the writers (writers.h) format them, the
/// regression test checks them in-process.
namespace leglab::experiments {

/// Table 1: the model identified on each joint.
struct Table1 {
  std::array<IdentificationResult, kLegJoints> joints;
  std::vector<double> theta_test_deg;  ///< the step heights it was identified from
};

/// Table 1 of an identification.
Table1 ComputeTable1(const std::array<JointIdentification, kLegJoints>& joints,
                     const IdentifyConfig& identify);

/// One row of Table 2: a distance between two angle trajectories per joint, deg, as mean and
/// sample std over the measured steps.
struct Table2Row {
  std::string key;  ///< "L2(Des,Dir)", "Linf(Pwl,MB)", ...: table2.json's field name
  std::array<MeanStd, kLegJoints> joints;
};

/// One row of the foot table: the Euclidean foot error, cm.
struct FootRow {
  std::string mode;
  std::vector<std::pair<std::string_view, long>> parameters;  ///< e.g. time_shift's {"k", 8}
  MeanStd l2_cm;
  MeanStd linf_cm;
};

/// One step of a run's learning curve: each joint's L2 distance to D and the foot's, that step.
struct LearningStep {
  long step = 0;  ///< warm-up steps negative, measured steps from 0
  LegAngles l2_deg{};
  double foot_l2_cm = 0.0;
};

/// A tick whose floor force is above this, N, is a stance tick (the foot loaded).
inline constexpr double kLoadedFzN = 0.1;

/// One mode's run on the test stand: what the floor did, per measured step.
struct StandRow {
  std::string mode;
  /// How far the foot slid along the floor while loaded (PlantTelemetry::slip_mm), each step, mm.
  std::vector<double> slip_mm;
  MeanStd slip_stat_mm;      ///< mean and std of slip_mm
  double max_slip_mm = 0.0;  ///< the largest of slip_mm
  /// The floor's mean vertical force over the stance, the ticks the foot carried more than
  /// kLoadedFzN, mean (and std) over the steps, N.
  MeanStd stance_fz_n;
  /// The same over the desired ground phase (StandTable::stance_ticks), N.
  MeanStd ground_phase_fz_n;
  double peak_fz_n = 0.0;  ///< the largest vertical force of any tick, N
  /// Ticks of a step the foot carried more than kLoadedFzN, mean over the steps.
  double loaded_ticks = 0.0;
  /// How far the stand's sled travelled within a step along x and along y (its highest
  /// position minus its lowest), mean (and std) over the steps, mm; 0 without a sled.
  MeanStd sled_travel_x_mm;
  MeanStd sled_travel_y_mm;
};

/// The stand's part of Table 2 (table2.json `stand`).
struct StandTable {
  double carried_weight_n = 0.0;  ///< (stand.load_kg + the leg's mass) x g
  /// The desired ground phase: the ticks where the desired foot is on the walk's ground (its
  /// lowest height, within 0.01 mm), indices within a step.
  std::vector<int> stance_ticks;
  std::vector<StandRow> modes;
};

/// Table 2 and the foot table.
struct Table2 {
  int steps = 0;
  int period = 0;
  /// The floor first (L2(Des,Floor), Linf(Des,Floor): one value, std 0), then per mode: L2
  /// and Linf to D, and to P if it follows P.
  std::vector<Table2Row> rows;
  std::vector<FootRow> foot;  ///< the floor ("floor"), then per mode in run order
  std::array<JointModelParams, kLegJoints> models;
  bool models_identified = false;
  /// The models fitted to the walk (TrackResult::walk_context), when a mode ran with them.
  std::optional<std::array<JointModelParams, kLegJoints>> walk_models;
  std::array<int, kLegJoints> pwl_segments{};
  /// On the test stand: slip and floor force per mode; empty in the air.
  std::optional<StandTable> stand;

  /// The row with `key`, or nullptr.
  const Table2Row* Find(std::string_view key) const;
  /// The foot row of `mode`, or nullptr.
  const FootRow* FindFoot(std::string_view mode) const;
};

/// Table 2 of a track run: BeginTable2, then AddModeToTable2 for each of its runs.
Table2 ComputeTable2(const TrackResult& result);

/// Table 2 before any mode: its header fields and the floor rows.
Table2 BeginTable2(const TrackResult& result);

/// Appends `run`'s rows (L2 and Linf to D, and to P if its mode follows P) and its foot row.
void AddModeToTable2(Table2& table, const ModeRun& run, const TrackResult& result);

/// The stand's row of `run` (steps of `period` ticks) for `stand`'s stance ticks.
StandRow ComputeStandRow(const ModeRun& run, const StandTable& stand, int period);

/// The learning curve of `run` (every step, warm-up included) against the desired motion.
std::vector<LearningStep> LearningCurve(const ModeRun& run, const TrackResult& result);

}  // namespace leglab::experiments
