#include "servo_rollouts.h"

#include <algorithm>
#include <numeric>

namespace leglab {
namespace {

// One tick of a vector's lanes: servo_tick::TargetSpeed and Advance, written for lanes. A lane
// not driven stops; one driven but not running starts at the measured angle at rest; one running
// takes the tick's angle and velocity and adds its squared error. Unless kChecked, the sine
// assumes every angle is in SinDegrees' reduced range and marks those that were not in
// `out_of_range`, for the caller to roll out again, checked.
template <bool kChecked, class State, class Input>
[[gnu::always_inline]] inline void Step(const servo_tick::Coefficients& common, double tick_s,
                                        double blend, const Input& in, State& lanes,
                                        LaneMask& out_of_range) {
  Lanes sine;
  if constexpr (kChecked) {
    sine = servo_tick::SinDegrees(lanes.angle);
  } else {
    out_of_range |= ~servo_tick::InReducedRange(lanes.angle);
    sine = servo_tick::SinDegreesInRange(lanes.angle);
  }
  const Lanes raw_duty = lanes.duty_per_deg * (in.acting - lanes.angle);
  const Lanes duty = Select(raw_duty < -1.0, Splat(-1.0),  // std::clamp(raw_duty, -1, 1)
                            Select(1.0 < raw_duty, Splat(1.0), raw_duty));
  const Lanes load_duty = lanes.load_duty_at_90 * sine;
  const Lanes net = duty - load_duty;
  const Lanes band = common.friction_duty + common.friction_load_ratio * Abs(load_duty);
  const Lanes target =
      Select(Abs(net) <= band, Lanes{}, common.v_max_deg_s * (net - CopySign(band, net)));
  const Lanes velocity = lanes.velocity + blend * (target - lanes.velocity);
  const Lanes angle = lanes.angle + velocity * tick_s;
  const Lanes e = angle - in.measured;
  const LaneMask step = in.driven & lanes.running;
  const LaneMask start = in.driven & ~lanes.running;
  lanes.sum = Select(step, lanes.sum + e * e, lanes.sum);
  lanes.angle = Select(step, angle, Select(start, in.measured, lanes.angle));
  lanes.velocity = Select(step, velocity, Select(start, Lanes{}, lanes.velocity));
  lanes.running = in.driven;
}

// Rolls out recordings `by_length` (longest first) in `lanes` lanes, each to the lane free
// soonest, the lowest on a tie, calling `on_start(step, lane, recording)` for each; returns the
// step at which each lane is done.
template <class OnStart>
std::vector<size_t> GreedySchedule(std::span<const size_t> by_length,
                                   std::span<const ServoRecording> recordings, size_t lanes,
                                   OnStart&& on_start) {
  std::vector<size_t> free_at(lanes, 0);
  for (size_t k : by_length) {
    const auto lane =
        static_cast<size_t>(std::min_element(free_at.begin(), free_at.end()) - free_at.begin());
    on_start(free_at[lane], lane, k);
    free_at[lane] += recordings[k].scored.size();
  }
  return free_at;
}

}  // namespace

ServoRollouts::ServoRollouts(std::span<const ServoRecording> recordings, double tick_s, int lag)
    : recordings_(recordings), tick_s_(tick_s) {
  Schedule(static_cast<size_t>(lag));
}

void ServoRollouts::Schedule(size_t lag) {
  std::vector<size_t> by_length(recordings_.size());
  std::iota(by_length.begin(), by_length.end(), size_t{0});
  std::stable_sort(by_length.begin(), by_length.end(), [&](size_t a, size_t b) {
    return recordings_[a].scored.size() > recordings_[b].scored.size();
  });
  // A step costs about the same with one vector as with two (one chain's latency against two
  // chains' arithmetic), and then in proportion to the vectors: the fewest vector-steps wins.
  size_t best_cost = 0;
  for (size_t v = 1; v <= kMaxVectors; ++v) {
    const std::vector<size_t> end =
        GreedySchedule(by_length, recordings_, v * kLaneCount, [](size_t, size_t, size_t) {});
    const size_t cost = std::max<size_t>(v, 2) * *std::max_element(end.begin(), end.end());
    if (v == 1 || cost < best_cost) {
      best_cost = cost;
      vectors_ = v;
    }
  }
  const size_t lanes = vectors_ * kLaneCount;
  std::vector<size_t> current(lanes, kNone);
  const std::vector<size_t> end =
      GreedySchedule(by_length, recordings_, lanes, [&](size_t step, size_t lane, size_t k) {
        handovers_.push_back({step, lane, current[lane], k});
        current[lane] = k;
      });
  for (size_t lane = 0; lane < lanes; ++lane) {
    handovers_.push_back({end[lane], lane, current[lane], kNone});
  }
  std::stable_sort(handovers_.begin(), handovers_.end(),
                   [](const Handover& a, const Handover& b) { return a.step < b.step; });
  const size_t steps = *std::max_element(end.begin(), end.end());
  inputs_.assign(steps * vectors_, StepInput{});
  for (const Handover& h : handovers_) {
    if (h.started == kNone) continue;
    const ServoRecording& r = recordings_[h.started];
    const size_t v = h.lane / kLaneCount, i = h.lane % kLaneCount;
    for (size_t t = 0; t < r.scored.size(); ++t) {
      StepInput& in = inputs_[(h.step + t) * vectors_ + v];
      in.acting[i] = r.request_deg[t > lag ? t - 1 - lag : 0];
      in.measured[i] = r.measured_deg[t];
      in.driven[i] = r.scored[t] != 0 ? -1 : 0;
    }
  }
}

void ServoRollouts::SquaredErrors(const ServoModelParams& p, std::vector<double>& sums,
                                  LaneInstructions instructions) const {
  sums.assign(recordings_.size(), 0.0);
  if (instructions == LaneInstructions::kAvx2) {
    RollOutAvx2(p, sums);
  } else {
    RollOut(p, sums);
  }
}

[[gnu::always_inline]] inline void ServoRollouts::HandOver(const ServoModelParams& p,
                                                           const Handover& h, State& state,
                                                           std::vector<double>& sums) const {
  LaneState& v = state[h.lane / kLaneCount];
  const size_t i = h.lane % kLaneCount;
  if (h.ended != kNone) sums[h.ended] = v.sum[i];
  const servo_tick::Coefficients c =
      h.started != kNone ? servo_tick::CoefficientsOf(p, recordings_[h.started].drive)
                         : servo_tick::Coefficients{};
  v.duty_per_deg[i] = c.duty_per_deg;
  v.load_duty_at_90[i] = c.load_duty_at_90;
  v.angle[i] = v.velocity[i] = v.sum[i] = 0.0;
  v.running[i] = 0;
}

// Every step of every vector, handing lanes over between recordings; then again, checked, if
// an angle left the sine's reduced range (a rollout diverging).
template <bool kChecked>
[[gnu::always_inline]] inline void ServoRollouts::RollOutSteps(const ServoModelParams& p,
                                                               std::vector<double>& sums) const {
  const servo_tick::Coefficients common = servo_tick::CoefficientsOf(p, recordings_.front().drive);
  const double blend = servo_tick::VelocityBlend(p, tick_s_);
  State state;
  LaneMask out_of_range{};
  const size_t steps = inputs_.size() / vectors_;
  size_t h = 0;
  for (size_t step = 0; step < steps;) {
    for (; h < handovers_.size() && handovers_[h].step == step; ++h) {
      HandOver(p, handovers_[h], state, sums);
    }
    const size_t until = h < handovers_.size() ? handovers_[h].step : steps;
    for (; step < until; ++step) {
      const StepInput* in = &inputs_[step * vectors_];
      for (size_t v = 0; v < vectors_; ++v) {
        Step<kChecked>(common, tick_s_, blend, in[v], state[v], out_of_range);
      }
    }
  }
  for (; h < handovers_.size(); ++h) HandOver(p, handovers_[h], state, sums);
  if constexpr (!kChecked) {
    if (!AllLanes(out_of_range == 0)) RollOutSteps<true>(p, sums);
  }
}

// RollOutSteps compiled twice, for the baseline and for AVX2: every function it calls on Lanes
// is always_inline (lanes.h), and `flatten` inlines the rest where the optimiser runs.
[[gnu::flatten]] void ServoRollouts::RollOut(const ServoModelParams& p,
                                             std::vector<double>& sums) const {
  RollOutSteps<false>(p, sums);
}

[[gnu::flatten, gnu::target("avx2")]] void ServoRollouts::RollOutAvx2(
    const ServoModelParams& p, std::vector<double>& sums) const {
  RollOutSteps<false>(p, sums);
}

}  // namespace leglab
