#pragma once

// The log fit's state shared by its three parts, internal to leglab::servo_io:
// log_preprocess.cc reads and resamples the logs, log_fit.cc fits and scores them into a Report,
// log_fit_report.cc writes it as log_fit.json, log_fit.md and each log's CSV.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "leglab/app/output.h"
#include "leglab/core/format.h"
#include "leglab/model/joint_model.h"
#include "leglab/servo/ladder.h"
#include "leglab/servo/log_fit.h"
#include "leglab/servo/servo_ladder.h"
#include "leglab/servo/servo_model.h"

namespace leglab::log_fit {

// A log as identify uses it: read, resampled at its motor's tick, and named for its outputs.
struct Log {
  ServoLog log;
  bool train = false;  // else a validation log
  std::string name;    // <motor>_<file stem>: the log_<name>.csv it writes
  ServoRecording recording;
  std::vector<double> time_s;  // each tick's time from the first sample (LogFitCurves::time_s)
  int segments = 0;            // of at least 2 samples, split at pauses over logs.gap_s
  int samples_dropped = 0;     // samples alone between two pauses: no segment
  int glitches = 0;            // samples whose measurement was left out (logs.glitch_deg)
  int ticks_at_top_speed = 0;  // driven ticks measured at 90 % of the final model's v_max or more
  int ticks_at_full_duty = 0;  // driven ticks whose request error saturates the final model's duty
};

// One motor's logs and the tick they are resampled to.
struct MotorGroup {
  std::string motor;
  double tick_s = 0.0;
  std::vector<size_t> train;       // indices into the logs
  std::vector<size_t> validate;    // ...
  std::vector<std::string> folds;  // the training logs' fold keys (FoldKey), sorted
};

// The model rungs' models of one motor, fitted on some of its training logs.
struct Models {
  JointModelParams paper;
  ServoModelParams extended;
  std::vector<RungParameters> further;  // each further model rung's (Report::further)
};

// What a log is held out by under cross-validation: its trajectory or its gain setting.
inline std::string FoldKey(const ServoLog& log, CrossValidation cv) {
  return cv == CrossValidation::kLeaveOneKpOut ? "kp " + FormatNumber(log.kp) : log.trajectory;
}

// A fit to do: the motor, the training logs it leaves out (none: the final models).
struct FitJob {
  size_t group = 0;
  std::optional<std::string> held_out;  // the fold left out (FoldKey)
  Models models;
  long training_ticks = 0;  // the driven ticks of its training logs
  long fitted_ticks = 0;    // of those, the ones its fits saw (FitSample)
};

// Every rung's prediction of one log (Report::rungs' order), and the oracle's shift.
struct Predictions {
  std::vector<std::vector<double>> angle_deg;
  int shift_ticks = 0;
};

// A log's request column taken as a desired motion and played through its motor's extended
// model: the predicted error of sending it as it is, and of each method's plan (driven ticks).
struct PlanGain {
  double direct_mae_deg = 0.0;
  double model_based_mae_deg = 0.0;
  double optimal_mae_deg = 0.0;
  int beyond_servo_ticks = 0;  // of the model-based plan, driven ticks only
};

// A scored log: which log, as what, by which fit.
struct Row {
  size_t log = 0;
  bool train_role = false;              // scored by the models fitted on it
  std::optional<std::string> held_out;  // the fold's key (cross-validation)
  std::vector<PredictionScore> scores;  // each rung's (Report::rungs' order)
  int shift_ticks = 0;
  double tick_s = 0.0;
  std::optional<PlanGain> plan;  // for the rows scored by the final models
};

// Everything identify reports of a log fit.
struct Report {
  std::vector<ServoRung> rungs;    // scored, in order (LogFitRungs)
  std::vector<ModelRung> further;  // the model rungs beyond the built-in two, in rungs' order
  std::vector<Log> logs;
  std::vector<MotorGroup> groups;
  std::vector<FitJob> jobs;
  std::vector<Row> rows;
  std::vector<Predictions> figures;  // per log: held out where cross-validated
};

/// log_fit.json's text: the models, the folds' models, and every scored log's row.
std::string ReportJson(const Report& report, const LogFitConfig& config);

/// log_fit.md's text: per motor, the scores, the logs' data and the plans.
std::string ReportMarkdown(const Report& report);

/// log_<name>.csv: the log on its ticks and each rung's prediction.
void WriteLogCsv(const LogFitCurves& c, const OutputDir& out);

}  // namespace leglab::log_fit
