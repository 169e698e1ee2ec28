#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "leglab/app/program.h"
#include "leglab/servo/servo_log.h"
#include "log_fit_report.h"

namespace leglab::log_fit {
namespace {

using Json = nlohmann::ordered_json;

// The paper's model in the log's ticks: the tick, the model's values under its keys' names
// (VisitKeys), and its top speed in deg/s.
Json PaperJson(const JointModelParams& p, double tick_s) {
  Json json = {{"tick_s", tick_s}};
  const auto visit = [](KeyVisitor& v, JointModelParams& m) { VisitKeys(v, m, kAnyJointModel); };
  for (const KeyValue& k : KeyValues(p, visit)) {
    json[k.key] = k.integer ? Json(static_cast<long>(k.value)) : Json(k.value);
  }
  json["v_max_deg_s"] = p.v_max_deg_per_tick / tick_s;
  return json;
}

Json ExtendedJson(const ServoModelParams& p, double tick_s, bool v_max_given) {
  return {{"tick_s", tick_s},
          {"gain_per_deg_kp", p.gain_per_deg_kp},
          {"v_max_deg_s", p.v_max_deg_s},
          {"v_max_given", v_max_given},
          {"stall_torque_nm", p.stall_torque_nm},
          {"friction_duty", p.friction_duty},
          {"friction_load_ratio", p.friction_load_ratio},
          {"velocity_lag_s", p.velocity_lag_s},
          {kJointModelNames.lag_ticks, p.lag_ticks}};
}

// How a row's log was kept from the models that scored it: the cross-validation, the
// validation list, or not at all ("none", a training log scored in sample).
std::string HeldOutBy(const Row& row, const LogFitConfig& config) {
  if (row.held_out)
    return std::string(kCrossValidationNames[static_cast<size_t>(config.cross_validate)]);
  return row.train_role ? "none" : "validate";
}

Json ScoresJson(const Report& report, const Row& row, bool rms) {
  Json j;
  for (size_t k = 0; k < report.rungs.size(); ++k) {
    j[report.rungs[k].name] = rms ? row.scores[k].rms_deg : row.scores[k].mae_deg;
  }
  return j;
}

// A further model rung's parameters in its motor's tick.
Json FurtherJson(const RungParameters& parameters, double tick_s) {
  Json json = {{"tick_s", tick_s}};
  for (const auto& [name, value] : parameters) json[name] = value;
  return json;
}

// The median absolute deviation of the sample intervals from their median (s): how unevenly
// the log was sampled.
double IntervalJitter(const std::vector<ServoLogSample>& samples) {
  const double median = MedianSampleInterval(samples);
  std::vector<double> spread;
  for (size_t i = 1; i < samples.size(); ++i) {
    spread.push_back(std::abs(samples[i].time_s - samples[i - 1].time_s - median));
  }
  std::sort(spread.begin(), spread.end());
  const size_t mid = spread.size() / 2;
  return spread.size() % 2 == 1 ? spread[mid] : 0.5 * (spread[mid - 1] + spread[mid]);
}

// What the log holds: its samples, their spacing, its segments and glitches, and how often it
// drives its servo to the final model's top speed or full duty.
Json DataJson(const Log& l) {
  const std::vector<ServoLogSample>& samples = l.log.samples;
  return {{"samples", samples.size()},
          {"duration_s", samples.back().time_s - samples.front().time_s},
          {"median_interval_s", MedianSampleInterval(samples)},
          {"interval_jitter_s", IntervalJitter(samples)},
          {"segments", l.segments},
          {"samples_dropped", l.samples_dropped},
          {"glitches", l.glitches},
          {"ticks_at_top_speed", l.ticks_at_top_speed},
          {"ticks_at_full_duty", l.ticks_at_full_duty}};
}

}  // namespace

std::string ReportJson(const Report& report, const LogFitConfig& config) {
  Json json;
  for (const FitJob& job : report.jobs) {
    if (job.held_out) continue;
    const MotorGroup& g = report.groups[job.group];
    json["models"]["paper"][g.motor] = PaperJson(job.models.paper, g.tick_s);
    json["fit_sample"][g.motor] = {{"training_ticks", job.training_ticks},
                                   {"fitted_ticks", job.fitted_ticks}};
    json["models"]["extended"][g.motor] =
        ExtendedJson(job.models.extended, g.tick_s, config.v_max_deg_s.count(g.motor) > 0);
    for (size_t m = 0; m < report.further.size(); ++m) {
      json["models"][report.further[m].rung.name][g.motor] =
          FurtherJson(job.models.further[m], g.tick_s);
    }
  }
  json["cross_validate"] =
      std::string(kCrossValidationNames[static_cast<size_t>(config.cross_validate)]);
  json["folds"] = Json::array();
  for (const FitJob& job : report.jobs) {
    if (!job.held_out) continue;
    const MotorGroup& g = report.groups[job.group];
    json["folds"].push_back({{"motor", g.motor},
                             {"held_out", *job.held_out},
                             {"training_ticks", job.training_ticks},
                             {"fitted_ticks", job.fitted_ticks},
                             {"paper", PaperJson(job.models.paper, g.tick_s)},
                             {"extended", ExtendedJson(job.models.extended, g.tick_s,
                                                       config.v_max_deg_s.count(g.motor) > 0)}});
    for (size_t m = 0; m < report.further.size(); ++m) {
      json["folds"].back()[report.further[m].rung.name] =
          FurtherJson(job.models.further[m], g.tick_s);
    }
  }
  json["logs"] = Json::array();
  for (const Row& row : report.rows) {
    const ServoLog& log = report.logs[row.log].log;
    json["logs"].push_back({{"file", log.file},
                            {"role", row.train_role ? "train" : "validate"},
                            {"held_out_by", HeldOutBy(row, config)},
                            {"motor", log.motor},
                            {"trajectory", log.trajectory},
                            {"kp", log.kp},
                            {"ticks_scored", row.scores[0].ticks_scored},
                            {"best_shift_s", row.shift_ticks * row.tick_s},
                            {"mae_deg", ScoresJson(report, row, false)},
                            {"rms_deg", ScoresJson(report, row, true)}});
    json["logs"].back()["data"] = DataJson(report.logs[row.log]);
    if (row.plan) {
      json["logs"].back()["plan"] = {{"direct_mae_deg", row.plan->direct_mae_deg},
                                     {"model_based_mae_deg", row.plan->model_based_mae_deg},
                                     {"optimal_mae_deg", row.plan->optimal_mae_deg},
                                     {"beyond_servo_ticks", row.plan->beyond_servo_ticks}};
    }
  }
  return json.dump(2) + "\n";
}

namespace {

// Two decimals, as long as the number needs ("%.2f" written out here: FormatFixed's variable
// precision, inlined into these tables, trips GCC's -Wformat-truncation).
std::string Fixed2(double value) {
  const int size = std::snprintf(nullptr, 0, "%.2f", value);
  std::string text(static_cast<size_t>(size) + 1, '\0');
  std::snprintf(text.data(), text.size(), "%.2f", value);
  text.resize(static_cast<size_t>(size));
  return text;
}

// Each log's data: samples, spacing, segments (split at pauses over logs.gap_s).
void DataMarkdown(const Report& report, const MotorGroup& g, std::ostringstream& md) {
  md << "\nThe logs (jitter: the median absolute deviation of the sample intervals; segments: "
        "split at pauses over logs.gap_s, each fitted and scored on its own; dropped: samples "
        "alone between two pauses; glitches: samples whose measurement was left out, over "
        "logs.glitch_deg from the line through their neighbours; top speed and full duty: "
        "driven ticks measured at 90 % of the final extended model's v_max or more, and whose "
        "request error saturates its duty):\n\n"
     << "| log | samples | duration (s) | median interval (ms) | jitter (ms) | segments | dropped "
        "| glitches | top speed | full duty |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const std::vector<size_t>* list : {&g.train, &g.validate}) {
    for (const size_t i : *list) {
      const Log& l = report.logs[i];
      const std::vector<ServoLogSample>& samples = l.log.samples;
      md << "| " << MarkdownText(l.name) << " | " << samples.size() << " | "
         << Fixed2(samples.back().time_s - samples.front().time_s) << " | "
         << Fixed2(1000.0 * MedianSampleInterval(samples)) << " | "
         << Fixed2(1000.0 * IntervalJitter(samples)) << " | " << l.segments << " | "
         << l.samples_dropped << " | " << l.glitches << " | " << l.ticks_at_top_speed << " | "
         << l.ticks_at_full_duty << " |\n";
    }
  }
}

// Each log's request column as a desired motion through the motor's final extended model.
void PlanMarkdown(const Report& report, const MotorGroup& g, std::ostringstream& md) {
  md << "\nPlanned requests, predicted by the extended model (mean absolute error from the "
        "desired motion, deg, driven ticks; beyond servo: ticks the model-based plan cannot "
        "reach):\n\n"
     << "| log | direct | model_based | optimal | beyond servo |\n|---|---|---|---|---|\n";
  for (const Row& row : report.rows) {
    if (!row.plan || report.logs[row.log].log.motor != g.motor) continue;
    md << "| " << MarkdownText(report.logs[row.log].name) << " | "
       << Fixed2(row.plan->direct_mae_deg) << " | " << Fixed2(row.plan->model_based_mae_deg)
       << " | " << Fixed2(row.plan->optimal_mae_deg) << " | " << row.plan->beyond_servo_ticks
       << " |\n";
  }
}

}  // namespace

std::string ReportMarkdown(const Report& report) {
  std::ostringstream md;
  md << "# Servo logs: open-loop prediction error (mean absolute, deg)\n\n";
  for (const ServoRung& rung : report.rungs) md << rung.label << ": " << rung.description << ". ";
  md << "validate rows are held out: the models never saw the log.\n";
  for (const MotorGroup& g : report.groups) {
    char tick[32];
    std::snprintf(tick, sizeof tick, "%.3f", g.tick_s * 1000.0);
    md << "\n## " << MarkdownText(g.motor) << " (tick " << tick << " ms)\n\n"
       << "| log | role | trajectory | kp | ticks |";
    for (const ServoRung& rung : report.rungs) md << " " << rung.label << " |";
    md << "\n|---|---|---|---|---|";
    for (size_t k = 0; k < report.rungs.size(); ++k) md << "---|";
    md << "\n";
    std::vector<double> sums(report.rungs.size());
    int held = 0;
    for (const Row& row : report.rows) {
      const ServoLog& log = report.logs[row.log].log;
      if (log.motor != g.motor) continue;
      md << "| " << MarkdownText(report.logs[row.log].name) << " | "
         << (row.train_role ? "train"
             : row.held_out ? "held out"
                            : "validate")
         << " | " << MarkdownText(log.trajectory) << " | " << FormatNumber(log.kp) << " | "
         << row.scores[0].ticks_scored;
      for (const PredictionScore& score : row.scores) md << " | " << Fixed2(score.mae_deg);
      md << " |\n";
      if (row.train_role) continue;
      ++held;
      for (size_t k = 0; k < sums.size(); ++k) sums[k] += row.scores[k].mae_deg;
    }
    if (held > 0) {
      md << "| **mean held out** | | | | ";
      for (const double sum : sums) md << " | **" << Fixed2(sum / held) << "**";
      md << " |\n";
    }
    DataMarkdown(report, g, md);
    for (const FitJob& job : report.jobs) {
      if (job.held_out || report.groups[job.group].motor != g.motor) continue;
      if (job.fitted_ticks < job.training_ticks) {
        md << "\nThe final models were fitted on " << job.fitted_ticks << " of the "
           << job.training_ticks
           << " driven training ticks: evenly spaced chunks of every training log "
              "(logs.fit_ticks); every score uses every tick.\n";
      }
    }
    PlanMarkdown(report, g, md);
  }
  return md.str();
}

void WriteLogCsv(const LogFitCurves& c, const OutputDir& out) {
  std::string text;
  for (const std::string_view column : kServoLogColumnList) text += std::string(column) + ',';
  for (const std::string& rung : c.rungs) text += rung + "_deg,";
  text.back() = '\n';
  for (size_t t = 0; t < c.request_deg.size(); ++t) {
    text += FormatNumber(c.time_s[t]) + ',' + FormatNumber(c.request_deg[t]) + ',' +
            FormatNumber(c.measured_deg[t]) + ',' + (c.torque_enabled[t] != 0 ? "1" : "0");
    for (const auto& angles : c.predicted_deg) text += ',' + FormatNumber(angles[t]);
    text += '\n';
  }
  WriteTextFile(out.Path("log_" + c.name + ".csv"), text);
}

}  // namespace leglab::log_fit
