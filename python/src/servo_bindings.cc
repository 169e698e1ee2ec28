// leglab.servo's compiled part: servo logs, the log fit, fitted servo models, plans and the
// online planner, on numpy arrays. python/leglab/servo/__init__.py holds the Python classes
// around it.

#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "convert.h"
#include "leglab/app/parallel.h"
#include "leglab/experiments/config.h"
#include "leglab/model/joint_model.h"
#include "leglab/servo/log_fit.h"
#include "leglab/servo/plan_program.h"
#include "leglab/servo/servo_log_io.h"
#include "leglab/servo/servo_model.h"
#include "leglab/servo/servo_plan.h"
#include "leglab/servo/servo_plan_io.h"
#include "leglab/servo/servo_planner.h"

namespace leglab::python {
namespace {

using leglab::FittedModel;

// A log as the Python ServoLog holds it: a dict of its fields and arrays (the arrays under
// kServoLogColumns' names).
py::dict LogToDict(const ServoLog& log) {
  const size_t n = log.samples.size();
  DoubleArray time(static_cast<py::ssize_t>(n));
  DoubleArray request(static_cast<py::ssize_t>(n));
  DoubleArray measured(static_cast<py::ssize_t>(n));
  py::array_t<bool> torque(static_cast<py::ssize_t>(n));
  for (size_t i = 0; i < n; ++i) {
    time.mutable_at(i) = log.samples[i].time_s;
    request.mutable_at(i) = log.samples[i].request_deg;
    measured.mutable_at(i) = log.samples[i].measured_deg;
    torque.mutable_at(i) = log.samples[i].torque_enabled;
  }
  py::dict d;
  d["file"] = log.file;
  d["motor"] = log.motor;
  d["trajectory"] = log.trajectory;
  d["kp"] = log.kp;
  d["mass_kg"] = log.mass_kg;
  d["length_m"] = log.length_m;
  d[py::str(kServoLogColumns.time_s)] = time;
  d[py::str(kServoLogColumns.request_deg)] = request;
  d[py::str(kServoLogColumns.measured_deg)] = measured;
  d[py::str(kServoLogColumns.torque_enabled)] = torque;
  return d;
}

// The dict of a Python ServoLog (its arrays already float64 and bool of one length) as a log.
ServoLog DictToLog(const py::dict& d) {
  ServoLog log;
  log.file = d["file"].cast<std::string>();
  log.motor = d["motor"].cast<std::string>();
  log.trajectory = d["trajectory"].cast<std::string>();
  log.kp = d["kp"].cast<double>();
  log.mass_kg = d["mass_kg"].cast<double>();
  log.length_m = d["length_m"].cast<double>();
  const auto time = d[py::str(kServoLogColumns.time_s)].cast<DoubleArray>();
  const auto request = d[py::str(kServoLogColumns.request_deg)].cast<DoubleArray>();
  const auto measured = d[py::str(kServoLogColumns.measured_deg)].cast<DoubleArray>();
  const auto torque =
      d[py::str(kServoLogColumns.torque_enabled)].cast<py::array_t<bool, py::array::c_style>>();
  const auto n = static_cast<size_t>(time.size());
  if (static_cast<size_t>(request.size()) != n || static_cast<size_t>(measured.size()) != n ||
      static_cast<size_t>(torque.size()) != n) {
    ThrowValueError("servo log '" + log.file + "': " + std::string(kServoLogColumns.time_s) + ", " +
                    std::string(kServoLogColumns.request_deg) + ", " +
                    std::string(kServoLogColumns.measured_deg) + " and " +
                    std::string(kServoLogColumns.torque_enabled) + " differ in length");
  }
  log.samples.resize(n);
  for (size_t i = 0; i < n; ++i) {
    log.samples[i] = {time.at(i), request.at(i), measured.at(i), torque.at(i)};
  }
  return log;
}

py::dict CurvesToDict(const LogFitCurves& c) {
  py::dict d;
  d["name"] = c.name;
  d["file"] = c.file;
  d["motor"] = c.motor;
  d["tick_s"] = c.tick_s;
  py::array_t<bool> torque(static_cast<py::ssize_t>(c.torque_enabled.size()));
  for (size_t t = 0; t < c.torque_enabled.size(); ++t) {
    torque.mutable_at(t) = c.torque_enabled[t] != 0;
  }
  // The columns of log_<name>.csv, named as it names them: the log's, then <rung>_deg.
  const std::array<py::object, kServoLogColumnList.size()> log = {
      ToArray(c.time_s), ToArray(c.request_deg), ToArray(c.measured_deg), torque};
  for (size_t i = 0; i < log.size(); ++i) d[py::str(std::string(kServoLogColumnList[i]))] = log[i];
  for (size_t k = 0; k < c.rungs.size(); ++k)
    d[py::str(c.rungs[k] + "_deg")] = ToArray(c.predicted_deg[k]);
  return d;
}

// A recording as a rung's Python functions see it: its arrays and its drive.
py::dict RecordingToDict(const ServoRecording& r) {
  py::dict d;
  d[py::str(std::string(kServoLogColumns.request_deg))] = ToArray(r.request_deg);
  d[py::str(std::string(kServoLogColumns.measured_deg))] = ToArray(r.measured_deg);
  py::array_t<bool> driven(static_cast<py::ssize_t>(r.scored.size()));
  for (size_t t = 0; t < r.scored.size(); ++t) driven.mutable_at(t) = r.scored[t] != 0;
  d["driven"] = driven;
  d["kp"] = r.drive.kp;
  d["mass_kg"] = r.drive.mass_kg;
  d["length_m"] = r.drive.length_m;
  return d;
}

// A model rung given in Python: (name, label, description, column, fit, predict). Its
// functions are called on the fit's worker threads, each call holding the GIL; they are held
// through shared pointers, so that copies made without the GIL touch no reference count.
ModelRung ToModelRung(py::handle item) {
  const auto t = item.cast<py::tuple>();
  ModelRung m;
  m.rung = {.name = t[0].cast<std::string>(),
            .kind = RungKind::kModel,
            .label = t[1].cast<std::string>(),
            .description = t[2].cast<std::string>(),
            .column = t[3].cast<std::string>()};
  const auto fit = std::make_shared<py::function>(t[4].cast<py::function>());
  const auto predict = std::make_shared<py::function>(t[5].cast<py::function>());
  const std::string name = m.rung.name;
  m.fit = [fit, name](std::span<const ServoRecording> train, double tick_s) {
    const py::gil_scoped_acquire gil;
    py::list recordings;
    for (const ServoRecording& r : train) recordings.append(RecordingToDict(r));
    const py::object result = (*fit)(recordings, tick_s);
    if (!py::isinstance<py::dict>(result)) {
      ThrowTypeError("rung '" + name + "': fit returned " +
                     std::string(py::str(result.get_type().attr("__name__"))) +
                     ", expected a dict of parameters by name");
    }
    RungParameters parameters;
    for (const auto& [key, value] : result.cast<py::dict>()) {
      const std::string parameter = py::str(key);
      parameters[parameter] =
          ToReal(value, "rung '" + name + "': fit's parameter '" + parameter + "'");
    }
    return parameters;
  };
  m.predict = [predict, name](const RungParameters& parameters, const ServoRecording& r,
                              double tick_s) {
    const py::gil_scoped_acquire gil;
    py::dict p;
    for (const auto& [key, value] : parameters) p[py::str(key)] = value;
    return ToFiniteVector((*predict)(p, RecordingToDict(r), tick_s),
                          "rung '" + name + "': predict's angles");
  };
  return m;
}

py::dict Fit(py::handle config, py::handle overrides, const py::list& given,
             py::handle threads_value, const py::list& rungs) {
  const auto threads = static_cast<int>(ToInteger(threads_value, "threads", kThreadsDoc));
  LogFitConfig logs;
  if (config.is_none()) {
    logs = LogFitConfigFromOverrides(ToOverrides(overrides));
  } else {
    const std::string path = ToPath(config, "config");
    logs =
        experiments::LoadExperimentConfig(path, ToOverrides(overrides), experiments::kIdentifyScope)
            .logs;
    if (!logs.given) {
      ThrowValueError("config '" + path +
                      "': has no logs section (leglab.servo.fit fits servo logs; step tests "
                      "are leglab.identify)");
    }
  }
  std::vector<GivenServoLog> logs_given;
  for (const py::handle item : given) {
    const auto pair = item.cast<py::tuple>();
    logs_given.push_back({DictToLog(pair[0].cast<py::dict>()), pair[1].cast<bool>()});
  }
  if (threads < 0) ThrowValueError("threads: expected 0 (one per core) or more");
  std::vector<ModelRung> extra;
  for (const py::handle item : rungs) extra.push_back(ToModelRung(item));
  LogFitResult result;
  {
    py::gil_scoped_release release;
    result = FitServoLogs(logs, threads, logs_given, extra);
  }
  py::dict d;
  d["json"] = result.json;
  d["markdown"] = result.markdown;
  py::list curves;
  for (const LogFitCurves& c : result.curves) curves.append(CurvesToDict(c));
  d["curves"] = curves;
  return d;
}

std::string ModelRepr(const FittedModel& m) {
  return "ServoModel(rung='" + m.rung + "', motor='" + m.motor +
         "', tick_s=" + std::string(py::repr(py::float_(m.tick_s))) + ")";
}

py::dict ModelToDict(const FittedModel& m) {
  py::dict d;
  d["tick_s"] = m.tick_s;
  // The model's values under its keys' names (its VisitKeys), as log_fit.json holds them.
  if (m.rung == "paper") {
    AddKeyValues(d, KeyValues(m.paper, [](KeyVisitor& v, JointModelParams& p) {
                   VisitKeys(v, p, kAnyJointModel);
                 }));
    d["v_max_deg_s"] = m.top_speed_deg_s;
  } else {
    AddKeyValues(
        d, KeyValues(m.extended, [](KeyVisitor& v, ServoModelParams& p) { VisitKeys(v, p); }));
  }
  return d;
}

// kp, mass and length for a model: the extended rung needs kp; the paper's ignores them.
ServoDrive ToDrive(const FittedModel& m, py::handle kp_value, py::handle mass_value,
                   py::handle length_value) {
  const std::optional<double> kp = ToOptionalReal(kp_value, "kp");
  const double mass_kg = ToReal(mass_value, "mass_kg");
  const double length_m = ToReal(length_value, "length_m");
  if (m.rung == "extended" && !kp) {
    ThrowValueError("kp is required for the extended rung (the servo's gain register)");
  }
  const ServoDrive drive{kp.value_or(1.0), mass_kg, length_m};
  if (std::string problem = ServoDriveProblem(drive); !problem.empty()) ThrowValueError(problem);
  return drive;
}

PlanMethod ToMethod(const std::string& method) {
  if (method == "model_based") return PlanMethod::kModelBased;
  if (method == "optimal") return PlanMethod::kOptimal;
  ThrowValueError("method: expected 'model_based' or 'optimal', got '" + method + "'");
}

DoubleArray Simulate(const FittedModel& m, py::handle requests, py::handle start_value,
                     py::handle kp, py::handle mass_kg, py::handle length_m) {
  const ServoDrive drive = ToDrive(m, kp, mass_kg, length_m);
  const std::vector<double> r = ToFiniteVector(requests, "requests_deg");
  const std::optional<double> start_deg = ToOptionalReal(start_value, "start_deg");
  std::vector<double> angles(r.size());
  if (r.empty()) return ToArray(angles);
  const double start = start_deg.value_or(r[0]);
  {
    py::gil_scoped_release release;
    if (m.rung == "paper") {
      JointModelState state = RestState(m.paper, start);
      for (size_t t = 0; t < r.size(); ++t) angles[t] = StepJointModel(m.paper, state, r[t]);
    } else {
      ServoModelState state = ServoRestState(m.extended, start);
      for (size_t t = 0; t < r.size(); ++t) {
        angles[t] = StepServoModel(m.extended, drive, m.tick_s, state, r[t]);
      }
    }
  }
  return ToArray(angles);
}

py::dict Plan(const FittedModel& m, py::handle desired, const std::string& method, py::handle kp,
              py::handle mass_kg, py::handle length_m, py::handle min_value, py::handle max_value) {
  const ServoDrive drive = ToDrive(m, kp, mass_kg, length_m);
  const double min_deg = ToReal(min_value, "min_deg");
  const double max_deg = ToReal(max_value, "max_deg");
  std::vector<double> d = ToFiniteVector(desired, "desired_deg", 1);
  if (!(std::isfinite(min_deg) && std::isfinite(max_deg) && min_deg < max_deg)) {
    ThrowValueError("min_deg and max_deg: expected finite min_deg < max_deg");
  }
  if (d[0] < min_deg || d[0] > max_deg) {
    ThrowValueError("desired_deg: its first angle " + std::string(py::repr(py::float_(d[0]))) +
                    " deg is outside min_deg/max_deg");
  }
  const PlanMethod how = ToMethod(method);
  PlanResult r;
  {
    py::gil_scoped_release release;
    r = PlanDesired(m, drive, std::move(d), min_deg, max_deg, how);
  }
  DoubleArray time(static_cast<py::ssize_t>(r.desired.size()));
  py::array_t<uint8_t> beyond(static_cast<py::ssize_t>(r.desired.size()));
  for (size_t t = 0; t < r.desired.size(); ++t) {
    time.mutable_at(t) = static_cast<double>(t) * m.tick_s;
    beyond.mutable_at(t) = r.plan.beyond_servo[t];
  }
  // The columns of plan's requests.csv, named as declared (kRequestsColumns), and direct_deg.
  const std::array<py::object, kRequestsColumns.size()> columns = {
      time, ToArray(r.desired), ToArray(r.plan.request_deg), ToArray(r.plan.predicted_deg), beyond};
  py::dict out;
  for (size_t i = 0; i < columns.size(); ++i) {
    out[py::str(std::string(kRequestsColumns[i].name))] = columns[i];
  }
  out["direct_deg"] = ToArray(r.direct);
  return out;
}

ServoPlanner MakePlanner(const FittedModel& m, const std::string& method, py::handle kp,
                         py::handle mass_kg, py::handle length_m, py::handle preview,
                         py::handle min_value, py::handle max_value, py::handle reanchor,
                         py::handle iterations, py::handle budget, py::handle hold,
                         py::handle handover) {
  const ServoDrive drive = ToDrive(m, kp, mass_kg, length_m);
  ServoPlannerOptions options;
  options.method = ToMethod(method);
  // The planner's own checks (ServoPlannerOptions) bound these further, naming them.
  // None: the method's own (-1); else the declared range from 0 (kServoPreviewDoc).
  options.preview_ticks =
      preview.is_none()
          ? -1
          : static_cast<int>(ToInteger(preview, "preview_ticks",
                                       WithRange(kServoPreviewDoc, 0, kServoPreviewDoc.max)));
  // Any number here: the planner checks it against its declaration ((0, inf]; inf: never).
  options.reanchor_deg = ToReal(reanchor, "reanchor_deg", /*finite=*/false);
  options.optimal_iterations_per_tick =
      static_cast<int>(ToInteger(iterations, "optimal_iterations_per_tick", kServoIterationsDoc));
  // None: half the model's tick (-1); the planner checks a number against its declaration.
  options.budget_s = budget.is_none() ? -1.0 : ToReal(budget, "budget_s");
  options.hold_ticks = static_cast<int>(ToInteger(hold, "hold_ticks", kServoHoldDoc));
  // None: the model's own (-1).
  options.handover_ticks =
      handover.is_none()
          ? -1
          : static_cast<int>(ToInteger(handover, "handover_ticks",
                                       WithRange(kServoHandoverDoc, 0, kServoHandoverDoc.max)));
  const ServoLimits limits{ToReal(min_value, "min_deg"), ToReal(max_value, "max_deg"),
                           m.top_speed_deg_s};
  if (m.rung == "paper") return {m.paper, m.tick_s, limits, options};
  return {m.extended, drive, m.tick_s, limits, options};
}

// window_deg as a span: a float64 array as it is (no copy, the fast path of a loop), anything
// else through numpy's checks into `storage`.
std::span<const double> Window(py::handle window, std::optional<DoubleArray>& storage) {
  if (DoubleArray::check_(window)) {
    const auto array = py::reinterpret_borrow<DoubleArray>(window);
    if (array.ndim() == 1) return {array.data(), static_cast<size_t>(array.size())};
  }
  storage = RealArray(window, "window_deg");
  if (storage->ndim() != 1) ThrowValueError("window_deg: expected a 1-D array of desired angles");
  return {storage->data(), static_cast<size_t>(storage->size())};
}

double Request(ServoPlanner& planner, py::handle window, py::handle measured_value) {
  const double measured = ToReal(measured_value, kServoLogColumns.measured_deg, false);
  std::optional<DoubleArray> storage;
  return planner.Request(Window(window, storage), measured);
}

void Hold(ServoPlanner& planner, py::handle window) {
  std::optional<DoubleArray> storage;
  planner.Hold(Window(window, storage));
}

// The log's functions: reading, checking and writing a log as the dict ServoLog holds.
void BindLogs(py::module_& m) {
  m.def(
      "_read_log",
      [](py::handle path, const std::string& format, const std::string& motor, double kp,
         double mass_kg, double length_m) {
        ServoLogFormat f = ServoLogFormat::kAuto;
        if (format == "csv") {
          f = ServoLogFormat::kCsv;
        } else if (format == "bam_json") {
          f = ServoLogFormat::kBamJson;
        } else if (format != "auto") {
          ThrowValueError("format: expected 'auto', 'csv' or 'bam_json', got '" + format + "'");
        }
        const std::string file = ToPath(path, "path");
        ServoLog log;
        {
          py::gil_scoped_release release;
          log = ReadServoLog(file, f, {motor, kp, mass_kg, length_m});
        }
        return LogToDict(log);
      },
      "_read_log(path, format, motor, kp, mass_kg, length_m): the log's fields as a dict");
  m.def(
      "_read_desired",
      [](py::handle path, double tick_s) {
        const std::string file = ToPath(path, "desired");
        std::vector<double> desired;
        {
          py::gil_scoped_release release;
          desired = ResampleDesired(ReadDesiredMotion(file), tick_s, file);
        }
        return DoubleArray(static_cast<py::ssize_t>(desired.size()), desired.data());
      },
      "_read_desired(path, tick_s): plan's --desired, read and put on ticks of tick_s (deg)");
  m.def(
      "_drive_problem",
      [](double kp, double mass_kg, double length_m) {
        return ServoDriveProblem({kp, mass_kg, length_m});
      },
      "_drive_problem(kp, mass_kg, length_m): '' when the drive keeps its declaration (a "
      "ServoDrive's ranges), else what is wrong, naming the field");
  m.def(
      "_log_columns",
      [] {
        py::tuple names(kServoLogColumnList.size());
        for (size_t c = 0; c < kServoLogColumnList.size(); ++c)
          names[c] = py::str(kServoLogColumnList[c]);
        return names;
      },
      "_log_columns() -> the names of a servo log's arrays, in the CSV log's order");
  m.def(
      "_check_log", [](const py::dict& d) { CheckServoLog(DictToLog(d)); },
      "_check_log(fields): ValueError unless the log is one identify accepts");
  m.def(
      "_log_csv_text", [](const py::dict& d) { return ServoLogCsvText(DictToLog(d)); },
      "_log_csv_text(fields): the log in leglab's CSV form");
}

}  // namespace

// ServoModel's docstring (numpydoc, as every public name's).
constexpr const char* kServoModelDoc =
    R"doc(
A servo model fitted to logs: one rung (extended or paper) of one motor, on its tick.

Get one from a LogFit: fit.model("xl330") or LogFit.load(path).model("xl330", rung="paper").
The extended model takes the servo's gain register kp and its load (mass_kg on an arm of
length_m, 0 hanging straight down); the paper's model ignores them.
)doc";

// ServoModel.to_dict's docstring.
constexpr const char* kServoToDictDoc =
    "to_dict() -> dict: the model as log_fit.json's models.<rung>.<motor> holds it.\n\n"
    "Returns\n-------\ndict\n    Its fields, under log_fit.json's names.";

// ServoModel.simulate's docstring.
constexpr const char* kServoSimulateDoc =
    R"doc(simulate(requests_deg, *, start_deg=None, kp=None, mass_kg=0.0, length_m=0.0) -> ndarray

The angles the model predicts with the requests sent as they are. A plan's predicted_deg is
simulate(request_deg, start_deg=desired_deg[0], ...).

Parameters
----------
requests_deg : array_like
    One request a tick, deg, 1-D, finite.
start_deg : float, optional
    The angle at rest before the first tick (None: the first request).
kp : float, optional
    The servo's gain register (required for the extended rung).
mass_kg, length_m : float, optional
    The servo's load.

Returns
-------
numpy.ndarray
    One angle a tick, deg.

Raises
------
TypeError
    An argument of the wrong type.
ValueError
    A value out of range or not finite; no kp for the extended rung.
MemoryError
    Naming `requests_deg`.)doc";

// ServoPlanner's docstring.
constexpr const char* kServoPlannerDoc =
    R"doc(
ServoPlanner(model, method="model_based", *, kp=None, mass_kg=0.0, length_m=0.0,
             preview_ticks=None, min_deg=-180.0, max_deg=180.0, reanchor_deg=2.0,
             optimal_iterations_per_tick=200, budget_s=None, hold_ticks=0,
             handover_ticks=None)

Requests for a servo one tick at a time (leglab.servo.plan, online). Each tick call
request(window_deg, measured_deg) with the desired angles from this tick on (as many as you
know, up to preview_ticks + 1; the last one is held beyond them) and the angle just measured;
send what it returns. model_based given horizon_ticks + 1 desired angles, and as measured what
the plan predicts, returns plan()'s requests bit for bit. A measured angle more than
reanchor_deg off the model's prediction moves the planner's model there (inf: never; see
docs/real-servos.md, "Online"). optimal is a receding horizon of preview_ticks ticks (and
hold_ticks after them with the last desired angle held), from model_based's plan by projected
L-BFGS; once that descent stalls, the rest of the tick goes to a second one, started from
model_based's plan and carried across ticks until it stalls, which takes over when lower: at
most optimal_iterations_per_tick iterations in all, and none that starts budget_s seconds after
request() was called (None: half the model's tick, which it spends on most ticks, so that
planners sharing a tick need a share each; 0: the cap alone, the same requests on every
machine). The requests acting on the preview's last handover_ticks ticks stay
model_based's (None: two horizons and the model's settling), so that the planner never spends
a request whose consequences it cannot see. Requests stay within [min_deg, max_deg] and change
at most at the model's top speed.

Parameters
----------
model : ServoModel
    The servo's fitted model (LogFit.model).
method : {"model_based", "optimal"}, optional
    How requests are planned.
kp : float, optional
    The servo's gain register (required for the extended rung).
mass_kg, length_m : float, optional
    The servo's load.
preview_ticks : int, optional
    Desired angles after this tick's that request() uses (None: the method's own).
min_deg, max_deg : float, optional
    The requests' bounds.
reanchor_deg : float, optional
    A measured angle this far off the prediction moves the model there (inf: never).
optimal_iterations_per_tick : int, optional
    optimal's iteration cap a tick, both descents together.
budget_s : float, optional
    optimal's time a tick, s (None: half the model's tick; 0: the cap alone).
hold_ticks : int, optional
    optimal: ticks after the preview with the last desired angle held.
handover_ticks : int, optional
    The preview's last ticks whose requests stay model_based's (None: the model's own).

Raises
------
TypeError
    An unknown keyword, an argument of the wrong type.
ValueError
    A value out of its declared range, an unknown method, a model the planner refuses.
)doc";

// ServoPlanner.reset's docstring.
constexpr const char* kPlannerResetDoc =
    "reset(angle_deg): the servo at rest there; the next request is tick 0.\n\n"
    "Parameters\n----------\nangle_deg : float\n    The angle, deg, finite.\n\n"
    "Raises\n------\nTypeError\n    `angle_deg` not a number.\nValueError\n    "
    "`angle_deg` out of range or not finite; the planner is left as it was.";

// ServoPlanner.request's docstring.
constexpr const char* kRequestDoc =
    R"doc(request(window_deg, measured_deg) -> float

The request R(t) of this tick.

Parameters
----------
window_deg : array_like
    D(t), D(t+1), ...: the desired angles from this tick on, deg (at least one, finite).
measured_deg : float
    M(t), the angle just measured, deg.

Returns
-------
float
    R(t), deg: send it.

Raises
------
TypeError
    `window_deg` not an array, `measured_deg` not a number.
ValueError
    An empty or non-finite window, a measured angle out of range or not finite; the planner is
    left as it was.)doc";

// ServoPlanner.hold's docstring.
constexpr const char* kHoldDoc =
    R"doc(hold(window_deg) -> None

A tick that passed with no request sent (the loop woke too late): the servo kept the last
request, and the planner's model is advanced by that tick as the servo was. The next request
is the next tick's.

Parameters
----------
window_deg : array_like
    As request()'s.

Raises
------
TypeError
    `window_deg` not an array.
ValueError
    An empty or non-finite window; the planner is left as it was.)doc";

void BindServo(py::module_& m) {
  BindLogs(m);
  m.def("_fit", &Fit, py::arg("config"), py::arg("overrides"), py::arg("given"), py::arg("threads"),
        py::arg("rungs") = py::list(),
        "_fit(config, overrides, given, threads, rungs=[]): identify's log fit, with rungs "
        "(name, label, description, column, fit, predict) added to the ladder's");
  m.def(
      "_model_from_json",
      [](const std::string& text, const std::string& rung, const std::string& motor,
         const std::string& source) {
        if (rung != "paper" && rung != "extended") {
          ThrowValueError("rung: expected 'extended' or 'paper', got '" + rung + "'");
        }
        return ParseFittedModel(text, rung, motor, source);
      },
      "_model_from_json(text, rung, motor, source)");

  py::class_<FittedModel>(m, "ServoModel", kServoModelDoc)
      .def_readonly("rung", &FittedModel::rung, "'extended' or 'paper'.")
      .def_readonly("motor", &FittedModel::motor, "The servo type, e.g. 'xl330'.")
      .def_readonly("tick_s", &FittedModel::tick_s, "The tick the model was fitted on, s.")
      .def_readonly("top_speed_deg_s", &FittedModel::top_speed_deg_s,
                    "The model's top speed (deg/s): a plan's requests change no faster.")
      .def_property_readonly(
          kJointModelNames.lag_ticks.data(),
          [](const FittedModel& f) {
            return f.rung == "paper" ? f.paper.lag_ticks : f.extended.lag_ticks;
          },
          "l: ticks before a request starts to act.")
      .def("to_dict", &ModelToDict, kServoToDictDoc)
      .def("simulate", &Simulate, py::arg("requests_deg"), py::kw_only(),
           py::arg("start_deg") = py::none(), py::arg("kp") = py::none(), py::arg("mass_kg") = 0.0,
           py::arg("length_m") = 0.0, kServoSimulateDoc)
      .def("__repr__", &ModelRepr);

  m.def("_plan", &Plan, py::arg("model"), py::arg("desired_deg"), py::arg("method"), py::arg("kp"),
        py::arg("mass_kg"), py::arg("length_m"), py::arg("min_deg"), py::arg("max_deg"),
        "_plan(model, desired_deg, method, kp, mass_kg, length_m, ...)");

  py::class_<ServoPlanner>(m, "ServoPlanner", kServoPlannerDoc)
      .def(py::init(&MakePlanner), py::arg("model"), py::arg("method") = "model_based",
           py::kw_only(), py::arg("kp") = py::none(), py::arg("mass_kg") = 0.0,
           py::arg("length_m") = 0.0, py::arg("preview_ticks") = py::none(),
           py::arg("min_deg") = -180.0, py::arg("max_deg") = 180.0, py::arg("reanchor_deg") = 2.0,
           py::arg("optimal_iterations_per_tick") = kOptimalMaxIterations,
           py::arg("budget_s") = py::none(), py::arg("hold_ticks") = 0,
           py::arg("handover_ticks") = py::none())
      .def_property_readonly("horizon_ticks", &ServoPlanner::HorizonTicks,
                             "l + 1: the desired angles after this tick's a request depends on.")
      .def_property_readonly("preview_ticks", &ServoPlanner::PreviewTicks,
                             "The desired angles after this tick's that request() uses.")
      .def("reset", &ServoPlanner::Reset, py::arg("angle_deg"), kPlannerResetDoc)
      .def("request", &Request, py::arg("window_deg"),
           py::arg(kServoLogColumns.measured_deg.data()),  // a literal's view: NUL-terminated
           kRequestDoc)
      .def("hold", &Hold, py::arg("window_deg"), kHoldDoc)
      .def_property_readonly("predicted_deg", &ServoPlanner::PredictedDeg,
                             "What the model predicted for the last measured angle.")
      .def_property_readonly("expected_deg", &ServoPlanner::ExpectedDeg,
                             "What the model predicts the next measured angle to be (after "
                             "reset, tick 0's): a servo that is the model measures it.")
      .def_property_readonly("reanchored", &ServoPlanner::Reanchored,
                             "Whether the last measured angle moved the model.")
      .def_property_readonly("ticks", &ServoPlanner::Ticks,
                             "Ticks since the last reset: requests and holds.");
}

}  // namespace leglab::python
