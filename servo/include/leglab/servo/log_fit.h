#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/app/output_docs.h"
#include "leglab/core/config_keys.h"
#include "leglab/servo/ladder.h"
#include "leglab/servo/servo_fit.h"  // LogFitConfig holds the extended fit's options
#include "leglab/servo/servo_log.h"
#include "leglab/servo/servo_log_io.h"
#include "leglab/servo/servo_model.h"

namespace leglab {

/// How identify scores the models on the training logs themselves.
enum class CrossValidation {
  kNone,                   ///< the models fitted on every training log, scored in sample
  kLeaveOneTrajectoryOut,  ///< per motor and trajectory: fitted without it, scored on it
  kLeaveOneKpOut,          ///< per motor and gain setting: fitted without it, scored on it
};
inline constexpr std::array<std::string_view, 3> kCrossValidationNames{
    "none", "leave_one_trajectory_out", "leave_one_kp_out"};
inline constexpr std::array<std::string_view, 3> kServoLogFormatNames{"auto", "csv", "bam_json"};

/// LogFitConfig::fit_ticks' default: above the 13,605 training ticks of the shipped XL330 logs.
inline constexpr int kDefaultFitTicks = 20'000;

/// `logs.*`: identify fits the joint models to recorded servo logs instead of step tests.
struct LogFitConfig {
  bool given = false;  ///< a `logs` section was given: identify fits logs
  /// Logs to fit on and logs to score the fitted models on, unchanged: files, or folders
  /// (every .json and .csv file in them, by name). Relative paths are taken from the working
  /// directory, else from leglab's data folder (data/servo_logs/... works from anywhere).
  std::vector<std::string> train;
  std::vector<std::string> validate;
  ServoLogFormat format = ServoLogFormat::kAuto;
  double tick_s = 0.0;  ///< 0: each motor's pooled median sample interval of its training logs
  CrossValidation cross_validate = CrossValidation::kNone;
  ServoLogDefaults csv;  ///< motor, kp, mass_kg, length_m of CSV logs
  /// A motor's published no-load speed (deg/s): the extended model's v_max is held at it
  /// instead of fitted (logs that never reach top speed cannot show it).
  std::map<std::string, double> v_max_deg_s;
  double lag_max_s = 0.06;    ///< longest lag either model's fit searches
  double window_max_s = 0.2;  ///< longest averaging window the paper's model's fit searches
  double shift_max_s = 1.0;   ///< longest time shift the hindsight oracle searches
  int iterations = 3000;      ///< Nelder-Mead iterations per run of the extended fit
  /// A pause between two samples longer than this (s) splits a log into segments, each
  /// resampled, fitted and scored on its own: nothing is interpolated across it.
  double gap_s = 0.25;
  /// A sample whose measured angle is more than this (deg) from the line through its two
  /// neighbours in time (same segment) is a glitch: its measurement is left out (the resampled
  /// angle interpolates its neighbours), its request kept, and it is counted. 0: no check.
  double glitch_deg = 15.0;
  /// The most resampled training ticks one model's fit sees (0: all). Above it the fit sees
  /// evenly spaced chunks of every training log, in proportion to its length and totalling
  /// this many (FitSample); scores and plans use every tick. Bounds a fit's cost whatever the
  /// logs' length; the shipped logs are under it, so it does not change their fit.
  int fit_ticks = kDefaultFitTicks;
};

/// The declared range of LogFitConfig::fit_ticks, FitSample's budget (0: all).
inline constexpr KeyDoc kFitTicksDoc{
    .min = 0,
    .max = 1e9,
    .unit = "ticks",
    .description =
        "the most resampled training ticks one model's fit sees (0: all); above it "
        "the fit sees evenly spaced chunks of every training log totalling this "
        "many, and the scores still use every tick"};

/// The `logs.*` keys, declared once (KeyVisitor); the lists and the map are Structured, read by
/// ReadLogFitStructured.
void VisitKeys(KeyVisitor& v, LogFitConfig& c);

/// The finest logs.tick_s a log is resampled to, as a share of its median sample interval:
/// ten ticks between samples interpolate what the samples hold, and a finer tick only
/// multiplies the fit's cost.
inline constexpr double kMinTickPerSampleInterval = 0.1;

/// The longest chunk FitSample cuts (ticks): 5.3 s at the XL330's tick, long against the
/// servos' settling, so that the restart at each chunk's start weighs little.
inline constexpr int kFitChunkTicks = 1000;

/// The training recordings as one model's fit sees them (LogFitConfig::fit_ticks): as they are
/// when they hold `budget` ticks or fewer in all, or `budget` is 0. Else recording k of n_k
/// ticks (T in all) keeps floor(budget n_k / T) of them (at least 1) in c = ceil(that /
/// kFitChunkTicks) chunks of equal length L spread evenly over it, the first at its start and
/// the last at its end, each after `lead_ticks` ticks marked undriven (scored 0: the requests
/// the model remembers when a run starts at the chunk, and the break between chunks); its
/// drive is kept. Deterministic. Throws std::invalid_argument on a budget outside kFitTicksDoc
/// or a lead outside a model's lag (kAnyJointModel.lag_ticks, plus the tick before it).
std::vector<ServoRecording> FitSample(std::span<const ServoRecording> train, long budget,
                                      int lead_ticks);

/// The rungs a log fit scores, in the order its tables and CSV columns show them: the ladder's
/// baselines and models (ServoLadder: direct, best_shift, paper, extended, then each rung of
/// LadderModelRungs), then `extra`'s. Throws InputError when an extra rung's name is not a
/// lower-case identifier, or is a rung's already.
std::vector<ServoRung> LogFitRungs(std::span<const ModelRung> extra = {});

/// One log as a log fit saw it and predicted it: the columns of log_<name>.csv.
struct LogFitCurves {
  std::string name;  ///< <motor>_<file stem>: identify writes log_<name>.csv
  std::string file;  ///< the log's file as given (or the name of a log given as values)
  std::string motor;
  double tick_s = 0.0;  ///< the motor's tick the log was resampled to (s)
  /// Each tick's time from the log's first sample (s): k * tick_s within its first segment,
  /// each later segment's ticks from its own first sample, and one tick (torque off, the
  /// values of the tick before) between segments.
  std::vector<double> time_s;
  std::vector<double> request_deg;      ///< on that tick
  std::vector<double> measured_deg;     ///< ...
  std::vector<uint8_t> torque_enabled;  ///< ...
  std::vector<std::string> rungs;       ///< the rungs predicting it (LogFitRungs' names), in order
  /// Each rung's prediction (in `rungs`' order), held out where cross-validated (deg).
  std::vector<std::vector<double>> predicted_deg;
};

/// What a log fit computed, as values: what identify writes in its log mode.
struct LogFitResult {
  std::string json;                  ///< log_fit.json's text
  std::string markdown;              ///< log_fit.md's text
  std::vector<LogFitCurves> curves;  ///< each log's log_<name>.csv, training logs first
};

/// A log given as a value rather than a file (`leglab.servo.fit` on ServoLog objects).
struct GivenServoLog {
  ServoLog log;       ///< checked as CheckServoLog checks; `file` names it in messages and tables
  bool train = true;  ///< else a validation log
};

/// RunLogFit's work without the files: the models fitted and scored on the configured logs and
/// `given` (after them; config.train may then be empty), with `extra`'s model rungs fitted and
/// scored beside the ladder's (LogFitRungs). Throws as RunLogFit and LogFitRungs.
LogFitResult FitServoLogs(const LogFitConfig& config, int threads,
                          const std::vector<GivenServoLog>& given = {},
                          std::span<const ModelRung> extra = {});

/// `logs.*` from `overrides` alone ("logs.cross_validate=none", "logs.iterations=500", as
/// --set writes them; any key outside `logs` is refused) over the defaults, as the config
/// loader reads them. Throws InputError naming the key (unknown, wrong type, out of range).
LogFitConfig LogFitConfigFromOverrides(const std::vector<std::string>& overrides);

/// Fits and scores the model ladder (direct, best shift in hindsight, the paper's model, the
/// extended model) on the configured logs, one parameter set per motor and rung, and writes
/// log_fit.json, log_fit.md and log_<motor>_<name>.csv (time_s, request_deg, measured_deg,
/// torque_enabled and each rung's prediction, held out where cross-validated) into `out`.
/// Returns log_fit.md's text. Throws InputError for a bad log or list (naming the file).
std::string RunLogFit(const LogFitConfig& config, const OutputDir& out, int threads);

/// The files identify writes in its log mode.
inline const std::vector<std::string> kLogFitOutputPrefixes{"log_fit.", "log_"};

/// The columns of log_<motor>_<name>.csv (LogFitCurves), one row per tick of the log's tick:
/// the log resampled (kLogColumnCount of them), then each of the ladder's scored rungs'
/// predictions (LogFitRungs()), <rung>_deg, described by the ladder's `column`; a rung added
/// for a fit adds its own column after them.
std::span<const ColumnDoc> LogCurveColumns();
inline constexpr size_t kLogColumnCount = 4;

/// What identify writes in its log mode (FitServoLogs' files; its config file aside).
std::span<const OutputDoc> LogFitOutputs();

}  // namespace leglab
