#pragma once

#include "leglab/model/joint_model.h"

namespace leglab {

/// How C_m, the offset that inverts a line of slope m, is computed.
enum class CmMethod {
  kClosed,  ///< the paper's closed form (appendix, eqs. 10-12): the sum of eq. 6 as an integral
  kExact,   ///< the exact root of the discrete S(C) = m (eq. 6)
};

/// Slopes within this much of +-v_max count as +-v_max (rounding in a fitted segment).
inline constexpr double kSlopeTolerance = 1e-9;

/// S of eq. 6: the model's velocity (deg/tick) when a line of slope `slope_deg_per_tick` is
/// requested and the request leads the actual angle by `x_deg`:
/// S(x) = (1/a) sum_{i=l+1}^{l+a} f(x - m (i - 1)).
double LineResponse(const JointModelParams& params, double slope_deg_per_tick, double x_deg);

/// The requested-minus-actual offset at which the model follows the line at top speed:
/// theta_0 + (l + a) v_max (section 4.2). Used as C_m for |m| = v_max by both methods.
double TopSpeedLineOffset(const JointModelParams& params);

/// C_m by the paper's closed form: eq. 11 when eq. 10 holds, else eq. 12; odd in m.
/// Throws std::invalid_argument when |m| > v_max, and std::domain_error when the parameters
/// break eq. 13 (theta_0 > v_max and 4 theta_0 > v_max a), outside which the closed form is
/// not derived.
double LineInverseOffsetClosed(const JointModelParams& params, double slope_deg_per_tick);

/// C_m as the exact solution of S(C_m) = m: S is continuous, non-decreasing and linear between
/// the breakpoints m (i - 1) +- theta_0, so the root is found by interpolating between the two
/// breakpoints that bracket m. Where S is flat at m the root nearest zero is returned (the
/// smallest for m > 0; C_{-m} = -C_m).
/// Throws std::invalid_argument when |m| > v_max.
double LineInverseOffsetExact(const JointModelParams& params, double slope_deg_per_tick);

/// C_m by `method`.
double LineInverseOffset(const JointModelParams& params, double slope_deg_per_tick,
                         CmMethod method);

}  // namespace leglab
