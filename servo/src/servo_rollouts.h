#pragma once

// ServoRollouts: the extended model's open-loop prediction error over many recordings at once,
// the objective the fit evaluates thousands of times. Internal to leglab::servo.

#include <array>
#include <span>
#include <vector>

#include "leglab/model/internal/lanes.h"
#include "leglab/servo/servo_model.h"
#include "servo_model_tick.h"

namespace leglab {

/// Each recording's sum of squared open-loop prediction errors over its driven ticks, as
/// PredictServoRecording predicts them, bit for bit: each run of driven ticks started from its
/// first tick's measured angle at rest, R(t-1-lag) acting at tick t (R(0) before it).
///
/// A rollout is one long chain of dependent operations (angle, sine, duty, velocity, angle):
/// its latency, not its arithmetic, sets its cost. So the recordings are rolled out side by
/// side, in the lanes of a few vectors stepped together, each lane rolling out one recording
/// after another, the longest first, each to the lane free soonest. The schedule depends on the
/// recordings alone: the constructor lays out every step's requests, measurements and driven
/// flags lane by lane once, for the many evaluations. A lane computes what a rollout on its own
/// does, so neither the grouping nor the instructions change a bit.
class ServoRollouts {
 public:
  /// Preconditions (checked by the caller): recordings not empty, each with matching sizes, at
  /// least one tick, finite samples; tick_s > 0; lag >= 0.
  ServoRollouts(std::span<const ServoRecording> recordings, double tick_s, int lag);

  /// Each recording's sum of squared errors under `p`, in the recordings' order.
  void SquaredErrors(const ServoModelParams& p, std::vector<double>& sums,
                     LaneInstructions instructions) const;

  /// The vectors stepped together (1 to kMaxVectors), chosen for the recordings' lengths.
  size_t vectors() const { return vectors_; }

  static constexpr size_t kMaxVectors = 3;

 private:
  static constexpr size_t kNone = static_cast<size_t>(-1);

  // One step of one vector: R(t-1-lag) acting, the measured angle, and whether the tick was
  // driven (a mask); an idle lane is not driven.
  struct StepInput {
    Lanes acting{}, measured{};
    LaneMask driven{};
  };

  // At `step`, lane `lane` hands recording `ended`'s sum over (or kNone) and starts
  // `started` (or kNone: it idles).
  struct Handover {
    size_t step, lane, ended, started;
  };

  // One vector's rollout state.
  struct LaneState {
    Lanes duty_per_deg{}, load_duty_at_90{};  // the servo_tick::Coefficients that differ by lane
    Lanes angle{}, velocity{}, sum{};         // sum: squared errors so far
    LaneMask running{};
  };
  using State = std::array<LaneState, kMaxVectors>;

  void Schedule(size_t lag);
  template <bool kChecked>
  void RollOutSteps(const ServoModelParams& p, std::vector<double>& sums) const;
  void RollOut(const ServoModelParams& p, std::vector<double>& sums) const;
  void RollOutAvx2(const ServoModelParams& p, std::vector<double>& sums) const;
  void HandOver(const ServoModelParams& p, const Handover& h, State& state,
                std::vector<double>& sums) const;

  std::span<const ServoRecording> recordings_;
  double tick_s_;
  size_t vectors_ = 1;
  std::vector<StepInput> inputs_;    // step s, vector v at s * vectors_ + v
  std::vector<Handover> handovers_;  // by step
};

}  // namespace leglab
