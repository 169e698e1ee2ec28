#pragma once

// PaperSensitivityLanes: the paper's model (eq. 3) swept over many recordings at once, in vector
// lanes, with its forward sensitivities, for the normal equations of the fit of v_max and
// theta_0. Internal to leglab_model.

#include <span>
#include <vector>

#include "leglab/model/identification.h"
#include "leglab/model/internal/lanes.h"
#include "leglab/model/joint_model.h"

namespace leglab {

/// One recording's squared error sum_t e^2 (e = measured - M) and its share of the Gauss-Newton
/// normal equations: J^T J's entries vv, vt, tt, vs, ts, ss and J^T e's ve, te, se for x = (ln
/// v_max, ln theta_0, start offset); each summed tick by tick in order.
struct PaperNormalEquations {
  double squared_error = 0, vv = 0, vt = 0, tt = 0, vs = 0, ts = 0, ss = 0;
  double ve = 0, te = 0, se = 0;
};

/// A recording and, for each tick j, the last tick of the run of equal requests holding it.
struct SweptRecording {
  const JointRecording* recording = nullptr;
  std::span<const int> run_end;
};

/// The sweep of identification.cc's SweepWithSensitivities and the fit's sums over it, for
/// every recording, bit for bit, in the lanes of vectors: recordings of about the same length
/// side by side, each lane visiting every request of its window (the scalar sweep visits one per
/// run of equal requests: cheaper where requests are held, as in a step test; the lanes where
/// they change every tick, as in a servo's log; a visit the scalar sweep skips adds exactly 0).
/// Worth it on AVX2 only: compiled for the x86-64 baseline, these lanes run slower than the
/// scalar sweep (benchmarks/fit_lanes_benchmark.cc), so the fit uses them on AVX2 alone.
class PaperSensitivityLanes {
 public:
  /// Preconditions (checked by the caller): each recording longer than `warmup` >= 1, its
  /// samples finite, run_end as described.
  PaperSensitivityLanes(std::span<const SweptRecording> recordings, int warmup);

  /// Each recording's normal equations at `p` (warmup >= p.lag_ticks + p.accel_ticks), its
  /// sweep started from its measured angle at warmup - 1 plus start_offsets[k] (0 for every
  /// recording when empty); the start-offset entries only when `with_starts`, else 0.
  void Accumulate(const JointModelParams& p, std::span<const double> start_offsets,
                  bool with_starts, std::vector<PaperNormalEquations>& equations,
                  LaneInstructions instructions) const;

 private:
  // kLaneCount recordings side by side: `lanes` of them, from order_[first], `ticks` the
  // longest's length; their samples at data_[offset + t].
  struct Group {
    size_t first = 0, lanes = 0, ticks = 0, offset = 0;
  };
  // Tick t of a group: each lane's request, measured angle, last tick of the request's run
  // (as a double), whether a run starts there (a mask), and whether the lane's recording has
  // the tick (a mask).
  struct Tick {
    Lanes request{}, measured{}, run_end{};
    LaneMask run_start{}, present{};
  };

  template <bool kStarts>
  void Sweep(const JointModelParams& p, const Group& g, Lanes start_angle,
             std::span<PaperNormalEquations> equations) const;
  void AccumulateGroups(const JointModelParams& p, std::span<const double> start_offsets,
                        bool with_starts, std::vector<PaperNormalEquations>& equations) const;
  void AccumulateAll(const JointModelParams& p, std::span<const double> start_offsets,
                     bool with_starts, std::vector<PaperNormalEquations>& equations) const;
  void AccumulateAllAvx2(const JointModelParams& p, std::span<const double> start_offsets,
                         bool with_starts, std::vector<PaperNormalEquations>& equations) const;

  std::span<const SweptRecording> recordings_;
  int warmup_;
  std::vector<size_t> order_;  // recordings, longest first
  std::vector<Group> groups_;
  std::vector<Tick> data_;
};

}  // namespace leglab
