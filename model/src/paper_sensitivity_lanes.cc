#include "paper_sensitivity_lanes.h"

#include <algorithm>
#include <numeric>

namespace leglab {

PaperSensitivityLanes::PaperSensitivityLanes(std::span<const SweptRecording> recordings, int warmup)
    : recordings_(recordings), warmup_(warmup), order_(recordings.size()) {
  std::iota(order_.begin(), order_.end(), size_t{0});
  std::stable_sort(order_.begin(), order_.end(), [&](size_t a, size_t b) {
    return recordings[a].recording->request_deg.size() >
           recordings[b].recording->request_deg.size();
  });
  for (size_t first = 0; first < order_.size(); first += kLaneCount) {
    Group g;
    g.first = first;
    g.lanes = std::min(kLaneCount, order_.size() - first);
    g.ticks = recordings[order_[first]].recording->request_deg.size();
    g.offset = data_.size();
    data_.resize(data_.size() + g.ticks);
    for (size_t i = 0; i < g.lanes; ++i) {
      const SweptRecording& s = recordings[order_[first + i]];
      const JointRecording& r = *s.recording;
      for (size_t t = 0; t < r.request_deg.size(); ++t) {
        Tick& tick = data_[g.offset + t];
        tick.request[i] = r.request_deg[t];
        tick.measured[i] = r.measured_deg[t];
        tick.run_end[i] = static_cast<double>(s.run_end[t]);
        tick.run_start[i] = t == 0 || r.request_deg[t] != r.request_deg[t - 1] ? -1 : 0;
        tick.present[i] = -1;
      }
    }
    groups_.push_back(g);
  }
}

// One group's sweep: SweepWithSensitivities and ContinuousFit's sums, lane by lane. Each lane
// visits every request of the window: those the scalar sweep visits (the window's first and
// each run's first) with the count of equal requests it gives them, the others with a count of
// 0, which adds +-0 to sums that are never -0 (they start at +0, and a sum is -0 only if both
// terms are), so not a bit; a - b is a + (-b).
template <bool kStarts>
[[gnu::always_inline]] inline void PaperSensitivityLanes::Sweep(
    const JointModelParams& p, const Group& g, Lanes start_angle,
    std::span<PaperNormalEquations> equations) const {
  const double v_max = p.v_max_deg_per_tick;
  const double theta0 = p.theta0_deg;
  const double gain = v_max / theta0;
  const double inv_a = 1.0 / p.accel_ticks;
  const Tick* data = &data_[g.offset];
  Lanes angle = start_angle, d_v{}, d_theta{}, d_start = Splat(1.0);
  Lanes sum{}, vv{}, vt{}, tt{}, vs{}, ts{}, ss{}, ve{}, te{}, se{};
  for (long t = warmup_; t < static_cast<long>(g.ticks); ++t) {
    Lanes speed_sum{}, linear_sum{}, unsaturated{};
    const long last = t - p.lag_ticks - 1;
    const long window_start = last - p.accel_ticks + 1;
    for (long j = window_start; j <= last; ++j) {
      const Tick& in = data[j];
      const Lanes end = Select(static_cast<double>(last) < in.run_end,
                               Splat(static_cast<double>(last)), in.run_end);
      const LaneMask visited = j == window_start ? ~LaneMask{} : in.run_start;
      const Lanes count = Select(visited, end - static_cast<double>(j) + 1.0, Lanes{});
      const Lanes x = in.request - angle;
      const LaneMask above = x >= theta0, below = x <= -theta0;
      const LaneMask linear = ~(above | below);
      const Lanes at_top = count * v_max;
      const Lanes f = Select(above, at_top, Select(below, -at_top, count * (x * gain)));
      speed_sum += f;
      linear_sum += Select(linear, f, Lanes{});
      unsaturated += Select(linear, count, Lanes{});
    }
    const Lanes decay = 1.0 - unsaturated * gain * inv_a;
    d_v = d_v * decay + speed_sum * inv_a;
    d_theta = d_theta * decay - linear_sum * inv_a;
    d_start *= decay;
    angle += speed_sum * inv_a;
    const Tick& now = data[t];
    const LaneMask present = now.present;
    const Lanes e = now.measured - angle;
    sum = Select(present, sum + e * e, sum);
    vv = Select(present, vv + d_v * d_v, vv);
    vt = Select(present, vt + d_v * d_theta, vt);
    tt = Select(present, tt + d_theta * d_theta, tt);
    ve = Select(present, ve + d_v * e, ve);
    te = Select(present, te + d_theta * e, te);
    if constexpr (kStarts) {
      vs = Select(present, vs + d_v * d_start, vs);
      ts = Select(present, ts + d_theta * d_start, ts);
      ss = Select(present, ss + d_start * d_start, ss);
      se = Select(present, se + d_start * e, se);
    }
  }
  for (size_t i = 0; i < g.lanes; ++i) {
    equations[order_[g.first + i]] = {sum[i], vv[i], vt[i], tt[i], vs[i],
                                      ts[i],  ss[i], ve[i], te[i], se[i]};
  }
}

void PaperSensitivityLanes::Accumulate(const JointModelParams& p,
                                       std::span<const double> start_offsets, bool with_starts,
                                       std::vector<PaperNormalEquations>& equations,
                                       LaneInstructions instructions) const {
  equations.assign(recordings_.size(), PaperNormalEquations{});
  if (instructions == LaneInstructions::kAvx2) {
    AccumulateAllAvx2(p, start_offsets, with_starts, equations);
  } else {
    AccumulateAll(p, start_offsets, with_starts, equations);
  }
}

[[gnu::always_inline]] inline void PaperSensitivityLanes::AccumulateGroups(
    const JointModelParams& p, std::span<const double> start_offsets, bool with_starts,
    std::vector<PaperNormalEquations>& equations) const {
  for (const Group& g : groups_) {
    Lanes start{};
    for (size_t i = 0; i < g.lanes; ++i) {
      const size_t k = order_[g.first + i];
      start[i] = recordings_[k].recording->measured_deg[static_cast<size_t>(warmup_) - 1] +
                 (start_offsets.empty() ? 0.0 : start_offsets[k]);
    }
    if (with_starts) {
      Sweep<true>(p, g, start, equations);
    } else {
      Sweep<false>(p, g, start, equations);
    }
  }
}

// AccumulateGroups compiled twice, for the baseline and for AVX2: every function it calls on
// Lanes is always_inline (lanes.h), and `flatten` inlines the rest where the optimiser runs.
[[gnu::flatten]] void PaperSensitivityLanes::AccumulateAll(
    const JointModelParams& p, std::span<const double> start_offsets, bool with_starts,
    std::vector<PaperNormalEquations>& equations) const {
  AccumulateGroups(p, start_offsets, with_starts, equations);
}

[[gnu::flatten, gnu::target("avx2")]] void PaperSensitivityLanes::AccumulateAllAvx2(
    const JointModelParams& p, std::span<const double> start_offsets, bool with_starts,
    std::vector<PaperNormalEquations>& equations) const {
  AccumulateGroups(p, start_offsets, with_starts, equations);
}

}  // namespace leglab
