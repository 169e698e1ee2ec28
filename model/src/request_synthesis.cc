#include "leglab/model/request_synthesis.h"

#include <cmath>

namespace leglab {

int SwitchLeadTicks(const JointModelParams& p) { return p.lag_ticks + (p.accel_ticks + 1) / 2; }

std::vector<double> SynthesizeRequests(const JointModelParams& p, const PiecewiseLinear& pwl,
                                       CmMethod method) {
  ValidateJointModelParams(p);
  std::vector<double> offsets(pwl.num_segments());
  for (int k = 0; k < pwl.num_segments(); ++k) {
    offsets[k] = LineInverseOffset(p, pwl.Slope(k), method);
  }
  const int lead = SwitchLeadTicks(p);
  std::vector<double> requests(pwl.period_ticks);
  for (int t = 0; t < pwl.period_ticks; ++t) {
    // Segment k's line at t: its value at t + lead, walked back `lead` ticks along its slope.
    const int k = pwl.SegmentAt(t + lead);
    requests[t] = pwl.At(t + lead) - pwl.Slope(k) * lead + offsets[k];
  }
  return requests;
}

}  // namespace leglab
