#pragma once

#include <vector>

#include "leglab/model/joint_model.h"
#include "leglab/model/line_inverse.h"
#include "leglab/model/piecewise_linear.h"

namespace leglab {

/// How many ticks before a desired-segment transition the requests switch to the next
/// inverted segment: l + a/2 (section 4.3), rounded half up for odd a.
int SwitchLeadTicks(const JointModelParams& params);

/// The model-based requests of section 4.3 for one period: every segment of `pwl` is inverted
/// by adding its C_m, and the requests switch to a segment SwitchLeadTicks() early:
///   R(t) = L_k(t) + C_{m_k},  k = the segment of P at t + SwitchLeadTicks(),
/// where L_k is segment k's line extended (cyclically) back to t.
/// Returns R(0..T-1), deg. Throws std::invalid_argument when a slope exceeds v_max, and what
/// the chosen C_m method throws (std::domain_error for the closed form outside eq. 13).
std::vector<double> SynthesizeRequests(const JointModelParams& params, const PiecewiseLinear& pwl,
                                       CmMethod method);

}  // namespace leglab
