#pragma once

#include <array>
#include <string_view>

#include "leglab/core/leg.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/metrics.h"

/// The numbers Stronger & Stone published, in one place: the writers print them beside
/// leglab's results and the tests compare against them. Nothing else types them.
namespace leglab::paper {

/// Table 1: the joint model identified on the Aibo, the same for all three joints
/// (v_max 2.5 deg/tick, theta_0 7 deg, l 4 ticks, a 6 ticks).
inline constexpr JointModelParams kTable1{2.5, 7.0, 4, 6};

/// One row of Table 2: the mean distance over 20 steps between two angle trajectories, deg,
/// per joint (rotator, abductor, knee).
struct Table2Row {
  std::string_view key;  ///< e.g. "L2(Des,Dir)", as in table2.json
  LegAngles mean_deg;
};

/// Table 2 (Des: desired, Dir: direct, MB: model-based, Pwl: piecewise-linear approximation).
inline constexpr std::array<Table2Row, 6> kTable2 = {{
    {"L2(Des,Dir)", {31.0, 29.0, 20.1}},
    {"Linf(Des,Dir)", {57.2, 59.5, 42.6}},
    {"L2(Des,MB)", {9.1, 10.4, 5.6}},
    {"Linf(Des,MB)", {29.4, 24.5, 11.1}},
    {"L2(Pwl,MB)", {2.7, 2.7, 2.6}},
    {"Linf(Pwl,MB)", {6.4, 6.0, 6.2}},
}};

/// One row of the paper's foot table: the Euclidean foot error, cm, mean and std over steps.
struct FootRow {
  std::string_view mode;  ///< leglab's controller mode name
  MeanStd l2_cm;
  MeanStd linf_cm;
};

/// The paper's foot-space comparison.
inline constexpr std::array<FootRow, 3> kFootCm = {{
    {"direct", {3.23, 0.01}, {4.61, 0.05}},
    {"time_shift", {1.55, 0.04}, {3.57, 0.08}},
    {"model_based", {1.21, 0.04}, {2.34, 0.12}},
}};

/// The Table 2 row with `key`, or nullptr.
constexpr const Table2Row* FindTable2Row(std::string_view key) {
  for (const Table2Row& row : kTable2) {
    if (row.key == key) return &row;
  }
  return nullptr;
}

/// The foot row of `mode`, or nullptr.
constexpr const FootRow* FindFootRow(std::string_view mode) {
  for (const FootRow& row : kFootCm) {
    if (row.mode == mode) return &row;
  }
  return nullptr;
}

}  // namespace leglab::paper
