#include <cmath>

#include "leglab/core/format.h"
#include "leglab/servo/log_fit_config.h"

namespace leglab {

void VisitKeys(KeyVisitor& v, LogFitConfig& c) {
  v.Structured("train", "list of files or folders", "[]",
               {.description = "logs the models are fitted on (.json in BAM's form, .csv in "
                               "leglab's); a folder means every log in it; relative to the "
                               "working directory, else to leglab's data folder"});
  v.Structured("validate", "list of files or folders", "[]",
               {.description = "logs the fitted models are scored on, unchanged (held out)"});
  v.Key("format", c.format, kServoLogFormatNames,
        {.description = "auto (by extension), csv (time_s,request_deg,measured_deg"
                        "[,torque_enabled]) or bam_json (BAM's recorded logs as they are)"});
  v.Key("tick_s", c.tick_s,
        {.min = 0,
         .max = 1,
         .unit = "s",
         .description = "the tick the logs are resampled to (request held, measurement "
                        "interpolated); 0: each motor's median sample interval over its "
                        "training logs"});
  v.Key("cross_validate", c.cross_validate, kCrossValidationNames,
        {.description = "none; leave_one_trajectory_out: per motor, each trajectory's logs "
                        "scored by models fitted on the motor's other trajectories; or "
                        "leave_one_kp_out: likewise for each gain setting"});
  v.Key("motor", c.csv.motor,
        {.description = "a CSV log's servo type (one model is fitted per type)"});
  // kp as the drive declares it, but from 0 (its default: a CSV log's kp must then be given).
  v.Key("kp", c.csv.kp, kLogKpDoc);
  v.Key("mass_kg", c.csv.mass_kg, WithDescription(kServoMassDoc, "a CSV log's load mass"));
  v.Key("length_m", c.csv.length_m,
        WithDescription(kServoLengthDoc,
                        "a CSV log's load distance from the axis (0 at the bottom)"));
  v.Structured("v_max_deg_s", "map of motor: deg/s", "{}",
               WithDescription(kServoVMaxDoc,
                               "published no-load speeds: the extended model's v_max of a motor "
                               "named here is held at it instead of fitted"));
  v.Key(
      "lag_max_s", c.lag_max_s,
      {.min = 0, .max = 1, .unit = "s", .description = "longest lag either model's fit searches"});
  v.Key("window_max_s", c.window_max_s,
        {.min = 0,
         .max = 1,
         .unit = "s",
         .description = "longest averaging window a of the paper's model the fit searches"});
  v.Key("shift_max_s", c.shift_max_s,
        {.min = 0,
         .max = 10,
         .unit = "s",
         .description = "longest time shift the best-shift oracle searches"});
  v.Key("gap_s", c.gap_s,
        {.min = 0,
         .max = 1e6,
         .min_open = true,
         .unit = "s",
         .description = "a pause between two samples longer than this splits a log into "
                        "segments, each fitted and scored on its own, never interpolated across"});
  v.Key("glitch_deg", c.glitch_deg,
        {.min = 0,
         .max = 1e5,
         .unit = "deg",
         .description = "a sample measured this far from the line through its two neighbours "
                        "is a glitch: its measurement is left out and counted (0: no check)"});
  v.Key("fit_ticks", c.fit_ticks, kFitTicksDoc);
  v.Key("iterations", c.iterations, kServoFitIterationsDoc);
}

namespace {

std::vector<std::string> ReadFileList(const YAML::Node& node, const std::string& key) {
  if (!node.IsDefined() || node.IsNull()) return {};
  std::vector<std::string> files;
  if (node.IsSequence()) {
    for (size_t i = 0; i < node.size(); ++i) {
      if (!node[i].IsScalar()) {
        FailConfig(key + "[" + std::to_string(i) + "] must be a file name, got '" +
                   FlowYaml(node[i]) + "'");
      }
      files.push_back(node[i].as<std::string>());
    }
    return files;
  }
  if (node.IsScalar()) return {node.as<std::string>()};
  FailConfig(key + " must be a list of files or folders, got '" + FlowYaml(node) + "'");
}

std::map<std::string, double> ReadSpeeds(const YAML::Node& node) {
  std::map<std::string, double> speeds;
  if (!node.IsDefined() || node.IsNull()) return speeds;
  if (!node.IsMap()) {
    FailConfig("logs.v_max_deg_s must be a map of motor: deg/s, got '" + FlowYaml(node) + "'");
  }
  for (const auto& item : node) {
    const std::string motor = KeyText(item.first);
    double speed = 0.0;
    try {
      speed = item.second.as<double>();
    } catch (const YAML::Exception&) {
      FailConfig("logs.v_max_deg_s." + motor + " must be a number, got '" + FlowYaml(item.second) +
                 "'");
    }
    // The range of the model's own v_max_deg_s, which a published speed replaces.
    if (const std::string problem = KeyValueProblem(speed, kServoVMaxDoc); !problem.empty()) {
      FailConfig("logs.v_max_deg_s." + motor + " must be " + problem + ", got " +
                 FormatNumber(speed, NumberStyle::kReadable));
    }
    speeds[motor] = speed;
  }
  return speeds;
}

}  // namespace

void ReadLogFitStructured(YamlKeyReader& reader, LogFitConfig& c) {
  c.train = ReadFileList(reader.Raw("train"), "logs.train");
  c.validate = ReadFileList(reader.Raw("validate"), "logs.validate");
  c.v_max_deg_s = ReadSpeeds(reader.Raw("v_max_deg_s"));
}

}  // namespace leglab

namespace leglab {

LogFitConfig LogFitConfigFromOverrides(const std::vector<std::string>& overrides) {
  YAML::Node root(YAML::NodeType::Map);
  for (const std::string& assignment : overrides) ApplyOverride(root, assignment);
  for (const auto& entry : root) {
    const std::string key = KeyText(entry.first);
    if (key != "logs") {
      FailConfig(key + " is not a logs.* key (a fit of logs given as values reads only those)");
    }
  }
  LogFitConfig config;
  YamlKeyReader reader(root);
  reader.Section("logs", [&] {
    VisitKeys(reader, config);
    ReadLogFitStructured(reader, config);
  });
  reader.Finish();
  config.given = true;
  return config;
}

}  // namespace leglab
