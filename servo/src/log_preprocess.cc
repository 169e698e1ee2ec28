#include "log_preprocess.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <span>

#include "leglab/app/data_dir.h"
#include "leglab/app/yaml_config.h"
#include "leglab/core/format.h"
#include "leglab/servo/servo_log.h"

namespace leglab::log_fit {
namespace {

namespace fs = std::filesystem;

std::string Sanitized(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == '-' || c == '.')) {
      c = '_';
    }
  }
  return out;
}

bool IsLogFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".json" || ext == ".csv";
}

// `entry` of logs.<key>: a file, or a folder's logs by name; from the working directory, else
// from leglab's data folder.
std::vector<std::string> Expand(const std::string& entry, const std::string& key) {
  fs::path path(entry);
  if (path.is_relative() && !PathExists(path) && PathExists(DataDir() / path)) {
    path = DataDir() / path;
  }
  if (!PathExists(path)) FailConfig(key + ": '" + entry + "' does not exist");
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return {path.string()};
  std::vector<std::string> files;
  for (const fs::directory_entry& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file(ec) && IsLogFile(e.path())) files.push_back(e.path().string());
  }
  if (ec) FailConfig(key + ": cannot list the folder '" + entry + "'");
  std::sort(files.begin(), files.end());
  if (files.empty()) FailConfig(key + ": the folder '" + entry + "' holds no .json or .csv log");
  return files;
}

std::vector<std::string> ExpandAll(const std::vector<std::string>& entries,
                                   const std::string& key) {
  std::vector<std::string> files;
  for (const std::string& entry : entries) {
    for (std::string& file : Expand(entry, key)) files.push_back(std::move(file));
  }
  return files;
}

// The most ticks a log is resampled to: twice the most samples a log may have.
constexpr double kMaxResampledTicks = 2.0 * static_cast<double>(kMaxServoLogSamples);

// The log's samples split at every pause longer than logs.gap_s.
std::vector<std::span<const ServoLogSample>> Segments(const ServoLog& log, double gap_s) {
  std::vector<std::span<const ServoLogSample>> segments;
  const std::span<const ServoLogSample> all(log.samples);
  size_t start = 0;
  for (size_t i = 1; i <= all.size(); ++i) {
    if (i == all.size() || all[i].time_s - all[i - 1].time_s > gap_s) {
      segments.push_back(all.subspan(start, i - start));
      start = i;
    }
  }
  return segments;
}

// `segment` with each glitch's measurement replaced by the line through its neighbours: a
// sample (not a segment's first or last) measured more than `glitch_deg` from that line, and
// further from it than either neighbour is from its own (a glitch pulls its neighbours' lines
// half as far). Counts them into `glitches`.
std::vector<ServoLogSample> WithoutGlitches(std::span<const ServoLogSample> segment,
                                            double glitch_deg, int& glitches) {
  std::vector<ServoLogSample> out(segment.begin(), segment.end());
  if (glitch_deg <= 0.0 || segment.size() < 3) return out;
  const auto line = [&](size_t i) {
    const ServoLogSample& a = segment[i - 1];
    const ServoLogSample& b = segment[i + 1];
    const double w = (segment[i].time_s - a.time_s) / (b.time_s - a.time_s);
    return a.measured_deg + w * (b.measured_deg - a.measured_deg);
  };
  const auto off = [&](size_t i) {
    return i == 0 || i + 1 == segment.size() ? 0.0 : std::abs(segment[i].measured_deg - line(i));
  };
  for (size_t i = 1; i + 1 < segment.size(); ++i) {
    const double d = off(i);
    if (d > glitch_deg && d > off(i - 1) && d >= off(i + 1)) {
      out[i].measured_deg = line(i);
      ++glitches;
    }
  }
  return out;
}

}  // namespace

std::vector<Log> ReadLogs(const LogFitConfig& config, const std::vector<GivenServoLog>& given) {
  if (config.train.empty() &&
      std::none_of(given.begin(), given.end(), [](const auto& g) { return g.train; })) {
    FailConfig("logs.train: no log to fit on");
  }
  const std::vector<std::string> train = ExpandAll(config.train, "logs.train");
  const std::vector<std::string> validate = ExpandAll(config.validate, "logs.validate");
  std::vector<Log> logs;
  std::set<std::string> names;
  std::set<std::string> files;
  for (size_t i = 0; i < train.size() + validate.size(); ++i) {
    const bool is_train = i < train.size();
    const std::string& file = is_train ? train[i] : validate[i - train.size()];
    const std::string canonical = fs::weakly_canonical(file).string();
    if (!files.insert(canonical).second) {
      FailConfig("logs: '" + file + "' is given twice (in logs.train or logs.validate)");
    }
    Log log;
    log.log = ReadServoLog(file, config.format, config.csv);
    log.train = is_train;
    log.name = Sanitized(log.log.motor + "_" + fs::path(file).stem().string());
    if (!names.insert(log.name).second) {
      FailConfig("logs: two logs would both write log_" + log.name + ".csv ('" + file + "')");
    }
    logs.push_back(std::move(log));
  }
  for (const GivenServoLog& g : given) {
    CheckServoLog(g.log);
    Log log;
    log.log = g.log;
    log.train = g.train;
    log.name = Sanitized(log.log.motor + "_" + fs::path(g.log.file).stem().string());
    if (!names.insert(log.name).second) {
      FailConfig("logs: two logs would both be named " + log.name + " ('" + g.log.file + "')");
    }
    logs.push_back(std::move(log));
  }
  // Training logs first, in the order given (each motor's fits see them in this order).
  std::stable_partition(logs.begin(), logs.end(), [](const Log& l) { return l.train; });
  return logs;
}

void Resample(Log& log, double tick_s, const LogFitConfig& config) {
  const std::vector<std::span<const ServoLogSample>> segments = Segments(log.log, config.gap_s);
  double ticks = 0.0;
  for (const auto& segment : segments) {
    if (segment.size() >= 2) ticks += (segment.back().time_s - segment.front().time_s) / tick_s + 2;
  }
  const ServoLog& l = log.log;
  if (!(ticks <= kMaxResampledTicks)) {
    FailConfig("logs.tick_s" +
               std::string(config.tick_s > 0.0 ? "" : " (0: the motor's median sample interval)") +
               " = " + FormatNumber(tick_s) + " s would resample the log '" + l.file + "' (" +
               FormatNumber(l.samples.back().time_s - l.samples.front().time_s) + " s) to " +
               FormatNumber(std::ceil(ticks), NumberStyle::kReadable) +
               " ticks, over the limit of " +
               FormatNumber(kMaxResampledTicks, NumberStyle::kReadable));
  }
  if (config.tick_s > 0.0 && l.samples.size() >= 2) {
    const double interval = MedianSampleInterval(std::span<const ServoLogSample>(l.samples));
    if (tick_s < kMinTickPerSampleInterval * interval) {
      FailConfig("logs.tick_s = " + FormatNumber(tick_s) + " s is under " +
                 FormatNumber(kMinTickPerSampleInterval) + " of the log '" + l.file +
                 "''s median sample interval, " + FormatNumber(interval, NumberStyle::kReadable) +
                 " s: its samples hold nothing at that tick; use at least " +
                 FormatNumber(kMinTickPerSampleInterval * interval, NumberStyle::kReadable) +
                 " s, or 0 for the motor's median interval");
    }
  }
  ServoRecording& r = log.recording;
  r.drive = {l.kp, l.mass_kg, l.length_m};
  const double first = l.samples.front().time_s;
  for (const auto& segment : segments) {
    if (segment.size() < 2) {
      log.samples_dropped += static_cast<int>(segment.size());
      continue;
    }
    if (!r.scored.empty()) {  // one tick, torque off, between segments: the model restarts
      log.time_s.push_back(log.time_s.back() + tick_s);
      r.request_deg.push_back(r.request_deg.back());
      r.measured_deg.push_back(r.measured_deg.back());
      r.scored.push_back(0);
    }
    const ResampledLog part =
        leglab::Resample(WithoutGlitches(segment, config.glitch_deg, log.glitches), tick_s);
    const double offset = segment.front().time_s - first;
    for (size_t k = 0; k < part.request_deg.size(); ++k) {
      log.time_s.push_back(offset + static_cast<double>(k) * tick_s);
    }
    r.request_deg.insert(r.request_deg.end(), part.request_deg.begin(), part.request_deg.end());
    r.measured_deg.insert(r.measured_deg.end(), part.measured_deg.begin(), part.measured_deg.end());
    r.scored.insert(r.scored.end(), part.torque_enabled.begin(), part.torque_enabled.end());
    ++log.segments;
  }
  if (log.segments == 0) {
    throw InputError("servo log '" + l.file + "': no two samples are within logs.gap_s = " +
                     FormatNumber(config.gap_s) + " s of each other");
  }
  if (std::find(r.scored.begin(), r.scored.end(), 1) == r.scored.end()) {
    throw InputError("servo log '" + l.file + "': no tick at " + FormatNumber(tick_s) +
                     " s has the torque on");
  }
  if (const std::string problem = KeyValueProblem(r.drive.kp, kServoKpDoc); !problem.empty()) {
    throw InputError("servo log '" + l.file + "': kp must be " + problem +
                     " (logs.kp for a CSV log), got " + FormatNumber(r.drive.kp));
  }
}

}  // namespace leglab::log_fit
