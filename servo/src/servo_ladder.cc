#include "leglab/servo/servo_ladder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace leglab {

PredictionScore ScorePrediction(std::span<const double> predicted_deg,
                                const ServoRecording& recording) {
  if (predicted_deg.size() != recording.measured_deg.size() ||
      recording.scored.size() != recording.measured_deg.size()) {
    throw std::invalid_argument("score: prediction and recording sizes differ");
  }
  double abs_sum = 0.0;
  double square_sum = 0.0;
  PredictionScore score;
  for (size_t t = 0; t < predicted_deg.size(); ++t) {
    if (recording.scored[t] == 0) continue;
    const double e = predicted_deg[t] - recording.measured_deg[t];
    abs_sum += std::abs(e);
    square_sum += e * e;
    ++score.ticks_scored;
  }
  if (score.ticks_scored == 0) throw std::invalid_argument("score: no driven tick");
  score.mae_deg = abs_sum / score.ticks_scored;
  score.rms_deg = std::sqrt(square_sum / score.ticks_scored);
  return score;
}

ShiftPrediction BestShiftPrediction(const ServoRecording& recording, int max_shift_ticks) {
  const size_t n = recording.request_deg.size();
  ShiftPrediction best;
  double best_mae = std::numeric_limits<double>::infinity();
  std::vector<double> shifted(n);
  for (int s = 0; s <= std::max(max_shift_ticks, 0); ++s) {
    for (size_t t = 0; t < n; ++t) {
      shifted[t] = recording.request_deg[t >= static_cast<size_t>(s) ? t - s : 0];
    }
    const double mae = ScorePrediction(shifted, recording).mae_deg;
    if (mae < best_mae) {
      best_mae = mae;
      best.shift_ticks = s;
      best.angle_deg = shifted;
    }
  }
  return best;
}

std::vector<double> PredictWithJointModel(const JointModelParams& params,
                                          const ServoRecording& recording) {
  ValidateJointModelParams(params);
  const size_t n = recording.request_deg.size();
  if (recording.measured_deg.size() != n || recording.scored.size() != n) {
    throw std::invalid_argument("servo recording: request, measured and scored sizes differ");
  }
  JointModelState state;
  return PredictDrivenRuns(
      recording,
      [&](size_t t) {
        // As after tick t: M(t) measured, remembering R(t), ..., R(t-l-a+1).
        state.angle_deg = recording.measured_deg[t];
        state.past_requests_deg = RecordedRequestsUpTo(
            recording, t,
            static_cast<size_t>(params.lag_ticks) + static_cast<size_t>(params.accel_ticks));
      },
      [&](size_t t) { return StepJointModel(params, state, recording.request_deg[t]); });
}

IdentificationResult FitJointModelToRecordings(std::span<const ServoRecording> recordings,
                                               const IdentificationOptions& options) {
  const size_t min_ticks = static_cast<size_t>(options.lag_max_ticks + options.accel_max_ticks) + 1;
  std::vector<JointRecording> runs;
  for (const ServoRecording& r : recordings) {
    // The runs are cut where `scored` says, so every column must be as long as it.
    if (r.request_deg.size() != r.scored.size() || r.measured_deg.size() != r.scored.size()) {
      throw std::invalid_argument("servo recording: request, measured and scored sizes differ");
    }
    for (size_t t = 0; t < r.scored.size();) {
      if (r.scored[t] == 0) {
        ++t;
        continue;
      }
      size_t end = t;
      while (end < r.scored.size() && r.scored[end] != 0) ++end;
      if (end - t >= min_ticks) {
        runs.push_back({{r.request_deg.begin() + static_cast<long>(t),
                         r.request_deg.begin() + static_cast<long>(end)},
                        {r.measured_deg.begin() + static_cast<long>(t),
                         r.measured_deg.begin() + static_cast<long>(end)}});
      }
      t = end;
    }
  }
  if (runs.empty()) {
    throw std::invalid_argument("paper model fit: no run of driven ticks is longer than " +
                                std::to_string(min_ticks - 1) + " ticks");
  }
  return IdentifyJointModel(runs, options);
}

}  // namespace leglab
