#pragma once

#include <span>
#include <vector>

#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"

namespace leglab {

/// How far a prediction is from a recording over its driven (scored) ticks.
struct PredictionScore {
  double mae_deg = 0.0;  ///< mean absolute error (deg)
  double rms_deg = 0.0;  ///< root mean square error (deg)
  int ticks_scored = 0;  ///< driven ticks compared
};

/// Scores `predicted_deg` (size N) against the recording's measured angles on its driven ticks.
/// Throws std::invalid_argument on a size mismatch or no driven tick.
PredictionScore ScorePrediction(std::span<const double> predicted_deg,
                                const ServoRecording& recording);

/// The best fixed time shift, chosen on the recording it predicts (an oracle in hindsight): the
/// angle at t predicted as the request at t - s (the first request before tick 0), s in
/// [0, max_shift_ticks] with the least mean absolute error over the driven ticks (the smallest
/// such s on a tie).
struct ShiftPrediction {
  int shift_ticks = 0;
  std::vector<double> angle_deg;  ///< size N
};
ShiftPrediction BestShiftPrediction(const ServoRecording& recording, int max_shift_ticks);

/// The paper's model (eq. 3) predicting a recording open loop, started as
/// PredictServoRecording starts the extended model: at tick 0 and at the first driven tick
/// after undriven ones from the measured angle, remembering the recorded requests before it;
/// undriven ticks predicted as measured. Size N. Throws std::invalid_argument as
/// ValidateJointModelParams does.
std::vector<double> PredictWithJointModel(const JointModelParams& params,
                                          const ServoRecording& recording);

/// Fits the paper's model to recordings by IdentifyJointModel, each run of consecutive driven
/// ticks one JointRecording (runs too short for the search's warm-up, lag_max + accel_max
/// ticks and one scored tick, are left out). Throws std::invalid_argument on a recording whose
/// request, measured and scored sizes differ, or when no run is long enough.
IdentificationResult FitJointModelToRecordings(std::span<const ServoRecording> recordings,
                                               const IdentificationOptions& options);

}  // namespace leglab
