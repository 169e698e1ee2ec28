#include "leglab/servo/log_fit.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <span>

#include "leglab/app/parallel.h"
#include "leglab/app/progress.h"
#include "leglab/app/yaml_config.h"
#include "leglab/core/format.h"
#include "leglab/servo/servo_ladder.h"
#include "leglab/servo/servo_log.h"
#include "leglab/servo/servo_plan.h"
#include "log_fit_report.h"
#include "log_preprocess.h"

namespace leglab {
namespace {

using namespace log_fit;  // NOLINT: this file's part of the log fit

std::vector<MotorGroup> GroupByMotor(std::vector<Log>& logs, const LogFitConfig& config) {
  std::map<std::string, MotorGroup> groups;
  for (size_t i = 0; i < logs.size(); ++i) {
    MotorGroup& g = groups[logs[i].log.motor];
    g.motor = logs[i].log.motor;
    (logs[i].train ? g.train : g.validate).push_back(i);
  }
  std::vector<MotorGroup> result;
  for (auto& [motor, g] : groups) {
    if (g.train.empty()) {
      FailConfig("logs.validate: '" + logs[g.validate.front()].log.file + "' is of motor '" +
                 motor + "', which no training log is");
    }
    std::vector<ServoLog> train_logs;
    for (size_t i : g.train) {
      train_logs.push_back(logs[i].log);
      g.folds.push_back(FoldKey(logs[i].log, config.cross_validate));
    }
    std::sort(g.folds.begin(), g.folds.end());
    g.folds.erase(std::unique(g.folds.begin(), g.folds.end()), g.folds.end());
    g.tick_s = config.tick_s > 0.0 ? config.tick_s : MedianSampleInterval(train_logs);
    if (config.cross_validate != CrossValidation::kNone && g.folds.size() < 2) {
      const bool by_kp = config.cross_validate == CrossValidation::kLeaveOneKpOut;
      FailConfig("logs.cross_validate: " +
                 std::string(kCrossValidationNames[static_cast<size_t>(config.cross_validate)]) +
                 " needs training logs of two " + (by_kp ? "kp values" : "trajectories") +
                 " or more of motor '" + motor + "'");
    }
    result.push_back(std::move(g));
  }
  return result;
}

int Ticks(double seconds, double tick_s) { return static_cast<int>(std::lround(seconds / tick_s)); }

IdentificationOptions PaperOptions(double tick_s, const LogFitConfig& config) {
  IdentificationOptions paper;
  paper.lag_min_ticks = 0;
  paper.lag_max_ticks = Ticks(config.lag_max_s, tick_s);
  paper.accel_min_ticks = 1;
  paper.accel_max_ticks = std::max(1, Ticks(config.window_max_s, tick_s));
  return paper;
}

ServoFitOptions ExtendedOptions(double tick_s, const std::string& motor,
                                const LogFitConfig& config) {
  ServoFitOptions extended;
  extended.lag_max_ticks = Ticks(config.lag_max_s, tick_s);
  extended.iterations = config.iterations;
  if (const auto it = config.v_max_deg_s.find(motor); it != config.v_max_deg_s.end()) {
    extended.v_max_deg_s = it->second;
  }
  return extended;
}

// `sampled`: FitSample cut the training logs to logs.fit_ticks, so that a fit its chunks are
// too short for is that key's doing, and the message says so.
JointModelParams FitPaper(std::span<const ServoRecording> train, double tick_s,
                          const std::string& motor, const LogFitConfig& config, bool sampled) {
  try {
    const JointModelParams params =
        FitJointModelToRecordings(train, PaperOptions(tick_s, config)).params;
    // A fit the logs do not bound (a step far beyond what the motor's ticks resolve) can end
    // outside the model's range; said here, naming the motor and the tick, rather than by the
    // first prediction that meets it.
    if (const std::string problem = JointModelParamsProblem(params); !problem.empty()) {
      FailConfig("logs: the paper's model fitted to motor '" + motor +
                 "' at logs.tick_s = " + FormatNumber(tick_s) + " s is outside its range (" +
                 problem + "): its logs do not bound it at that tick");
    }
    return params;
  } catch (const std::invalid_argument& e) {
    if (sampled) {
      FailConfig("logs.fit_ticks " + std::to_string(config.fit_ticks) +
                 ": the chunks of the logs it leaves are too short to fit the paper's model to "
                 "motor '" +
                 motor + "' (" + e.what() + "); raise it, or 0 for every tick");
    }
    FailConfig("logs: the paper's model cannot be fitted to motor '" + motor + "': " + e.what());
  }
}

// Every rung's prediction of `r` by `models`, in `report.rungs`' order.
Predictions Predict(const Report& report, const Models& models, const ServoRecording& r,
                    double tick_s, const LogFitConfig& config) {
  Predictions p;
  size_t further = 0;
  for (const ServoRung& rung : report.rungs) {
    if (rung.name == "direct") {
      p.angle_deg.push_back(r.request_deg);
    } else if (rung.name == "best_shift") {
      ShiftPrediction shift = BestShiftPrediction(r, Ticks(config.shift_max_s, tick_s));
      p.shift_ticks = shift.shift_ticks;
      p.angle_deg.push_back(std::move(shift.angle_deg));
    } else if (rung.name == "paper") {
      p.angle_deg.push_back(PredictWithJointModel(models.paper, r));
    } else if (rung.name == "extended") {
      p.angle_deg.push_back(PredictServoRecording(models.extended, r, tick_s));
    } else {
      p.angle_deg.push_back(report.further[further].predict(models.further[further], r, tick_s));
      if (p.angle_deg.back().size() != r.request_deg.size()) {
        throw InputError("the rung '" + rung.name + "' predicted " +
                         std::to_string(p.angle_deg.back().size()) + " angles for a log of " +
                         std::to_string(r.request_deg.size()) + " ticks");
      }
      ++further;
    }
  }
  return p;
}

Row Score(size_t log, const ServoRecording& r, const Predictions& p, double tick_s) {
  Row row;
  row.log = log;
  row.tick_s = tick_s;
  row.shift_ticks = p.shift_ticks;
  for (const std::vector<double>& angles : p.angle_deg) {
    row.scores.push_back(ScorePrediction(angles, r));
  }
  return row;
}

std::vector<FitJob> Jobs(const std::vector<MotorGroup>& groups, const LogFitConfig& config) {
  std::vector<FitJob> jobs;
  for (size_t g = 0; g < groups.size(); ++g) {
    jobs.push_back({g, std::nullopt, {}});
    if (config.cross_validate == CrossValidation::kNone) continue;
    for (const std::string& fold : groups[g].folds) jobs.push_back({g, fold, {}});
  }
  return jobs;
}

// A further model rung's parameters for one motor, a fit it refuses said as bad input naming
// the rung and the motor.
RungParameters FitFurther(const ModelRung& rung, std::span<const ServoRecording> train,
                          double tick_s, const std::string& motor) {
  try {
    return rung.fit(train, tick_s);
  } catch (const std::invalid_argument& e) {
    FailConfig("logs: the rung '" + rung.rung.name + "' cannot be fitted to motor '" + motor +
               "': " + e.what());
  }
}

// Ticks [begin, end) of `from` onto the end of `to`, the first `undriven` of them scored 0.
void AppendTicks(const ServoRecording& from, size_t begin, size_t end, size_t undriven,
                 ServoRecording& to) {
  for (size_t t = begin; t < end; ++t) {
    to.request_deg.push_back(from.request_deg[t]);
    to.measured_deg.push_back(from.measured_deg[t]);
    to.scored.push_back(t < begin + undriven ? 0 : from.scored[t]);
  }
}

// Every job's fits, as tasks run in parallel: each job's paper model, and its extended model
// lag by lag (FitServoModelAtLag), the lag of least error kept as FitServoModel keeps it.
void RunJobs(std::vector<FitJob>& jobs, const std::vector<MotorGroup>& groups,
             const std::vector<Log>& logs, std::span<const ModelRung> further,
             const LogFitConfig& config, int threads) {
  std::vector<std::vector<ServoRecording>> train(jobs.size());
  struct Task {
    size_t job = 0;
    int lag = -1;  // the extended model's fit at this lag; -1: another rung's
    int further =
        -1;  // the further model rung's fit (Report::further); -1 with lag -1: the paper's
  };
  std::vector<Task> tasks;
  for (size_t j = 0; j < jobs.size(); ++j) {
    const MotorGroup& g = groups[jobs[j].group];
    for (size_t i : g.train) {
      if (jobs[j].held_out && FoldKey(logs[i].log, config.cross_validate) == *jobs[j].held_out) {
        continue;
      }
      train[j].push_back(logs[i].recording);
    }
    for (const ServoRecording& r : train[j]) {
      for (const uint8_t on : r.scored) jobs[j].training_ticks += on;
    }
    // The lead: the longest lag the extended fit searches, and the tick before it.
    train[j] = FitSample(train[j], config.fit_ticks,
                         ExtendedOptions(g.tick_s, g.motor, config).lag_max_ticks + 1);
    for (const ServoRecording& r : train[j]) {
      for (const uint8_t on : r.scored) jobs[j].fitted_ticks += on;
    }
    tasks.push_back({j, -1, -1});
    jobs[j].models.further.resize(further.size());
    for (size_t m = 0; m < further.size(); ++m) tasks.push_back({j, -1, static_cast<int>(m)});
    const int lags = ExtendedOptions(g.tick_s, g.motor, config).lag_max_ticks;
    for (int lag = 0; lag <= lags; ++lag) tasks.push_back({j, lag, -1});
  }
  // Progress: each task counts its training ticks when it ends.
  std::vector<long> task_ticks(tasks.size());
  long long planned = 0;
  for (size_t k = 0; k < tasks.size(); ++k) {
    for (const ServoRecording& r : train[tasks[k].job]) {
      task_ticks[k] += static_cast<long>(r.scored.size());
    }
    planned += task_ticks[k];
  }
  ReplanProgress(planned, "training ticks over " + std::to_string(tasks.size()) + " fits");
  std::atomic<int> done{0};
  const std::string of = " of " + std::to_string(tasks.size()) + " fits done, for " +
                         std::to_string(jobs.size()) + " models (final and folds)";
  SetProgressPhase("fitting: 0" + of);
  std::vector<ServoLagFit> lag_fits(tasks.size());
  ParallelFor(static_cast<int>(tasks.size()), threads, [&](int k) {
    const Task& task = tasks[static_cast<size_t>(k)];
    FitJob& job = jobs[task.job];
    const MotorGroup& g = groups[job.group];
    if (task.further >= 0) {
      const ModelRung& rung = further[static_cast<size_t>(task.further)];
      job.models.further[static_cast<size_t>(task.further)] =
          FitFurther(rung, train[task.job], g.tick_s, g.motor);
    } else if (task.lag < 0) {
      job.models.paper = FitPaper(train[task.job], g.tick_s, g.motor, config,
                                  job.fitted_ticks < job.training_ticks);
    } else {
      lag_fits[static_cast<size_t>(k)] = FitServoModelAtLag(
          train[task.job], g.tick_s, ExtendedOptions(g.tick_s, g.motor, config), task.lag);
    }
    CountProgressTicks(task_ticks[static_cast<size_t>(k)]);
    SetProgressPhase("fitting: " + std::to_string(++done) + of);
  });
  SetProgressPhase("scoring and planning each log");
  // Tasks are in lag order within a job: a later lag replaces only a strictly better one.
  std::vector<std::optional<ServoLagFit>> best(jobs.size());
  for (size_t k = 0; k < tasks.size(); ++k) {
    if (tasks[k].lag < 0) continue;
    std::optional<ServoLagFit>& b = best[tasks[k].job];
    if (!b || lag_fits[k].squared_error < b->squared_error) b = lag_fits[k];
  }
  for (size_t j = 0; j < jobs.size(); ++j) jobs[j].models.extended = best[j]->params;
}

double DrivenMae(std::span<const double> angles, const ServoRecording& r) {
  double sum = 0.0;
  int count = 0;
  for (size_t t = 0; t < angles.size(); ++t) {
    if (r.scored[t] == 0) continue;
    sum += std::abs(angles[t] - r.request_deg[t]);
    ++count;
  }
  return sum / count;
}

PlanGain PlanLog(const ServoModelParams& model, const ServoRecording& r, double tick_s) {
  // -180..180 deg, widened to the log's own requests (a servo whose angles run 0..360).
  const auto [least, most] = std::minmax_element(r.request_deg.begin(), r.request_deg.end());
  const ServoLimits limits{std::min(-180.0, *least), std::max(180.0, *most), model.v_max_deg_s};
  PlanGain gain;
  gain.direct_mae_deg = DrivenMae(PredictServoAngles(model, r.drive, tick_s, r.request_deg), r);
  const ServoPlan based =
      PlanServoRequests(model, r.drive, tick_s, r.request_deg, limits, PlanMethod::kModelBased);
  gain.model_based_mae_deg = DrivenMae(based.predicted_deg, r);
  for (size_t t = 0; t < r.scored.size(); ++t) {
    gain.beyond_servo_ticks += based.beyond_servo[t] != 0 && r.scored[t] != 0 ? 1 : 0;
  }
  const ServoPlan optimal =
      PlanServoRequests(model, r.drive, tick_s, r.request_deg, limits, PlanMethod::kOptimal);
  gain.optimal_mae_deg = DrivenMae(optimal.predicted_deg, r);
  return gain;
}

// How often `log` drives its servo to the limits of the final extended model `model`, on its
// driven ticks: measured speed from the tick before at least 90 % of v_max, and a request error
// (the request acting, R(t-1-l), less the angle measured at t-1) whose duty saturates.
void CountLimits(const ServoModelParams& model, double tick_s, Log& log) {
  const ServoRecording& r = log.recording;
  log.ticks_at_top_speed = 0;
  log.ticks_at_full_duty = 0;
  const auto lag = static_cast<size_t>(model.lag_ticks);
  for (size_t t = 1; t < r.scored.size(); ++t) {
    if (r.scored[t] == 0 || r.scored[t - 1] == 0) continue;
    const double speed = std::abs(r.measured_deg[t] - r.measured_deg[t - 1]) / tick_s;
    log.ticks_at_top_speed += speed >= 0.9 * model.v_max_deg_s ? 1 : 0;
    const double error = r.request_deg[t > lag ? t - 1 - lag : 0] - r.measured_deg[t - 1];
    log.ticks_at_full_duty += std::abs(model.gain_per_deg_kp * r.drive.kp * error) >= 1.0 ? 1 : 0;
  }
}

// The rows and figures: every training log in sample (and held out when cross-validated),
// every validation log by its motor's final models.
void ScoreAll(Report& report, const LogFitConfig& config) {
  report.figures.resize(report.logs.size());
  for (const FitJob& job : report.jobs) {
    const MotorGroup& g = report.groups[job.group];
    for (size_t i : g.train) {
      const Log& log = report.logs[i];
      if (job.held_out && FoldKey(log.log, config.cross_validate) != *job.held_out) continue;
      Predictions p = Predict(report, job.models, log.recording, g.tick_s, config);
      Row row = Score(i, log.recording, p, g.tick_s);
      row.train_role = !job.held_out;
      row.held_out = job.held_out;
      if (!job.held_out) {
        row.plan = PlanLog(job.models.extended, log.recording, g.tick_s);
        CountLimits(job.models.extended, g.tick_s, report.logs[i]);
      }
      report.rows.push_back(row);
      if (job.held_out || config.cross_validate == CrossValidation::kNone) {
        report.figures[i] = std::move(p);
      }
    }
    if (job.held_out) continue;
    for (size_t i : g.validate) {
      Predictions p = Predict(report, job.models, report.logs[i].recording, g.tick_s, config);
      report.rows.push_back(Score(i, report.logs[i].recording, p, g.tick_s));
      report.rows.back().plan = PlanLog(job.models.extended, report.logs[i].recording, g.tick_s);
      CountLimits(job.models.extended, g.tick_s, report.logs[i]);
      report.figures[i] = std::move(p);
    }
  }
  // Per motor, by log: in sample, then held out.
  std::stable_sort(report.rows.begin(), report.rows.end(), [&](const Row& a, const Row& b) {
    return std::tie(report.logs[a.log].log.motor, a.log, b.train_role) <
           std::tie(report.logs[b.log].log.motor, b.log, a.train_role);
  });
}

}  // namespace

std::vector<ServoRung> LogFitRungs(std::span<const ModelRung> extra) {
  std::vector<ServoRung> rungs;
  for (const ServoRung& rung : ServoLadder()) {
    if (rung.kind != RungKind::kLearned) rungs.push_back(rung);
  }
  for (const ModelRung& m : extra) {
    const std::string& name = m.rung.name;
    const bool identifier = !name.empty() &&
                            std::islower(static_cast<unsigned char>(name[0])) != 0 &&
                            std::all_of(name.begin(), name.end(), [](unsigned char c) {
                              return std::islower(c) != 0 || std::isdigit(c) != 0 || c == '_';
                            });
    if (!identifier) {
      throw InputError("rung '" + name + "': a rung's name must be a lower-case identifier " +
                       "(a-z, 0-9, _; a letter first): it names a JSON key and a CSV column");
    }
    for (const ServoRung& rung : ServoLadder()) {
      if (rung.name == name)
        throw InputError("rung '" + name + "': the ladder has a rung of that name");
    }
    for (const ServoRung& rung : rungs) {
      if (rung.name == name) throw InputError("rung '" + name + "': given twice");
    }
    if (!m.fit || !m.predict) throw InputError("rung '" + name + "': it needs a fit and a predict");
    rungs.push_back(m.rung);
    rungs.back().kind = RungKind::kModel;
  }
  return rungs;
}

std::span<const ColumnDoc> LogCurveColumns() {
  static_assert(kServoLogColumnList.size() == kLogColumnCount);
  static const std::vector<ServoRung> rungs = LogFitRungs();
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all(rungs.size());
    for (size_t k = 0; k < rungs.size(); ++k) all[k] = rungs[k].name + "_deg";
    return all;
  }();
  static const std::vector<ColumnDoc> columns = [] {
    std::vector<ColumnDoc> all{
        {kServoLogColumns.time_s, "s", "the tick's time from the log's start"},
        {kServoLogColumns.request_deg, "deg", "the request in force (held between samples)"},
        {kServoLogColumns.measured_deg, "deg", "the measured angle (interpolated between samples)"},
        {kServoLogColumns.torque_enabled, "",
         "1 when the servo drove the joint, 0 when it was limp (not scored)"},
    };
    for (size_t k = 0; k < rungs.size(); ++k) all.push_back({names[k], "deg", rungs[k].column});
    return all;
  }();
  return columns;
}

std::vector<ServoRecording> FitSample(std::span<const ServoRecording> train, long budget,
                                      int lead_ticks) {
  if (const std::string problem = KeyValueProblem(static_cast<double>(budget), kFitTicksDoc);
      !problem.empty()) {
    throw std::invalid_argument("FitSample: the budget must be " + problem + ", got " +
                                std::to_string(budget));
  }
  const KeyDoc lead_doc = WithRange(kAnyJointModel.lag_ticks, 0, kAnyJointModel.lag_ticks.max + 1);
  if (const std::string problem = KeyValueProblem(lead_ticks, lead_doc); !problem.empty()) {
    throw std::invalid_argument("FitSample: the lead must be " + problem + ", got " +
                                std::to_string(lead_ticks));
  }
  double total = 0.0;
  for (const ServoRecording& r : train) total += static_cast<double>(r.scored.size());
  if (budget == 0 || total <= static_cast<double>(budget)) return {train.begin(), train.end()};
  std::vector<ServoRecording> sample;
  for (const ServoRecording& r : train) {
    const size_t n = r.scored.size();
    const auto keep = std::max<size_t>(
        1, static_cast<size_t>(static_cast<double>(budget) * static_cast<double>(n) / total));
    const size_t chunks = (keep + kFitChunkTicks - 1) / kFitChunkTicks;
    const size_t length = keep / chunks;
    ServoRecording s{.drive = r.drive, .request_deg = {}, .measured_deg = {}, .scored = {}};
    for (size_t c = 0; c < chunks; ++c) {
      // Evenly from the start to the end: chunk c begins at c (n - L) / (chunks - 1).
      const size_t begin = chunks == 1 ? (n - length) / 2 : c * (n - length) / (chunks - 1);
      const size_t lead = std::min(begin, static_cast<size_t>(lead_ticks));
      AppendTicks(r, begin - lead, begin + length, lead, s);
    }
    sample.push_back(std::move(s));
  }
  return sample;
}

LogFitResult FitServoLogs(const LogFitConfig& config, int threads,
                          const std::vector<GivenServoLog>& given,
                          std::span<const ModelRung> extra) {
  Report report;
  report.rungs = LogFitRungs(extra);
  report.further.assign(LadderModelRungs().begin(), LadderModelRungs().end());
  report.further.insert(report.further.end(), extra.begin(), extra.end());
  SetProgressPhase("reading the logs");
  report.logs = ReadLogs(config, given);
  report.groups = GroupByMotor(report.logs, config);
  for (const MotorGroup& g : report.groups) {
    for (const std::vector<size_t>* list : {&g.train, &g.validate}) {
      for (size_t i : *list) Resample(report.logs[i], g.tick_s, config);
    }
  }
  report.jobs = Jobs(report.groups, config);
  RunJobs(report.jobs, report.groups, report.logs, report.further, config, threads);
  ScoreAll(report, config);
  LogFitResult result;
  result.markdown = ReportMarkdown(report);
  result.json = ReportJson(report, config);
  for (const MotorGroup& g : report.groups) {
    for (const std::vector<size_t>* list : {&g.train, &g.validate}) {
      for (size_t i : *list) {
        Log& log = report.logs[i];
        LogFitCurves c{
            .name = log.name, .file = log.log.file, .motor = g.motor, .tick_s = g.tick_s};
        c.time_s = std::move(log.time_s);
        c.request_deg = std::move(log.recording.request_deg);
        c.measured_deg = std::move(log.recording.measured_deg);
        c.torque_enabled = std::move(log.recording.scored);
        for (const ServoRung& rung : report.rungs) c.rungs.push_back(rung.name);
        c.predicted_deg = std::move(report.figures[i].angle_deg);
        result.curves.push_back(std::move(c));
      }
    }
  }
  return result;
}

std::string RunLogFit(const LogFitConfig& config, const OutputDir& out, int threads) {
  const LogFitResult result = FitServoLogs(config, threads);
  WriteTextFile(out.Path("log_fit.json"), result.json);
  WriteTextFile(out.Path("log_fit.md"), result.markdown);
  for (const LogFitCurves& c : result.curves) WriteLogCsv(c, out);
  return result.markdown;
}

// log_fit.json's fields (log_fit_report.cc writes them), as dotted paths; `[]` is every element
// of a list.
constexpr ColumnDoc kLogFitFields[] = {
    {"models.paper.<motor>.<value>", "",
     "the paper's model of a servo type: v_max_deg_per_tick, theta0_deg, lag_ticks, "
     "accel_ticks in its ticks, tick_s (s) and v_max_deg_s (deg/s), as plan reads it"},
    {"models.extended.<motor>.<value>", "",
     "the extended model: gain_per_deg_kp, v_max_deg_s, v_max_given (true when given, not "
     "fitted), stall_torque_nm, friction_duty, friction_load_ratio, velocity_lag_s, lag_ticks "
     "and tick_s, as plan reads it"},
    {"models.<rung>.<motor>.<value>", "",
     "a model rung added for that fit (leglab.servo.fit's rungs=, FitServoLogs' extra): its "
     "parameters by name and tick_s"},
    {"fit_sample.<motor>.training_ticks", "ticks", "the servo type's training ticks"},
    {"fit_sample.<motor>.fitted_ticks", "ticks", "those its fit saw (logs.fit_ticks)"},
    {"cross_validate", "", "logs.cross_validate"},
    {"folds[].motor", "", "a fold of the cross-validation: its servo type"},
    {"folds[].held_out", "", "the trajectory or gain it leaves out"},
    {"folds[].training_ticks", "ticks", "its training ticks"},
    {"folds[].fitted_ticks", "ticks", "those its fit saw"},
    {"folds[].<rung>.<value>", "", "the fold's models, as models.* holds them"},
    {"logs[].file", "", "a log: its file"},
    {"logs[].role", "", "train or validate"},
    {"logs[].held_out_by", "",
     "how it was scored held out: the cross-validation's name, validate (a validate log) or "
     "none (scored by the models it trained)"},
    {"logs[].motor", "", "its servo type"},
    {"logs[].trajectory", "", "its motion's name"},
    {"logs[].kp", "", "its position gain"},
    {"logs[].ticks_scored", "ticks", "its ticks with the torque on"},
    {"logs[].best_shift_s", "s", "the best time shift in hindsight"},
    {"logs[].mae_deg.<rung>", "deg", "each rung's mean absolute prediction error"},
    {"logs[].rms_deg.<rung>", "deg", "each rung's RMS prediction error"},
    {"logs[].data.samples", "", "its samples"},
    {"logs[].data.duration_s", "s", "its length"},
    {"logs[].data.median_interval_s", "s", "the median time between samples"},
    {"logs[].data.interval_jitter_s", "s", "the spread of the time between samples"},
    {"logs[].data.segments", "", "its pieces of 2 samples or more between pauses over logs.gap_s"},
    {"logs[].data.samples_dropped", "", "samples alone between two pauses: in no segment"},
    {"logs[].data.glitches", "", "measurements left out as glitches (logs.glitch_deg)"},
    {"logs[].data.ticks_at_top_speed", "ticks",
     "driven ticks measured at 90 % of the final model's v_max or more"},
    {"logs[].data.ticks_at_full_duty", "ticks",
     "driven ticks whose request error saturates the final model's duty"},
    {"logs[].plan.direct_mae_deg", "deg",
     "planned on the log's motion: the model's error with the desired angles sent as they are"},
    {"logs[].plan.model_based_mae_deg", "deg", "with the model-based requests"},
    {"logs[].plan.optimal_mae_deg", "deg", "with the optimal requests"},
    {"logs[].plan.beyond_servo_ticks", "ticks", "ticks the motion is beyond the servo"},
};

std::span<const OutputDoc> LogFitOutputs() {
  static const std::vector<ServoRung> rungs = LogFitRungs();
  static const std::vector<ColumnDoc> columns = [] {
    std::vector<ColumnDoc> all(LogCurveColumns().begin(), LogCurveColumns().end());
    all.push_back({"<rung>_deg", "deg",
                   "a model rung added for that fit (leglab.servo.fit's rungs=, FitServoLogs' "
                   "extra): its prediction"});
    return all;
  }();
  static const std::string json = [] {
    std::string names;
    for (const ServoRung& rung : rungs) names += (names.empty() ? "" : ", ") + rung.name;
    return "With a logs section: every servo type's fitted models (as plan reads them), each "
           "log's scores by rung (" +
           names +
           "), training and held out, the logs' quality, and the planned requests' predicted "
           "errors.";
  }();
  static const OutputDoc outputs[] = {
      {"log_fit.json", json, kLogFitFields},
      {"log_fit.md",
       "With a logs section: log_fit.json as Markdown tables, one section per servo "
       "type.",
       {}},
      {"log_<motor>_<name>.csv",
       "With a logs section: one log as the fit saw it, beside every rung's prediction.", columns},
  };
  return outputs;
}

}  // namespace leglab
