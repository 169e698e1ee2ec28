#include "leglab/servo/servo_plan_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>

#include "leglab/app/input_error.h"
#include "leglab/app/output.h"
#include "leglab/app/progress.h"
#include "leglab/core/format.h"
#include "leglab/servo/servo_log_io.h"
#include "leglab/servo/servo_planner.h"

namespace leglab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// The longest plan: about a minute of model_based planning, and a day at 86 ms ticks.
constexpr long kMaxPlanTicks = 1'000'000;

std::string ReadWholeFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  if (ec || !fs::is_regular_file(path)) {
    throw InputError(what + " '" + path + "': cannot be read (no such file)");
  }
  if (size > kMaxServoLogBytes) {
    throw InputError(what + " '" + path + "': larger than " +
                     std::to_string(kMaxServoLogBytes >> 20) + " MiB");
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(what + " '" + path + "': cannot be read");
  return text.str();
}

std::string Names(const Json& object) {
  std::string names;
  for (const auto& [name, value] : object.items()) names += (names.empty() ? "" : ", ") + name;
  return names.empty() ? "none" : names;
}

// The member `name` of `object` (at `where`), which must be an object.
const Json& Member(const Json& object, const std::string& name, const std::string& where,
                   const std::string& file) {
  if (!object.is_object() || !object.contains(name)) {
    throw InputError(file + ": " + where + name + " is missing");
  }
  const Json& member = object.at(name);
  if (!member.is_object()) {
    throw InputError(file + ": " + where + name + " is not an object");
  }
  return member;
}

double Number(const Json& object, const std::string& name, const std::string& where,
              const std::string& file) {
  const auto found = object.find(name);
  if (found == object.end()) {
    throw InputError(file + ": " + where + name + " is missing");
  }
  if (!found->is_number()) {
    throw InputError(file + ": " + where + name + " is not a number");
  }
  return found->get<double>();
}

// A model's count of ticks (l or a): a whole number in `doc`'s range (any joint model's, up to
// kMaxServoLagTicks: beyond it a model's memory makes planning quadratic).
int Ticks(const Json& object, const std::string& name, const std::string& where,
          const std::string& file, const KeyDoc& doc) {
  const double value = Number(object, name, where, file);
  std::string problem = KeyValueProblem(value, doc);
  if (problem.empty() && value != std::floor(value)) problem = "a whole number";
  if (!problem.empty()) {
    throw InputError(file + ": " + where + name + " must be " + problem + ", got " +
                     FormatNumber(value));
  }
  return static_cast<int>(value);
}

// The entry of `motor` in `rung_models`, or of the only motor when `motor` is empty.
std::string ChooseMotor(const Json& rung_models, const std::string& motor, const std::string& where,
                        const std::string& file) {
  if (!motor.empty()) {
    if (rung_models.contains(motor)) return motor;
    throw InputError(file + ": " + where + " has no motor '" + motor +
                     "' (it has: " + Names(rung_models) + ")");
  }
  if (rung_models.size() != 1) {
    throw InputError(file + ": " + where + " has " + std::to_string(rung_models.size()) +
                     " motors; choose one with --motor (" + Names(rung_models) + ")");
  }
  return rung_models.items().begin().key();
}

// A model's values read under its keys' names, in its declaration's order (`visit`, its
// VisitKeys): a number each, an integer key a whole number in its declared range. Its ranges
// are the caller's to check.
template <typename Params, typename Visit>
Params ReadKeys(const Json& entry, const std::string& where, const std::string& file, Visit visit) {
  Params params{};
  for (const KeyValue& k : KeyValues(params, visit)) {
    const double value =
        k.integer ? Ticks(entry, k.key, where, file, k.doc) : Number(entry, k.key, where, file);
    KeyAssigner assigner(k.key, value);
    try {
      visit(assigner, params);
    } catch (const std::invalid_argument& e) {  // a rule of several keys, broken
      throw InputError(file + ": " + where + e.what());
    }
  }
  return params;
}

void ReadRungParams(const Json& entry, const std::string& where, const std::string& file,
                    FittedModel& model) {
  std::string problem;
  if (model.rung == "paper") {
    model.paper = ReadKeys<JointModelParams>(
        entry, where, file,
        [](KeyVisitor& v, JointModelParams& p) { VisitKeys(v, p, kAnyJointModel); });
    problem = JointModelParamsProblem(model.paper);
    model.top_speed_deg_s = model.paper.v_max_deg_per_tick / model.tick_s;
  } else {
    model.extended = ReadKeys<ServoModelParams>(
        entry, where, file, [](KeyVisitor& v, ServoModelParams& p) { VisitKeys(v, p); });
    problem = ServoModelParamsProblem(model.extended);
    model.top_speed_deg_s = model.extended.v_max_deg_s;
  }
  if (!problem.empty()) throw InputError(file + ": " + where + ": " + problem);
}

// One plain decimal cell (the whole cell, no '+', hex or spaces), finite.
double ParseCell(const std::string& cell, const std::string& where) {
  double value = 0.0;
  const char* end = cell.data() + cell.size();
  const auto parsed = std::from_chars(cell.data(), end, value);
  if (cell.empty() || parsed.ec != std::errc() || parsed.ptr != end || !std::isfinite(value)) {
    throw InputError(where + ": '" + cell.substr(0, 40) + "' is not a finite decimal number");
  }
  return value;
}

void ParseDesiredRow(const std::string& line, int row, const std::string& file,
                     DesiredServoMotion& motion) {
  const std::string where = "--desired '" + file + "': row " + std::to_string(row);
  const size_t comma = line.find(',');
  if (comma == std::string::npos || line.find(',', comma + 1) != std::string::npos) {
    throw InputError(where + " must have 2 columns (time_s,desired_deg)");
  }
  const double time = ParseCell(line.substr(0, comma), where + ", time_s");
  const double angle = ParseCell(line.substr(comma + 1), where + ", desired_deg");
  if (!motion.time_s.empty() && time <= motion.time_s.back()) {
    throw InputError(where + ", time_s: " + FormatNumber(time) + " is not after the row before");
  }
  if (motion.time_s.size() >= kMaxServoLogSamples) {
    throw InputError("--desired '" + file + "': more than " + std::to_string(kMaxServoLogSamples) +
                     " rows");
  }
  motion.time_s.push_back(time);
  motion.desired_deg.push_back(angle);
}

DesiredServoMotion ReadDesiredCsv(const std::string& path, const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "time_s,desired_deg") {
    throw InputError("--desired '" + path +
                     "': the header must be time_s,desired_deg (or a servo log's), got '" +
                     line.substr(0, 40) + "'");
  }
  DesiredServoMotion motion;
  for (int row = 1; std::getline(in, line); ++row) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) ParseDesiredRow(line, row, path, motion);
  }
  if (motion.time_s.size() < 2) {
    throw InputError("--desired '" + path + "': needs at least 2 rows");
  }
  return motion;
}

DesiredServoMotion FromLog(const ServoLog& log, bool with_drive) {
  DesiredServoMotion motion;
  motion.is_log = true;
  for (const ServoLogSample& s : log.samples) {
    motion.time_s.push_back(s.time_s);
    motion.desired_deg.push_back(s.request_deg);
  }
  if (with_drive) {
    motion.motor = log.motor;
    motion.drive = ServoDrive{log.kp, log.mass_kg, log.length_m};
  }
  return motion;
}

long TickCount(const DesiredServoMotion& motion, double tick_s, const std::string& path) {
  const double span = (motion.time_s.back() - motion.time_s.front()) / tick_s;
  if (!(span < static_cast<double>(kMaxPlanTicks))) {
    throw InputError("--desired '" + path + "': spans more than " + std::to_string(kMaxPlanTicks) +
                     " ticks of " + FormatNumber(tick_s) + " s");
  }
  return static_cast<long>(std::floor(span + 1e-9 / tick_s)) + 1;
}

// Linear interpolation of the desired CSV at time `time`, from sample `i` on.
double Interpolate(const DesiredServoMotion& m, double time, size_t& i) {
  while (i + 2 < m.time_s.size() && m.time_s[i + 1] <= time) ++i;
  const double span = m.time_s[i + 1] - m.time_s[i];
  const double w = std::clamp((time - m.time_s[i]) / span, 0.0, 1.0);
  return m.desired_deg[i] + w * (m.desired_deg[i + 1] - m.desired_deg[i]);
}

}  // namespace

FittedModel ParseFittedModel(const std::string& text, const std::string& rung,
                             const std::string& motor, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {  // malformed, or a number too large for a double
    throw InputError(source + ": not valid JSON (" + e.what() + ")");
  }
  const std::string& file = source;
  const Json& models = Member(root, "models", "", file);
  const Json& rung_models = Member(models, rung, "models.", file);
  FittedModel model;
  model.rung = rung;
  model.motor = ChooseMotor(rung_models, motor, "models." + rung, file);
  const std::string where = "models." + rung + "." + model.motor;
  const Json& entry = Member(rung_models, model.motor, "models." + rung + ".", file);
  model.tick_s = Number(entry, "tick_s", where + ".", file);
  if (const std::string problem = KeyValueProblem(model.tick_s, kServoTickDoc); !problem.empty()) {
    throw InputError(source + ": " + where + ".tick_s must be " + problem + ", got " +
                     FormatNumber(model.tick_s));
  }
  ReadRungParams(entry, where + ".", file, model);
  return model;
}

FittedModel ReadFittedModel(const std::string& path, const std::string& rung,
                            const std::string& motor) {
  return ParseFittedModel(ReadWholeFile(path, "--model"), rung, motor, "--model '" + path + "'");
}

DesiredServoMotion ReadDesiredMotion(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".json") return FromLog(ReadServoLog(path, ServoLogFormat::kBamJson, {}), true);
  const std::string text = ReadWholeFile(path, "--desired");
  if (text.starts_with("time_s,request_deg")) {
    return FromLog(ReadServoLog(path, ServoLogFormat::kCsv, {}), false);
  }
  return ReadDesiredCsv(path, text);
}

std::vector<double> ResampleDesired(const DesiredServoMotion& motion, double tick_s,
                                    const std::string& path) {
  const long ticks = TickCount(motion, tick_s, path);
  if (motion.is_log) {
    std::vector<ServoLogSample> samples(motion.time_s.size());
    for (size_t i = 0; i < samples.size(); ++i) {
      samples[i] = {motion.time_s[i], motion.desired_deg[i], 0.0, true};
    }
    return Resample(samples, tick_s).request_deg;
  }
  std::vector<double> desired(static_cast<size_t>(ticks));
  size_t i = 0;
  for (long t = 0; t < ticks; ++t) {
    desired[t] = Interpolate(motion, motion.time_s.front() + static_cast<double>(t) * tick_s, i);
  }
  return desired;
}

PlanResult PlanDesired(const FittedModel& model, const ServoDrive& drive,
                       std::vector<double> desired_deg, double min_deg, double max_deg,
                       PlanMethod method) {
  PlanResult r;
  r.model = model;
  r.drive = drive;
  r.desired = std::move(desired_deg);
  r.limits = {min_deg, max_deg, model.top_speed_deg_s};
  if (model.rung == "paper") {
    r.plan = PlanJointModelRequests(model.paper, model.tick_s, r.desired, r.limits, method);
    r.direct = PredictJointModelAngles(model.paper, r.desired);
  } else {
    r.plan = PlanServoRequests(model.extended, drive, model.tick_s, r.desired, r.limits, method);
    r.direct = PredictServoAngles(model.extended, drive, model.tick_s, r.desired);
  }
  return r;
}

PlanResult PlanDesiredOnline(const FittedModel& model, const ServoDrive& drive,
                             std::vector<double> desired_deg, double min_deg, double max_deg,
                             const ServoPlannerOptions& options) {
  const ServoLimits limits{min_deg, max_deg, model.top_speed_deg_s};
  ServoPlanner planner = model.rung == "paper"
                             ? ServoPlanner(model.paper, model.tick_s, limits, options)
                             : ServoPlanner(model.extended, drive, model.tick_s, limits, options);
  PlanResult r =
      PlanDesired(model, drive, std::move(desired_deg), min_deg, max_deg, PlanMethod::kModelBased);
  r.preview_ticks = planner.PreviewTicks();
  const std::span<const double> desired(r.desired);
  const auto window = static_cast<size_t>(planner.PreviewTicks()) + 1;
  planner.Reset(desired[0]);
  for (size_t t = 0; t < desired.size(); ++t) {
    CountProgressTicks(1);  // the display's count, and where a stop request ends the run
    r.plan.predicted_deg[t] = planner.ExpectedDeg();
    r.plan.request_deg[t] = planner.Request(
        desired.subspan(t, std::min(window, desired.size() - t)), r.plan.predicted_deg[t]);
    if (!std::isfinite(r.plan.request_deg[t]) || !std::isfinite(r.plan.predicted_deg[t])) {
      throw std::invalid_argument("servo planner: the plan is not finite at tick " +
                                  std::to_string(t) + ": the model's numbers are out of its range");
    }
  }
  return r;
}

}  // namespace leglab
