#include "leglab/servo/plan_program.h"

#include <unistd.h>
#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "leglab/app/input_error.h"
#include "leglab/app/output.h"
#include "leglab/app/program.h"
#include "leglab/app/progress.h"
#include "leglab/core/format.h"
#include "leglab/servo/servo_log_io.h"
#include "leglab/servo/servo_planner.h"

namespace leglab {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

ServoDrive ChooseDrive(const PlanOptions& o, const DesiredServoMotion& motion,
                       const FittedModel& model) {
  if (motion.drive) {
    if (o.kp || o.mass_kg || o.length_m) {
      throw InputError("--kp, --mass-kg and --length-m: the log '" + o.desired_path +
                       "' gives its own kp, mass and length; leave them out");
    }
    if (const std::string problem = ServoDriveProblem(*motion.drive);
        model.rung == "extended" && !problem.empty()) {
      throw InputError("--desired '" + o.desired_path + "': the log's " + problem);
    }
    return *motion.drive;
  }
  if (model.rung == "extended" && !o.kp) {
    throw InputError("--kp is required for the extended rung (the desired file gives no kp)");
  }
  return {o.kp.value_or(1.0), o.mass_kg.value_or(0.0), o.length_m.value_or(0.0)};
}

void CheckOptions(const PlanOptions& o) {
  // The drive's flags keep the drive's declaration (kServo*Doc); the request bounds, any angle
  // a plan may hold.
  const struct {
    const char* flag;
    std::optional<double> value;
    const KeyDoc& doc;
  } flags[] = {{"--kp", o.kp, kServoKpDoc},
               {"--mass-kg", o.mass_kg, kServoMassDoc},
               {"--length-m", o.length_m, kServoLengthDoc},
               {"--min-deg", o.min_deg, kServoAngleDoc},
               {"--max-deg", o.max_deg, kServoAngleDoc}};
  for (const auto& f : flags) {
    if (!f.value) continue;
    if (std::string problem = KeyValueProblem(*f.value, f.doc); !problem.empty()) {
      throw InputError(std::string(f.flag) + " must be " + problem + ", got " +
                       FormatNumber(*f.value));
    }
  }
  if (o.preview_ticks) {
    const KeyDoc doc = WithRange(kServoPreviewDoc, 0, kMaxServoPreviewTicks);
    if (std::string problem = KeyValueProblem(*o.preview_ticks, doc); !problem.empty()) {
      throw InputError("--preview-ticks must be " + problem + ", got " +
                       std::to_string(*o.preview_ticks));
    }
  }
  if (o.preview_ticks && !o.online) {
    throw InputError("--preview-ticks goes with --online (the batch plan sees the whole motion)");
  }
  // The online optimal planner's effort, each flag in its option's declared range.
  const struct {
    const char* flag;
    std::optional<double> value;
    KeyDoc doc;
  } efforts[] = {
      {"--budget-ms", o.budget_ms, WithRange(kServoBudgetDoc, -1, kServoBudgetDoc.max * 1000)},
      {"--hold-ticks", o.hold_ticks, kServoHoldDoc},
      {"--handover-ticks", o.handover_ticks, kServoHandoverDoc},
      {"--iterations-per-tick", o.iterations_per_tick, kServoIterationsDoc}};
  for (const auto& f : efforts) {
    if (!f.value) continue;
    if (!o.online || o.method != "optimal") {
      throw InputError(std::string(f.flag) +
                       " goes with --online --method optimal (the online optimal planner's "
                       "effort)");
    }
    if (std::string problem = KeyValueProblem(*f.value, f.doc); !problem.empty()) {
      throw InputError(std::string(f.flag) + " must be " + problem + ", got " +
                       FormatNumber(*f.value));
    }
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

// The root of the mean squared error: the optimal plans' objective, as an angle.
double RootMeanSquareError(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0.0;
  for (size_t t = 0; t < a.size(); ++t) sum += (a[t] - b[t]) * (a[t] - b[t]);
  return std::sqrt(sum / static_cast<double>(a.size()));
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
    // Online, the planner runs tick by tick (optimal up to its budget a tick): the display
    // counts them.
    ReplanProgress(static_cast<long long>(desired.size()), "ticks");
    SetProgressPhase("planning online, tick by tick");
    ServoPlannerOptions options;
    options.method = method;
    options.preview_ticks = o.preview_ticks.value_or(-1);
    if (o.budget_ms) options.budget_s = *o.budget_ms < 0 ? -1.0 : *o.budget_ms / 1000.0;
    options.hold_ticks = o.hold_ticks.value_or(options.hold_ticks);
    options.handover_ticks = o.handover_ticks.value_or(options.handover_ticks);
    options.optimal_iterations_per_tick =
        o.iterations_per_tick.value_or(options.optimal_iterations_per_tick);
    return PlanDesiredOnline(model, drive, std::move(desired), o.min_deg, o.max_deg, options);
  }
  return PlanDesired(model, drive, std::move(desired), o.min_deg, o.max_deg, method);
}

void WriteRequests(const PlanResult& r, const fs::path& path) {
  CsvWriter csv(path, ColumnNames(kRequestsColumns));
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
  j["predicted_rms_deg"] = {{"planned", RootMeanSquareError(r.plan.predicted_deg, r.desired)},
                            {"direct", RootMeanSquareError(r.direct, r.desired)}};
  j["limits"] = {{"min_deg", r.limits.min_deg},
                 {"max_deg", r.limits.max_deg},
                 {"max_speed_deg_s", r.limits.max_speed_deg_s}};
  if (r.model.rung == "extended") {
    j["drive"] = {{"kp", r.drive.kp}, {"mass_kg", r.drive.mass_kg}, {"length_m", r.drive.length_m}};
  }
  if (r.preview_ticks) j["online"] = {{"preview_ticks", *r.preview_ticks}};
  if (r.preview_ticks && o.method == "optimal") {
    const ServoPlannerOptions defaults;
    j["online"]["hold_ticks"] = o.hold_ticks.value_or(defaults.hold_ticks);
    j["online"]["handover_ticks"] = o.handover_ticks.value_or(defaults.handover_ticks);
    j["online"]["budget_ms"] = o.budget_ms.value_or(defaults.budget_s);
    j["online"]["iterations_per_tick"] =
        o.iterations_per_tick.value_or(defaults.optimal_iterations_per_tick);
  }
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

std::string RunPlan(const PlanOptions& options) {
  OutputDir out(options.out_dir, {"requests.", "plan."});
  const ProgressStyle style = options.quiet || !options.online ? ProgressStyle::kOff
                              : options.progress               ? ProgressStyle::kLines
                              : ::isatty(STDERR_FILENO) != 0   ? ProgressStyle::kBar
                                                               : ProgressStyle::kOff;
  std::optional<ProgressDisplay> display;
  if (style != ProgressStyle::kOff) display.emplace("plan", style, 1);
  const PlanResult result = Plan(options);
  FinishProgress();
  WriteRequests(result, out.Path("requests.csv"));
  WriteTextFile(out.Path("plan.json"), PlanJson(options, result));
  out.Commit();
  return Summary(options, result);
}

// plan.json's fields (as the summary above writes them), as dotted paths.
constexpr ColumnDoc kPlanFields[] = {
    {"rung", "", "the model planned with: paper or extended"},
    {"method", "", "model_based or optimal"},
    {"motor", "", "the servo type whose model it is"},
    {"tick_s", "s", "the model's tick, the requests' spacing"},
    {"ticks", "", "the desired motion's ticks"},
    {"beyond_servo_ticks", "",
     "the ticks where the model-based inversion cannot reach the desired angle"},
    {"predicted_mae_deg.planned", "deg",
     "the model's mean absolute error from the desired angles under the planned requests"},
    {"predicted_mae_deg.direct", "deg", "the same with the desired angles sent as they are"},
    {"predicted_rms_deg.planned", "deg",
     "the root mean square of the same errors: the optimal method's objective (its sum of "
     "squares) as an angle"},
    {"predicted_rms_deg.direct", "deg", "the same with the desired angles sent as they are"},
    {"limits.min_deg", "deg", "the least request"},
    {"limits.max_deg", "deg", "the greatest request"},
    {"limits.max_speed_deg_s", "deg/s", "the fastest change of the request"},
    {"drive.kp", "", "the extended rung's drive: the position gain"},
    {"drive.mass_kg", "kg", "the load's mass"},
    {"drive.length_m", "m", "the load's arm"},
    {"online.preview_ticks", "ticks", "with --online, the desired ticks each request saw ahead"},
    {"online.hold_ticks", "ticks", "with --online --method optimal, --hold-ticks"},
    {"online.handover_ticks", "ticks",
     "with --online --method optimal, --handover-ticks (-1: two horizons and the model's "
     "settling)"},
    {"online.budget_ms", "ms",
     "with --online --method optimal, --budget-ms (-1: half the model's tick; 0: none)"},
    {"online.iterations_per_tick", "", "with --online --method optimal, --iterations-per-tick"},
    {"model_file", "", "the --model file"},
    {"desired_file", "", "the --desired file"},
};

std::span<const OutputDoc> PlanOutputs() {
  static const OutputDoc outputs[] = {
      {"requests.csv", "The planned requests tick by tick, beside the desired motion.",
       kRequestsColumns},
      {"plan.json", "The plan's summary.", kPlanFields},
  };
  return outputs;
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
  CLI::Option* progress =
      app.add_flag("--progress", o.progress,
                   "with --online: plain progress lines on stderr (default: a bar on a terminal)");
  app.add_flag("--quiet", o.quiet, "no progress on stderr")->excludes(progress);
  AddListOutputsFlag(app, PlanOutputs());
  app.add_option("--preview-ticks", o.preview_ticks,
                 "with --online: desired angles ahead the planner is given (default: the "
                 "method's own)");
  app.add_option("--budget-ms", o.budget_ms,
                 "with --online --method optimal: wall-clock time a tick may iterate (ms; "
                 "default -1, half the model's tick; 0: the iteration cap alone, the same "
                 "requests on every machine)");
  app.add_option("--hold-ticks", o.hold_ticks,
                 "with --online --method optimal: ticks after the preview over which the last "
                 "desired angle is taken as held (default 0)");
  app.add_option("--handover-ticks", o.handover_ticks,
                 "with --online --method optimal: the preview's last ticks whose requests stay "
                 "model_based's (default -1: two horizons and the model's settling)");
  app.add_option("--iterations-per-tick", o.iterations_per_tick,
                 "with --online --method optimal: the most L-BFGS iterations a tick (default " +
                     std::to_string(kOptimalMaxIterations) + ")");
  RefuseEmptyValues(app);
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

}  // namespace leglab
