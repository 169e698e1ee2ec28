#pragma once

#include <span>
#include <vector>

#include "leglab/model/joint_model.h"

namespace leglab {

/// The floor of one joint: the cyclic trajectory x(0..T-1) nearest, in least squares,
/// to the desired cycle D that a joint with the model's top speed v_max and acceleration time a
/// could follow at all:
///   |x(t+1) - x(t)| <= v_max                          (speed, deg/tick)
///   |x(t+1) - 2 x(t) + x(t-1)| <= 2 v_max / a          (change of speed, deg/tick per tick)
/// for every t, indices cyclic (T = desired_deg.size() ticks). Any cyclic motion within these
/// limits is at least RmsDistance(floor, D) from D (RMS, metrics.h), whatever the requests.
///
/// The bound on the change of speed is the floor's definition, not eq. 3's limit. Its reason: the
/// paper's joint takes the same a ticks to go from 0 to v_max as to reverse from v_max to
/// -v_max (section 3, Figs. 3 and 4), so its speed changes by up to 2 v_max / a per tick. In
/// eq. 3 that is the change while every f term is saturated: one term of +-v_max leaves the
/// average of a and one of -+v_max enters. Eq. 3 itself is not held to it: while f terms are
/// in their linear zone, each also moves with M, and the speed can change by up to
/// 2 v_max / a + (a - 1) v_max^2 / (a theta_0) per tick (1.58 deg/tick^2 for Table 1, against
/// 0.83). So the floor bounds a joint with these two limits, not eq. 3 exactly.
///
/// This is the Euclidean projection of D onto a polyhedron (T unknowns, 4T rows). It is solved
/// in O(T) time and memory: a primal-dual interior point whose Newton systems are cyclic
/// pentadiagonal finds the active rows, and the projection onto them is then solved exactly
/// (iterative refinement on the banded normal equations), checked for feasibility and
/// multipliers >= 0, and the set corrected where a degenerate row was misread. The result is
/// the projection to rounding, not to a solver's tolerance (docs/design/floor.md). A D that
/// already meets every bound is returned as is. Returns x, deg, size T.
/// Throws std::invalid_argument on T < 3, a non-finite D (or one whose spread overflows), or
/// invalid params (ValidateJointModelParams; only v_max and a are used).
std::vector<double> FloorTrajectory(std::span<const double> desired_deg,
                                    const JointModelParams& params);

}  // namespace leglab
