#pragma once

#include <span>
#include <vector>

#include "leglab/model/joint_model.h"

namespace leglab {

/// One recorded run of a joint: the request sent at each tick and the angle measured right
/// after it (the paper's R(t) and actual angle), consecutive ticks, degrees.
struct JointRecording {
  std::vector<double> request_deg;
  std::vector<double> measured_deg;
  /// The weight of this recording's squared errors in IdentifyJointModel's objective (finite,
  /// > 0). E.g. K for one cycle averaged over K recorded cycles of a periodic run (synchronous
  /// averaging): sum_k sum_t (m_k(t) - M(t))^2 = K sum_t (mean_k m(t) - M(t))^2 + a constant
  /// when the prediction M is the same every cycle. 1 (the default): the unweighted fit, bit for
  /// bit (w * v == v).
  double weight = 1.0;
};

/// The declared range of a recording's cycle, AverageCycles' and CycleScatter's period: one
/// tick or more.
inline constexpr KeyDoc kCyclePeriodDoc{.min = 1, .unit = "ticks"};

/// Synchronous averaging of a periodic run: `run` is whole cycles of `period_ticks` with the
/// same requests every cycle, after any warm-up (a time-invariant plant then answers every cycle
/// alike, up to noise). Returns one recording of `warmup_ticks` + `played_cycles` * period ticks
/// that plays the cycle over and over from tick -warmup_ticks (mod period): at each tick the
/// cycle's request and the mean over the K = size / period cycles of the measured angle there,
/// with weight run.weight * K / played_cycles, so that its weighted squared error against a
/// prediction that repeats every cycle is the run's own up to a constant (the spread of the
/// cycles about their mean). For IdentifyJointModel with warm-up `warmup_ticks` = lag_max +
/// accel_max: it scores the played cycles, each tick of the cycle `played_cycles` times. Throws
/// std::invalid_argument on a run that is not whole cycles (at least one), requests that differ
/// between cycles, mismatched lengths, a period outside kCyclePeriodDoc, warmup_ticks < 0 or
/// played_cycles < 1.
JointRecording AverageCycles(const JointRecording& run, int period_ticks, int warmup_ticks,
                             int played_cycles);

/// What AverageCycles leaves out: run.weight * sum over the run's ticks of (measured - the mean
/// of the cycles' measured angles at that tick of the cycle)^2, the cycles' spread about their
/// mean. Added to the squared error of a prediction that repeats every cycle against the
/// averaged recording, it gives that prediction's squared error against the whole run. Throws
/// as AverageCycles on a run that is not whole cycles of the same requests.
double CycleScatter(const JointRecording& run, int period_ticks);

/// The search space of the fit.
struct IdentificationOptions {
  int lag_min_ticks = 0;  ///< l is searched exhaustively over [lag_min, lag_max]
  int lag_max_ticks = 12;
  int accel_min_ticks = 1;  ///< a is searched exhaustively over [accel_min, accel_max]
  int accel_max_ticks = 12;
};

/// The fitted model and how well it predicts the recordings.
struct IdentificationResult {
  JointModelParams params;
  double rms_residual_deg = 0.0;  ///< RMS of measured - predicted over the scored ticks
};

/// Open-loop prediction of a recording by the model: the model is started at tick W - 1 from
/// the measured angle there, with the recorded requests as its memory, and run on the
/// recorded requests. Returns the prediction M(t) for t = 0..N-1 (M(t) = measured(t) for
/// t < W). W = `warmup_ticks` must be at least l + a.
std::vector<double> PredictRecording(const JointModelParams& params,
                                     const JointRecording& recording, int warmup_ticks);

/// The open-loop prediction of PredictRecording, started from measured(W - 1) +
/// `start_offset_deg` instead, for ticks t = W..N-1, with its exact derivatives (forward
/// sensitivities along eq. 3) with respect to ln v_max, ln theta_0 and the start offset. Where
/// a term of f sits exactly on a kink (|R - M| = theta_0) the derivative is the saturated
/// side's. The angles agree with PredictRecording's (start offset 0) to rounding: terms of
/// equal requests are summed as one.
struct PredictionSensitivities {
  std::vector<double> angle_deg;       ///< M(t), deg, size N - W
  std::vector<double> d_log_v_max;     ///< dM(t) / d ln v_max, deg
  std::vector<double> d_log_theta0;    ///< dM(t) / d ln theta_0, deg
  std::vector<double> d_start_offset;  ///< dM(t) / d start offset, deg per deg
};

/// See PredictionSensitivities. Throws std::invalid_argument as PredictRecording does.
PredictionSensitivities PredictRecordingSensitivities(const JointModelParams& params,
                                                      const JointRecording& recording,
                                                      int warmup_ticks,
                                                      double start_offset_deg = 0.0);

/// The fit's models keep v_max <= kMaxFittedSpeedRatio * theta_0. A servo that runs at top
/// speed until it is within a fraction of a degree of its request (a high gain for its top
/// speed) fits best with a theta_0 so small that eq. 3 swings about a request for ever
/// (v_max >= 2 theta_0, see SettlesOnEveryCycle): a model with no cyclic steady state, which the
/// optimal and ILC modes cannot use. Bounded so, every step of eq. 3 on f's linear piece
/// contracts by at least |1 - 1.9| = 0.9 and every fitted model settles under every request
/// cycle. Shipped configs' fits stay well inside it; see docs/design/identification.md.
inline constexpr double kMaxFittedSpeedRatio = 1.9;

/// Fits {v_max, theta_0, l, a} to the recordings by minimising the model's open-loop
/// prediction error over every tick after the first lag_max + accel_max: every (l, a) of their
/// ranges, v_max and theta_0 (on their logarithms, so they stay positive) by
/// Levenberg-Marquardt on the exact Jacobian (PredictionSensitivities) from two starts each,
/// in two rounds: every candidate to a loose tolerance, then, best first, on to the full one
/// only until the fourth best finished is 5 % below the next candidate's screened error (a
/// screen, not a proof; see docs/design/identification.md). The best four (l, a) are then
/// refitted together with the angle each recording's prediction starts from (a nuisance
/// parameter: started from one noisy sample, as PredictRecording does, a prediction at top speed
/// never recovers from that sample's error), by Levenberg-Marquardt and then a short Nelder-Mead
/// polish (LevenbergMarquardt, NelderMead): the optimum usually sits on a kink of f, where no
/// derivative-based step makes progress. Within v_max <= kMaxFittedSpeedRatio theta_0
/// throughout. Deterministic. Throws std::invalid_argument on empty or mismatched recordings,
/// non-finite samples, bad ranges, or recordings too short to score.
IdentificationResult IdentifyJointModel(std::span<const JointRecording> recordings,
                                        const IdentificationOptions& options = {});

}  // namespace leglab
