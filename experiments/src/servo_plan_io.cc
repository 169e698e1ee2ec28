#include "leglab/experiments/servo_plan_io.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>

#include "leglab/app/output.h"
#include "leglab/core/format.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/program.h"
#include "leglab/experiments/servo_log_io.h"
#include "leglab/model/servo_planner.h"

namespace leglab::experiments {
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

int Ticks(const Json& object, const std::string& name, const std::string& where,
          const std::string& file) {
  const double value = Number(object, name, where, file);
  // Beyond kMaxServoLagTicks a model's memory makes planning quadratic; no servo lags that long.
  if (value != std::floor(value) || value < 0.0 || value > kMaxServoLagTicks) {
    throw InputError(file + ": " + where + name + " must be a whole number from 0 to " +
                     std::to_string(kMaxServoLagTicks) + ", got " + FormatNumber(value));
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

void ReadRungParams(const Json& entry, const std::string& where, const std::string& file,
                    FittedModel& model) {
  std::string problem;
  if (model.rung == "paper") {
    model.paper = {Number(entry, "v_max_deg_per_tick", where, file),
                   Number(entry, "theta0_deg", where, file), Ticks(entry, "lag_ticks", where, file),
                   Ticks(entry, "accel_ticks", where, file)};
    problem = JointModelParamsProblem(model.paper);
    model.top_speed_deg_s = model.paper.v_max_deg_per_tick / model.tick_s;
  } else {
    model.extended = {Number(entry, "gain_per_deg_kp", where, file),
                      Number(entry, "v_max_deg_s", where, file),
                      Number(entry, "stall_torque_nm", where, file),
                      Number(entry, "friction_duty", where, file),
                      Number(entry, "friction_load_ratio", where, file),
                      Number(entry, "velocity_lag_s", where, file),
                      Ticks(entry, "lag_ticks", where, file)};
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

ServoDrive ChooseDrive(const PlanOptions& o, const DesiredServoMotion& motion,
                       const FittedModel& model) {
  if (motion.drive) {
    if (o.kp || o.mass_kg || o.length_m) {
      throw InputError("--kp, --mass-kg and --length-m: the log '" + o.desired_path +
                       "' gives its own kp, mass and length; leave them out");
    }
    return *motion.drive;
  }
  if (model.rung == "extended" && !o.kp) {
    throw InputError("--kp is required for the extended rung (the desired file gives no kp)");
  }
  return {o.kp.value_or(1.0), o.mass_kg.value_or(0.0), o.length_m.value_or(0.0)};
}

void CheckOptions(const PlanOptions& o) {
  struct Bound {
    const char* name;
    std::optional<double> value;
    double min;
    double max;
    bool min_open;
  };
  const Bound bounds[] = {{"--kp", o.kp, 0.0, kMaxServoKp, true},
                          {"--mass-kg", o.mass_kg, 0.0, kMaxServoMassKg, false},
                          {"--length-m", o.length_m, 0.0, kMaxServoLengthM, false},
                          {"--min-deg", o.min_deg, -kMaxPlanAngleDeg, kMaxPlanAngleDeg, false},
                          {"--max-deg", o.max_deg, -kMaxPlanAngleDeg, kMaxPlanAngleDeg, false}};
  for (const Bound& b : bounds) {
    if (!b.value) continue;
    const double v = *b.value;
    if (!(v <= b.max && (b.min_open ? v > b.min : v >= b.min))) {
      throw InputError(std::string(b.name) + " must be in " + (b.min_open ? "(" : "[") +
                       FormatNumber(b.min, NumberStyle::kReadable) + ", " +
                       FormatNumber(b.max, NumberStyle::kReadable) + "], got " + FormatNumber(v));
    }
  }
  if (o.preview_ticks && !o.online) {
    throw InputError("--preview-ticks goes with --online (the batch plan sees the whole motion)");
  }
  if (o.min_deg >= o.max_deg) {
    throw InputError("--min-deg " + FormatNumber(o.min_deg) + " must be below --max-deg " +
                     FormatNumber(o.max_deg));
  }
}

double MeanAbsoluteError(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (size_t t = 0; t < a.size(); ++t) sum += std::abs(a[t] - b[t]);
  return sum / static_cast<double>(a.size());
}

PlanResult Plan(const PlanOptions& o) {
  CheckOptions(o);
  const DesiredServoMotion motion = ReadDesiredMotion(o.desired_path);
  const FittedModel model =
      ReadFittedModel(o.model_path, o.rung, o.motor.empty() ? motion.motor : o.motor);
  const ServoDrive drive = ChooseDrive(o, motion, model);
  std::vector<double> desired = ResampleDesired(motion, model.tick_s, o.desired_path);
  if (desired[0] < o.min_deg || desired[0] > o.max_deg) {
    throw InputError("--desired '" + o.desired_path + "': its first angle " +
                     FormatNumber(desired[0]) + " deg is outside --min-deg/--max-deg");
  }
  const PlanMethod method = o.method == "optimal" ? PlanMethod::kOptimal : PlanMethod::kModelBased;
  if (o.online) {
    return PlanDesiredOnline(model, drive, std::move(desired), o.min_deg, o.max_deg, method,
                             o.preview_ticks.value_or(-1));
  }
  return PlanDesired(model, drive, std::move(desired), o.min_deg, o.max_deg, method);
}

void WriteRequests(const PlanResult& r, const fs::path& path) {
  CsvWriter csv(path, {"time_s", "desired_deg", "request_deg", "predicted_deg", "beyond_servo"});
  for (size_t t = 0; t < r.desired.size(); ++t) {
    csv.Cell(static_cast<double>(t) * r.model.tick_s)
        .Cell(r.desired[t])
        .Cell(r.plan.request_deg[t])
        .Cell(r.plan.predicted_deg[t])
        .Cell(static_cast<long>(r.plan.beyond_servo[t]));
    csv.EndRow();
  }
  csv.Close();
}

std::string PlanJson(const PlanOptions& o, const PlanResult& r) {
  Json j;
  j["rung"] = r.model.rung;
  j["method"] = o.method;
  j["motor"] = r.model.motor;
  j["tick_s"] = r.model.tick_s;
  j["ticks"] = r.desired.size();
  j["beyond_servo_ticks"] = r.plan.beyond_servo_ticks;
  j["predicted_mae_deg"] = {{"planned", MeanAbsoluteError(r.plan.predicted_deg, r.desired)},
                            {"direct", MeanAbsoluteError(r.direct, r.desired)}};
  j["limits"] = {{"min_deg", r.limits.min_deg},
                 {"max_deg", r.limits.max_deg},
                 {"max_speed_deg_s", r.limits.max_speed_deg_s}};
  if (r.model.rung == "extended") {
    j["drive"] = {{"kp", r.drive.kp}, {"mass_kg", r.drive.mass_kg}, {"length_m", r.drive.length_m}};
  }
  if (r.preview_ticks) j["online"] = {{"preview_ticks", *r.preview_ticks}};
  j["model_file"] = o.model_path;
  j["desired_file"] = o.desired_path;
  return j.dump(2) + "\n";
}

std::string Summary(const PlanOptions& o, const PlanResult& r) {
  std::ostringstream s;
  s << std::fixed << "plan: " << r.desired.size() << " ticks of " << std::setprecision(2)
    << r.model.tick_s * 1000.0 << " ms, the " << r.model.rung << " model of " << r.model.motor
    << ", " << o.method << ": predicted mean absolute error "
    << MeanAbsoluteError(r.plan.predicted_deg, r.desired) << " deg planned vs "
    << MeanAbsoluteError(r.direct, r.desired) << " deg with the desired angles sent as they are; "
    << r.plan.beyond_servo_ticks
    << " ticks beyond the servo for the model-based inversion. Wrote requests.csv and plan.json "
       "into "
    << o.out_dir << ".\n";
  return s.str();
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
  if (!(model.tick_s >= kMinPlanTickS && model.tick_s <= kMaxPlanTickS)) {
    throw InputError(source + ": " + where + ".tick_s must be from " +
                     FormatNumber(kMinPlanTickS, NumberStyle::kReadable) + " to " +
                     FormatNumber(kMaxPlanTickS, NumberStyle::kReadable) + " s, got " +
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
                             PlanMethod method, int preview_ticks) {
  ServoPlannerOptions options;
  options.method = method;
  options.preview_ticks = preview_ticks;
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

std::string RunPlan(const PlanOptions& options) {
  OutputDir out(options.out_dir, {"requests.", "plan."});
  const PlanResult result = Plan(options);
  WriteRequests(result, out.Path("requests.csv"));
  WriteTextFile(out.Path("plan.json"), PlanJson(options, result));
  out.Commit();
  return Summary(options, result);
}

int PlanMain(int argc, char** argv) {
  CLI::App app(
      "Plan requests for a real servo from a fitted model (identify's log_fit.json) to follow "
      "a desired motion within its limits",
      "plan");
  PlanOptions o;
  app.add_option("--model", o.model_path, "identify's log_fit.json")->required();
  app.add_option("--rung", o.rung, "which model: paper or extended (default)")
      ->check(CLI::IsMember({"paper", "extended"}));
  app.add_option("--method", o.method, "model_based (default) or optimal")
      ->check(CLI::IsMember({"model_based", "optimal"}));
  app.add_option("--desired", o.desired_path,
                 "a CSV time_s,desired_deg, or a servo log (BAM .json or leglab's log CSV)")
      ->required();
  app.add_option("--out", o.out_dir, "folder for requests.csv and plan.json")->required();
  app.add_option("--motor", o.motor, "the model file's motor (needed when it has several)");
  app.add_option("--kp", o.kp, "the servo's gain register (extended rung, not with a BAM log)");
  app.add_option("--mass-kg", o.mass_kg, "the load's mass (kg, default 0)");
  app.add_option("--length-m", o.length_m, "the load's arm (m, default 0)");
  app.add_option("--min-deg", o.min_deg, "least request (deg, default -180)");
  app.add_option("--max-deg", o.max_deg, "greatest request (deg, default 180)");
  app.add_flag("--online", o.online,
               "the online planner's requests, tick by tick on the model, instead of the batch "
               "plan's");
  app.add_option("--preview-ticks", o.preview_ticks,
                 "with --online: desired angles ahead the planner is given (default: the "
                 "method's own)")
      ->check(CLI::Range(0, kMaxServoPreviewTicks));
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "plan: error: " << MessageLine(e.what()) << " (see --help)\n";
    return 2;
  }
  InstallInterruptCleanup("plan");
  return ReportErrors("plan", [&] { std::cout << RunPlan(o); });
}

}  // namespace leglab::experiments
