#pragma once

// The extended model's fit (ServoModelParams, leglab/servo/servo_model.h) to recorded runs.

#include <optional>
#include <span>

#include "leglab/core/config_keys.h"
#include "leglab/servo/servo_model.h"

namespace leglab {

/// The fit's search space and effort.
struct ServoFitOptions {
  int lag_max_ticks = 6;  ///< l is searched exhaustively over [0, lag_max_ticks]
  /// When set, v_max is held at this value (e.g. the servo's published no-load speed) instead
  /// of being fitted: logs that never drive the servo to its top speed cannot show it.
  std::optional<double> v_max_deg_s;
  int restarts = 3;       ///< Nelder-Mead runs per lag, each from the last one's best
  int iterations = 3000;  ///< iterations per Nelder-Mead run
};

/// The declared range of the extended fit's Nelder-Mead iterations per run (logs.iterations).
inline constexpr KeyDoc kServoFitIterationsDoc{
    .min = 1,
    .max = 1'000'000,
    .description = "Nelder-Mead iterations per run of the extended model's fit"};

/// ServoFitOptions' values with their ranges (lag_max_ticks as a model's lag, restarts from 1,
/// kServoFitIterationsDoc, a fixed v_max as kServoVMaxDoc): what FitServoModel checks.
void VisitKeys(KeyVisitor& visitor, ServoFitOptions& options);

/// Fits the continuous parameters of ServoModelParams (gain, v_max unless fixed, stall torque,
/// both frictions and the velocity lag; on logarithms where they must stay positive) for every
/// lag, by Nelder-Mead (NelderMead) on the sum over recordings of each one's mean squared
/// open-loop prediction error over its driven ticks (every recording weighs alike whatever its
/// length), and returns the best lag's (FitServoModelAtLag for each lag, the smallest lag on a
/// tie). Deterministic. Throws std::invalid_argument on no recordings, one without a driven
/// tick, mismatched sizes, non-finite samples, a drive out of range, tick_s outside
/// kServoTickDoc, or options outside their declaration (VisitKeys).
ServoModelParams FitServoModel(std::span<const ServoRecording> recordings, double tick_s,
                               const ServoFitOptions& options = {});

/// The fit at one lag: its parameters and the objective there (FitServoModel's sum of mean
/// squared errors, deg^2).
struct ServoLagFit {
  ServoModelParams params;
  double squared_error = 0.0;
};

/// FitServoModel's work at lag `lag` alone (0 <= lag <= options.lag_max_ticks), so that a
/// caller may fit the lags in parallel: FitServoModel is the fit of least squared_error over
/// the lags, the smallest lag on a tie. Throws as FitServoModel, and on a lag out of range.
ServoLagFit FitServoModelAtLag(std::span<const ServoRecording> recordings, double tick_s,
                               const ServoFitOptions& options, int lag);

}  // namespace leglab
