// leglab.run_track's C++ half (_run_track) and the context a Python controller is given: what
// `track` computes, with controllers written in Python run beside the registered modes under
// the same plant, seed and scoring (ExternalMode).
#include <pybind11/stl.h>

#include <array>
#include <csignal>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bindings.h"
#include "convert.h"
#include "leglab/app/output.h"
#include "leglab/app/parallel.h"
#include "leglab/app/progress.h"
#include "leglab/controller/controller.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/tables.h"
#include "leglab/experiments/track.h"
#include "leglab/experiments/writers.h"

namespace leglab::python {
namespace {

using experiments::ExperimentConfig;
using experiments::ExternalMode;
using experiments::ModeRun;
using experiments::TrackResult;
using leglab::ColumnTable;

// What a Python controller's reset(context) gets: the run's desired cycle, models and limits
// and the robot's forward kinematics (a copy of the C++ context).
struct PyControllerContext {
  ControllerContext context;
};

// A controller written in Python (leglab.Controller's protocol) as a JointController. Every call
// takes the GIL: the experiment runs with it released.
class PythonController final : public JointController {
 public:
  PythonController(py::object controller, std::string name, py::object context, bool has_observe,
                   bool has_end_of_step)
      : controller_(std::move(controller)),
        name_(std::move(name)),
        context_(std::move(context)),
        request_(controller_.attr("request")),
        has_observe_(has_observe),
        has_end_of_step_(has_end_of_step) {}

  ~PythonController() override {
    try {
      py::gil_scoped_acquire gil;
      request_ = py::object();
      context_ = py::object();
      controller_ = py::object();
    } catch (...) {
      // Without the GIL the references cannot be dropped safely: leak them instead.
      (void)request_.release();
      (void)context_.release();
      (void)controller_.release();
    }
  }
  PythonController(const PythonController&) = delete;
  PythonController& operator=(const PythonController&) = delete;

  void Reset() override {
    py::gil_scoped_acquire gil;
    controller_.attr("reset")(context_);
  }

  LegAngles Update(long tick, const LegAngles& measured_deg) override {
    py::gil_scoped_acquire gil;
    // Ctrl-C reaches a long run here, between two ticks.
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    const py::object request = request_(tick, ToArray(measured_deg));
    return ToLegAngles(request,
                       "controller '" + name_ + "': request(tick " + std::to_string(tick) + ")");
  }

  void Observe(long /*tick*/, const LegAngles& applied_deg,
               const LegAngles& measured_deg) override {
    if (!has_observe_) return;
    py::gil_scoped_acquire gil;
    // A controller sees what it may: the measured angles and the applied request, not the
    // true angles nor the stand's instruments (NaN).
    PlantReading reading;
    constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
    reading.measured_deg = measured_deg;
    reading.applied_deg = applied_deg;
    reading.true_deg = {kNan, kNan, kNan};
    reading.telemetry.contact_force_n = {kNan, kNan, kNan};
    reading.telemetry.carriage_z_mm = reading.telemetry.slip_mm = kNan;
    reading.telemetry.sled_x_mm = reading.telemetry.sled_y_mm = kNan;
    controller_.attr("observe")(ToArray(applied_deg), reading);
  }

  void EndOfStep(long step) override {
    if (!has_end_of_step_) return;
    py::gil_scoped_acquire gil;
    controller_.attr("end_of_step")(step);
  }

  std::string_view name() const override { return name_; }

 private:
  py::object controller_;
  std::string name_;
  py::object context_;
  py::object request_;
  bool has_observe_;
  bool has_end_of_step_;
};

// Whether `controller` overrides leglab.Controller's `method` (the base's do nothing: a run
// skips calling them).
bool Overrides(const py::object& controller, const char* method) {
  const py::object base = py::module_::import("leglab").attr("Controller");
  const py::object own = py::getattr(py::type::of(controller), method, py::none());
  return !own.is_none() && !own.is(py::getattr(base, method, py::none()));
}

std::vector<ExternalMode> ToExternalModes(py::handle controllers) {
  std::vector<ExternalMode> modes;
  for (const py::handle item : controllers) {
    const auto controller = py::reinterpret_borrow<py::object>(item);
    const py::object name = py::getattr(controller, "name", py::none());
    if (!py::isinstance<py::str>(name)) {
      ThrowValueError("controllers: " + std::string(py::repr(controller)) +
                      " has no `name` (str): subclass leglab.Controller and set name");
    }
    if (!py::hasattr(controller, "request") || !py::hasattr(controller, "reset")) {
      ThrowValueError("controller '" + name.cast<std::string>() +
                      "': has no request(tick, measured) or reset(context)");
    }
    const bool observe = Overrides(controller, "observe");
    const bool end_of_step = Overrides(controller, "end_of_step");
    std::string mode = name.cast<std::string>();
    modes.push_back({mode,
                     [controller, mode, observe, end_of_step](
                         const ControllerContext& context) -> std::unique_ptr<JointController> {
                       py::gil_scoped_acquire gil;
                       py::object py_context = py::cast(PyControllerContext{context});
                       return std::make_unique<PythonController>(
                           controller, mode, std::move(py_context), observe, end_of_step);
                     }});
  }
  return modes;
}

// A table's columns as numpy arrays (float64, int64, str), by column name.
py::dict ToColumns(const ColumnTable& table) {
  const py::module_ numpy = py::module_::import("numpy");
  py::dict columns;
  for (size_t c = 0; c < table.names.size(); ++c) {
    std::visit(
        [&](const auto& values) {
          using T = typename std::decay_t<decltype(values)>::value_type;
          if constexpr (std::is_same_v<T, double>) {
            columns[py::str(table.names[c])] = ToArray(values);
          } else if constexpr (std::is_same_v<T, long>) {
            py::array_t<long> array(static_cast<py::ssize_t>(values.size()));
            std::copy(values.begin(), values.end(), array.mutable_data());
            columns[py::str(table.names[c])] = array;
          } else {
            columns[py::str(table.names[c])] = numpy.attr("array")(py::cast(values));
          }
        },
        table.columns[c]);
  }
  return columns;
}

py::dict ModelsDict(const std::array<JointModelParams, kLegJoints>& models) {
  py::dict d;
  for (int j = 0; j < kLegJoints; ++j) d[py::str(std::string(kLegJointNames[j]))] = models[j];
  return d;
}

// While it lives, SIGINT, SIGTERM and SIGHUP only ask the run to stop (RequestStop): the run
// unwinds at its next step, and its OutputDir removes the staging folder and the lock, where
// SIGTERM's default action would have left both behind. Restore() brings back the previous
// actions; DeliverPending() then hands the signal that came to the process as it would have
// been: SIGTERM's default ends it (cleaned up), Python's SIGINT handler raises
// KeyboardInterrupt. A signal during or after the commit waits for it: the results are whole.
class StopOnSignals {
 public:
  StopOnSignals() {
    RequestStop(0);
    struct sigaction action {};
    action.sa_handler = [](int signal) { RequestStop(signal); };
    sigemptyset(&action.sa_mask);
    for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &action, &previous_[i]);
  }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;
  ~StopOnSignals() { Restore(); }

  void Restore() {
    if (restored_) return;
    for (size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &previous_[i], nullptr);
    restored_ = true;
  }

  // After Restore, with the GIL: delivers the pending signal, if any. Returns if none came, or
  // if a handler took it without raising; throws the exception a Python handler raised.
  static void DeliverPending() {
    const int signal = StopRequested();
    RequestStop(0);
    if (signal == 0) return;
    std::raise(signal);
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  }

 private:
  static constexpr std::array<int, 3> kSignals = {SIGINT, SIGTERM, SIGHUP};
  std::array<struct sigaction, 3> previous_{};
  bool restored_ = false;
};

// What `track` computes and, with `out`, writes, exactly as the program does.
py::dict RunTrack(py::handle config_path, py::handle overrides, py::handle controllers,
                  py::handle out, py::handle threads_value) {
  const auto threads = static_cast<int>(ToInteger(threads_value, "threads", kThreadsDoc));
  ExperimentConfig config =
      experiments::LoadExperimentConfig(ToPath(config_path, "config"), ToOverrides(overrides));
  config.threads = threads;
  const std::vector<ExternalMode> external = ToExternalModes(controllers);
  std::vector<std::string> external_names;
  external_names.reserve(external.size());
  for (const ExternalMode& mode : external) external_names.push_back(mode.name);
  std::optional<OutputDir> dir;
  if (!out.is_none()) {
    dir.emplace(ToPath(out, "out"), experiments::TrackOutputPrefixes(external_names));
  }

  struct ModeTables {
    std::string mode;
    ColumnTable trace{experiments::TraceColumns()};
    ColumnTable foot{experiments::FootColumns()};
  };
  std::vector<ModeTables> tables;
  std::optional<experiments::Table2> table;
  std::optional<TrackResult> result;
  std::string markdown;
  {
    py::gil_scoped_release release;
    result = experiments::RunTrackExperiment(
        config,
        [&](const TrackResult& r, ModeRun&& run) {
          if (!table) table = experiments::BeginTable2(r);
          experiments::AddModeToTable2(*table, run, r);
          ModeTables& t = tables.emplace_back();
          t.mode = std::string(experiments::ModeInfo(run).name);
          experiments::ModeTraceRows(run, r, t.trace, t.foot);
          if (dir) experiments::WriteModeOutputs(run, r, *dir);
        },
        external);
    if (!table) table = experiments::BeginTable2(*result);
    if (dir) {
      markdown = experiments::WriteTrackTables(*result, *table, config, *dir);
      experiments::WriteConfigFile("track", config, *dir);
      dir->Commit();
    } else {
      markdown = experiments::Table2Markdown(*table);
    }
  }
  py::dict d;
  d["table2"] = py::module_::import("json").attr("loads")(experiments::Table2Json(*table, config));
  py::dict traces, feet;
  for (const ModeTables& t : tables) {
    traces[py::str(t.mode)] = ToColumns(t.trace);
    feet[py::str(t.mode)] = ToColumns(t.foot);
  }
  d["traces"] = traces;
  d["feet"] = feet;
  d["models"] = ModelsDict(result->context.models);
  d["walk_models"] =
      result->walk_context ? py::object(ModelsDict(result->walk_context->models)) : py::none();
  d["models_identified"] = result->models_identified;
  d["markdown"] = markdown;
  d["config_yaml"] = config.merged_yaml;
  d["plant_ticks"] = result->plant_ticks;
  return d;
}

// RunTrack; with `out`, a signal stops the run and leaves nothing behind (StopOnSignals).
py::dict RunTrackStoppable(py::handle config_path, py::handle overrides, py::handle controllers,
                           py::handle out, py::handle threads) {
  if (out.is_none()) return RunTrack(config_path, overrides, controllers, out, threads);
  StopOnSignals stop;
  py::dict result;
  try {
    result = RunTrack(config_path, overrides, controllers, out, threads);
  } catch (const RunStopped& stopped) {
    // The OutputDir is gone: nothing of this run is on disk.
    stop.Restore();
    const int signal = stopped.signal();
    StopOnSignals::DeliverPending();
    throw std::runtime_error("run_track: stopped by signal " + std::to_string(signal) +
                             "; nothing written");
  }
  stop.Restore();
  StopOnSignals::DeliverPending();
  return result;
}

}  // namespace

// ControllerContext's docstring.
constexpr const char* kControllerContextDoc =
    R"doc(
What a controller is built from (given to Controller.reset): the desired cycle, the models the
experiment identified (or was given), the leg's limits and forward kinematics. Angles in
degrees; a tick's row is rotator, abductor, knee.
)doc";

// ControllerContext.foot_mm's docstring (numpydoc, as every public name's).
constexpr const char* kContextFootMmDoc =
    R"doc(foot_mm(q_deg) -> numpy.ndarray

Forward kinematics: the foot in the body frame.

Parameters
----------
q_deg : array_like
    3 joint angles, deg.

Returns
-------
numpy.ndarray
    The foot, mm, shape (3,).

Raises
------
TypeError
    `q_deg` not an array.
ValueError
    Not 3 angles, or an angle not finite.)doc";

void BindTrack(py::module_& m) {
  py::class_<PyControllerContext>(m, "ControllerContext", kControllerContextDoc)
      .def_property_readonly(
          "desired", [](const PyControllerContext& c) { return ToArray(c.context.desired); },
          "The desired cycle, deg, shape (T, 3): row t is tick t of every step.")
      .def_property_readonly(
          "period", [](const PyControllerContext& c) { return c.context.desired.size(); },
          "T: ticks per step.")
      .def_property_readonly(
          "desired_foot_mm",
          [](const PyControllerContext& c) {
            std::vector<LegAngles> feet;
            feet.reserve(c.context.desired.size());
            for (const LegAngles& q : c.context.desired) {
              const Eigen::Vector3d f = experiments::FootMm(*c.context.geometry, q);
              feet.push_back({f.x(), f.y(), f.z()});
            }
            return ToArray(feet);
          },
          "The desired foot path (forward kinematics of `desired`), body frame, mm, shape (T, "
          "3).")
      .def_property_readonly(
          "models",
          [](const PyControllerContext& c) {
            return py::make_tuple(c.context.models[0], c.context.models[1], c.context.models[2]);
          },
          "Each joint's JointModel (identified on the plant, or the config's model.*).")
      .def_property_readonly(
          "limits_deg",
          [](const PyControllerContext& c) { return ToLimitsArray(c.context.limits); },
          "Each joint's (lower, upper) limit, deg, shape (3, 2); requests are clamped into them.")
      .def_property_readonly(
          "warmup_steps", [](const PyControllerContext& c) { return c.context.warmup_steps; },
          "Steps run before the experiment measures (tick 0 is the first warm-up tick).")
      .def_property_readonly(
          "approximation",
          [](const PyControllerContext& c) {
            std::vector<LegAngles> rows(c.context.desired.size());
            for (int j = 0; j < kLegJoints; ++j) {
              const std::vector<double> p = c.context.Approximation(j).Sample();
              for (size_t t = 0; t < rows.size(); ++t) rows[t][j] = p[t];
            }
            return ToArray(rows);
          },
          "Each joint's piecewise-linear approximation P of the desired cycle (section 4.1), "
          "deg, shape (T, 3).")
      .def(
          "foot_mm",
          [](const PyControllerContext& c, py::handle q_deg) {
            const LegAngles q = ToLegAngles(q_deg, "q_deg");
            const Eigen::Vector3d f = experiments::FootMm(*c.context.geometry, q);
            return ToArray(LegAngles{f.x(), f.y(), f.z()});
          },
          py::arg("q_deg"), kContextFootMmDoc);
  m.def("_run_track", &RunTrackStoppable, py::arg("config"), py::arg("overrides"),
        py::arg("controllers"), py::arg("out"), py::arg("threads"),
        "_run_track(config, overrides, controllers, out, threads) -> dict\n\n"
        "run_track's C++ half: a dict of the result's parts (see leglab.run_track).");
}

}  // namespace leglab::python
