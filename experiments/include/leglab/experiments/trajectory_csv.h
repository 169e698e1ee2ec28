#pragma once

#include <array>
#include <string>

#include "leglab/controller/controller.h"
#include "leglab/core/leg.h"
#include "leglab/model/kinematics.h"

namespace leglab::experiments {

/// The header line a desired-trajectory CSV must start with:
/// `tick,rotator_deg,abductor_deg,knee_deg` (one column per joint, LegJoint order).
std::string DesiredCsvHeader();

/// Reads one cycle of desired joint angles (deg, LegJoint order) from the CSV at `path`
/// (`desired.csv`): the header DesiredCsvHeader(), then one row a tick, ticks 0..period-1 in
/// order, each cell plain decimal (the tick digits only; no hex, no '+', no spaces), every angle
/// finite and within `limits` (rad, tolerance 1e-9). Blank lines and a trailing '\r' are
/// ignored. Throws InputError naming the file and the row and column at fault (or the row count
/// against `period`, track.t_step_ticks).
DesiredCycle ReadDesiredCsv(const std::string& path, int period,
                            const std::array<JointLimits, kLegJoints>& limits);

}  // namespace leglab::experiments
