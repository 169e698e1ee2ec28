// leglab.JointModel, leglab.identify and leglab.floor: the paper's joint model (eq. 3), its
// identification and the floor of a desired cycle, on numpy arrays.
#include <pybind11/stl.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "convert.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/model/floor.h"
#include "leglab/model/identification.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/paper.h"

namespace leglab::python {
namespace {

std::string ModelRepr(const JointModelParams& p) {
  return "JointModel(v_max_deg_per_tick=" +
         std::string(py::repr(py::float_(p.v_max_deg_per_tick))) +
         ", theta0_deg=" + std::string(py::repr(py::float_(p.theta0_deg))) +
         ", lag_ticks=" + std::to_string(p.lag_ticks) +
         ", accel_ticks=" + std::to_string(p.accel_ticks) + ")";
}

// The longest cycle identify averages (period_ticks): 8000 s of 8 ms ticks.
constexpr KeyDoc kPeriodDoc = WithRange(kCyclePeriodDoc, 1, 1'000'000);

// `params` if the model's declaration (VisitKeys, the config's) allows it; std::invalid_argument
// (ValueError) naming the field otherwise.
JointModelParams CheckedModel(JointModelParams params) {
  CheckKeys("", params, [](KeyVisitor& v, JointModelParams& p) { VisitKeys(v, p); });
  return params;
}

// `value` as an integer in the range `doc` declares.
int ToInt(py::handle value, std::string_view what, const KeyDoc& doc) {
  return static_cast<int>(ToInteger(value, what, doc));
}

JointModelParams MakeModel(py::handle v_max_deg_per_tick, py::handle theta0_deg,
                           py::handle lag_ticks, py::handle accel_ticks) {
  const JointModelNames& names = kJointModelNames;
  return CheckedModel({ToReal(v_max_deg_per_tick, names.v_max_deg_per_tick),
                       ToReal(theta0_deg, names.theta0_deg),
                       ToInt(lag_ticks, names.lag_ticks, kJointModelKeys.lag_ticks),
                       ToInt(accel_ticks, names.accel_ticks, kJointModelKeys.accel_ticks)});
}

// `model` as a JointModel; TypeError naming `what` for anything else.
JointModelParams ToModel(py::handle model, const std::string& what) {
  if (!py::isinstance<JointModelParams>(model)) {
    ThrowTypeError(what + ": expected a JointModel, got " +
                   std::string(py::str(py::type::of(model).attr("__name__"))));
  }
  return model.cast<JointModelParams>();
}

// The recordings `identify` is given: one (two 1-D arrays) or several (two lists of them).
std::vector<JointRecording> ToRecordings(py::handle requests, py::handle measured) {
  const bool several =
      (py::isinstance<py::list>(requests) || py::isinstance<py::tuple>(requests)) &&
      py::len(requests) > 0 &&
      py::module_::import("numpy").attr("ndim")(requests[py::int_(0)]).cast<int>() == 1;
  std::vector<JointRecording> recordings;
  if (!several) {
    recordings.push_back(
        {ToFiniteVector(requests, "requests"), ToFiniteVector(measured, "measured"), 1.0});
  } else {
    if (!(py::isinstance<py::list>(measured) || py::isinstance<py::tuple>(measured)) ||
        py::len(measured) != py::len(requests)) {
      ThrowValueError("measured: expected as many recordings as requests (" +
                      std::to_string(py::len(requests)) + ")");
    }
    for (size_t i = 0; i < py::len(requests); ++i) {
      const std::string index = "[" + std::to_string(i) + "]";
      recordings.push_back({ToFiniteVector(requests[py::int_(i)], "requests" + index),
                            ToFiniteVector(measured[py::int_(i)], "measured" + index), 1.0});
    }
  }
  for (size_t i = 0; i < recordings.size(); ++i) {
    if (recordings[i].request_deg.size() != recordings[i].measured_deg.size()) {
      ThrowValueError("recording " + std::to_string(i) + ": " +
                      std::to_string(recordings[i].request_deg.size()) + " requests but " +
                      std::to_string(recordings[i].measured_deg.size()) + " measured angles");
    }
  }
  return recordings;
}

// A (min, max) pair of ticks with min <= max, each in `doc`'s range (a model's l or a).
std::pair<int, int> ToRange(py::handle range, const std::string& what, const KeyDoc& doc) {
  if (!(py::isinstance<py::tuple>(range) || py::isinstance<py::list>(range))) {
    ThrowTypeError(what + ": expected (min, max), a tuple of two integers, got " +
                   std::string(py::str(py::type::of(range).attr("__name__"))));
  }
  if (py::len(range) != 2) {
    ThrowValueError(what + ": expected (min, max), a tuple of two integers, got " +
                    std::to_string(py::len(range)) + " values");
  }
  const int low = ToInt(range[py::int_(0)], what + "[0]", doc);
  const int high = ToInt(range[py::int_(1)], what + "[1]", doc);
  if (high < low) {
    ThrowValueError(what + ": expected (min, max) with min <= max, got (" + std::to_string(low) +
                    ", " + std::to_string(high) + ")");
  }
  return {low, high};
}

IdentificationResult Identify(py::handle requests, py::handle measured, py::handle lag_range,
                              py::handle accel_range, py::handle period) {
  const std::optional<int> period_ticks =
      period.is_none()
          ? std::nullopt
          : std::optional<int>(static_cast<int>(ToInteger(period, "period_ticks", kPeriodDoc)));
  const std::vector<JointRecording> recordings = ToRecordings(requests, measured);
  experiments::IdentifyConfig identify;
  std::tie(identify.search.lag_min_ticks, identify.search.lag_max_ticks) =
      ToRange(lag_range, "lag_range_ticks", kJointModelKeys.lag_ticks);
  std::tie(identify.search.accel_min_ticks, identify.search.accel_max_ticks) =
      ToRange(accel_range, "accel_range_ticks", kJointModelKeys.accel_ticks);
  identify.average_cycles = period_ticks.has_value();
  if (period_ticks) {
    identify.t_step_ticks = *period_ticks;
  }
  IdentificationResult result;
  {
    py::gil_scoped_release release;
    result = experiments::FitStepTests(recordings, identify);
  }
  // A fit outside the model's ranges (recordings in units far from degrees) is an error, not
  // a model the constructor would refuse.
  try {
    CheckedModel(result.params);
  } catch (const std::invalid_argument& e) {
    ThrowValueError(std::string("identify: the fitted model is outside the model's ranges (") +
                    e.what() + "); are the recordings in degrees?");
  }
  return result;
}

// PAPER_TABLE2 and PAPER_FOOT_CM: the paper's Table 2 and foot table, keyed as table2.json
// keys them (paper::kTable2, kFootCm).
void BindPaperTables(py::module_& m) {
  py::dict table2;
  for (const paper::Table2Row& row : paper::kTable2) {
    table2[py::str(std::string(row.key))] =
        py::make_tuple(row.mean_deg[0], row.mean_deg[1], row.mean_deg[2]);
  }
  m.attr("PAPER_TABLE2") = table2;
  py::dict foot;
  for (const paper::FootRow& row : paper::kFootCm) {
    py::dict norms;
    for (const auto& [name, value] : {std::pair{"L2", row.l2_cm}, std::pair{"Linf", row.linf_cm}}) {
      py::dict mean_std;
      mean_std["mean"] = value.mean;
      mean_std["std"] = value.std;
      norms[name] = mean_std;
    }
    foot[py::str(std::string(row.mode))] = norms;
  }
  m.attr("PAPER_FOOT_CM") = foot;
}

// JointModel's docstring (numpydoc, as every public name's).
constexpr const char* kJointModelDoc =
    R"doc(
The paper's model of one joint (eq. 3), in its own units: degrees and 8 ms ticks.

    M(t) = M(t-1) + (1/a) * sum_{i=l+1}^{l+a} f(R(t-i) - M(t-1))

where f (eq. 2) is linear with slope v_max / theta_0 inside (-theta_0, theta_0) and saturates
at +-v_max outside. The paper's Table 1 is leglab.PAPER_MODEL.

Parameters
----------
v_max_deg_per_tick : float
    Top speed v_max, deg per 8 ms tick (> 0).
theta0_deg : float
    The request-actual difference that gives top speed, deg (> 0).
lag_ticks : int
    l, ticks before a request starts to act (>= 0).
accel_ticks : int
    a, ticks over which the speed is averaged (>= 1).

Raises
------
TypeError
    A value that is not a number (bool is not; l and a must be integers).
ValueError
    Naming the field, for one outside its range, the config's model.* ranges: v_max in
    [0.01, 45], theta_0 in [0.01, 180], l in [0, 50], a in [1, 50].
)doc";

// JointModel.simulate's docstring.
constexpr const char* kSimulateDoc =
    R"doc(simulate(requests, start_deg) -> numpy.ndarray

The model's angles under requests, from rest.

Parameters
----------
requests : array_like
    R(0..N-1), 1-D, deg, finite.
start_deg : float
    The angle at rest, deg: M(-1) and every remembered request equal it.

Returns
-------
numpy.ndarray
    M(0..N-1), deg.

Raises
------
TypeError
    `requests` not an array, `start_deg` not a number.
ValueError
    `requests` not 1-D or not finite, `start_deg` not finite.
MemoryError
    Naming `requests`.)doc";

// JointModel.steady_state's docstring.
constexpr const char* kSteadyStateDoc =
    R"doc(steady_state(cycle) -> numpy.ndarray

The cyclic steady state of eq. 3 under a request cycle repeated for ever.

Parameters
----------
cycle : array_like
    R(0..T-1), 1-D, deg, finite, at least one.

Returns
-------
numpy.ndarray
    The angles M(0..T-1) of one cycle, deg.

Raises
------
TypeError
    `cycle` not an array.
ValueError
    `cycle` empty, not 1-D or not finite; a model that never settles (v_max >= 2 theta_0 can
    swing about a request for ever).)doc";

// JointModel.speed_response's docstring.
constexpr const char* kSpeedResponseDoc =
    "speed_response(x_deg) -> float\n\n"
    "f of eq. 2: the speed for a request-actual difference.\n\n"
    "Parameters\n----------\nx_deg : float\n    The difference, deg, finite.\n\n"
    "Returns\n-------\nfloat\n    The speed, deg/tick.\n\n"
    "Raises\n------\nTypeError\n    `x_deg` not a number.\n"
    "ValueError\n    `x_deg` not finite.";

// JointModel.to_dict's docstring.
constexpr const char* kToDictDoc =
    "to_dict() -> dict\n\n"
    "The four parameters as a dict.\n\n"
    "Returns\n-------\ndict\n    Under the keys of table1.json's joints.";

// JointModel and PAPER_MODEL.
using JointModelClass = py::class_<JointModelParams>;

// JointModel's runs of eq. 3: simulate, steady_state, speed_response.
void DefJointModelRuns(JointModelClass& c) {
  c.def(
       "simulate",
       [](const JointModelParams& p, py::handle requests, py::handle start) {
         const std::vector<double> r = ToFiniteVector(requests, "requests");
         const double start_deg = ToReal(start, "start_deg");
         py::gil_scoped_release release;
         std::vector<double> angles = SimulateJointModel(p, r, RestState(p, start_deg));
         py::gil_scoped_acquire acquire;
         return ToArray(angles);
       },
       py::arg("requests"), py::arg("start_deg"), kSimulateDoc)
      .def(
          "steady_state",
          [](const JointModelParams& p, py::handle cycle) {
            const std::vector<double> r = ToFiniteVector(cycle, "cycle", 1);
            std::vector<double> angles;
            {
              py::gil_scoped_release release;
              try {
                angles = CyclicSteadyState(p, r);
              } catch (const std::runtime_error& e) {
                // A model that swings for ever (v_max >= 2 theta_0): the caller's model.
                throw std::invalid_argument(std::string("steady_state: ") + e.what());
              }
            }
            return ToArray(angles);
          },
          py::arg("cycle"), kSteadyStateDoc)
      .def(
          "speed_response",
          [](const JointModelParams& p, py::handle x) {
            return SpeedResponse(p, ToReal(x, "x_deg"));
          },
          py::arg("x_deg"), kSpeedResponseDoc);
}

void BindJointModel(py::module_& m) {
  JointModelClass c(m, "JointModel", kJointModelDoc);
  c  // The names are views of literals, so NUL-terminated.
      .def(py::init(&MakeModel), py::arg(kJointModelNames.v_max_deg_per_tick.data()),
           py::arg(kJointModelNames.theta0_deg.data()), py::arg(kJointModelNames.lag_ticks.data()),
           py::arg(kJointModelNames.accel_ticks.data()),
           "JointModel(v_max_deg_per_tick, theta0_deg, lag_ticks, accel_ticks)")
      .def_readonly(kJointModelNames.v_max_deg_per_tick.data(),
                    &JointModelParams::v_max_deg_per_tick, "Top speed v_max, deg per tick.")
      .def_readonly(kJointModelNames.theta0_deg.data(), &JointModelParams::theta0_deg,
                    "Request-actual difference that gives top speed, deg.")
      .def_readonly(kJointModelNames.lag_ticks.data(), &JointModelParams::lag_ticks,
                    "l: ticks before a request starts to act.")
      .def_readonly(kJointModelNames.accel_ticks.data(), &JointModelParams::accel_ticks,
                    "a: ticks over which the speed is averaged.");
  DefJointModelRuns(c);
  c.def_property_readonly("settles_on_every_cycle", &SettlesOnEveryCycle,
                          "Whether eq. 3 settles under every request cycle (v_max < 2 theta_0).")
      .def(
          "to_dict",
          [](const JointModelParams& p) {
            py::dict d;
            AddKeyValues(d, KeyValues(p, [](KeyVisitor& v, JointModelParams& model) {
                           VisitKeys(v, model, kAnyJointModel);
                         }));
            return d;
          },
          kToDictDoc)
      .def("__repr__", &ModelRepr)
      // An operator: another type compares unequal (NotImplemented), as Python's own do.
      .def(
          "__eq__",
          [](const JointModelParams& a, const JointModelParams& b) {
            return a.v_max_deg_per_tick == b.v_max_deg_per_tick && a.theta0_deg == b.theta0_deg &&
                   a.lag_ticks == b.lag_ticks && a.accel_ticks == b.accel_ticks;
          },
          py::is_operator())
      .def(py::pickle(
          [](const JointModelParams& p) {
            return py::make_tuple(p.v_max_deg_per_tick, p.theta0_deg, p.lag_ticks, p.accel_ticks);
          },
          [](const py::tuple& t) {
            if (t.size() != 4) ThrowValueError("JointModel: a pickled model holds 4 values");
            return MakeModel(t[0], t[1], t[2], t[3]);
          }));

  m.attr("PAPER_MODEL") = paper::kTable1;
}

}  // namespace

// floor's docstring.
constexpr const char* kFloorDoc =
    R"doc(floor(desired_cycle, model) -> numpy.ndarray

The floor of a desired cycle: the cyclic trajectory nearest it (least squares) that a
joint with the model's top speed v_max and acceleration time a can follow at all. No request
policy brings a joint of that model closer to the desired cycle.

Parameters
----------
desired_cycle : array_like
    One cycle, deg: shape (T,) with one JointModel, or (T, 3) with a sequence of three
    (rotator, abductor, knee). T >= 3.
model : JointModel or sequence of JointModel
    A JointModel, or three.

Returns
-------
numpy.ndarray
    The floor, shaped as desired_cycle, deg.

Raises
------
TypeError
    `desired_cycle` not an array, `model` not a JointModel (or a sequence of them for a (T, 3)
    cycle).
ValueError
    A cycle of the wrong shape, shorter than 3 or not finite; not three models for a (T, 3)
    cycle.
MemoryError
    Naming `desired_cycle`.)doc";

// identify's docstring after its first line (BindModel writes the defaults there).
constexpr const char* kIdentifyDoc =
    R"doc(
Fits the paper's joint model to recordings, as `identify` does to its step tests.

Parameters
----------
requests : array_like or list of array_like
    The request sent each tick, deg: a 1-D array (one recording) or a list of them.
measured : array_like or list of array_like
    The angle measured right after each request, deg, shaped as `requests`.
lag_range_ticks : (int, int), optional
    (min, max) of l, searched exhaustively (integers, 0 to 50).
accel_range_ticks : (int, int), optional
    (min, max) of a, searched exhaustively (integers, 1 to 50).
period_ticks : int, optional
    When given (1 to 1,000,000), every recording is whole cycles of this many ticks with the
    same requests every cycle (a step test's square wave), and each is averaged into one cycle
    before the fit, as `identify` does (identify.average_cycles: true); None fits every tick as
    it is.

Returns
-------
Identification
    model, and rms_residual_deg: over every scored tick, with period_ticks the averaged fit's
    residual plus the cycles' spread about their mean, as `identify` reports it. The first
    lag_max + accel_max ticks of each recording are the prediction's warm-up and are not scored.

Raises
------
TypeError
    An argument of the wrong type: an array argument that is no array, a range that is not a
    pair, a bound or period that is not an integer.
ValueError
    Recordings that are empty, of different lengths, non-finite, too short to score, or not
    whole cycles of one request pattern when period_ticks is given; a range outside its bounds
    or with min > max; a fit outside the model's ranges.)doc";

void BindModel(py::module_& m) {
  BindJointModel(m);
  BindPaperTables(m);
  py::class_<IdentificationResult>(m, "Identification",
                                   "A model fitted to recordings, with how well it predicts them.")
      .def_readonly("model", &IdentificationResult::params, "The fitted JointModel.")
      .def_readonly("rms_residual_deg", &IdentificationResult::rms_residual_deg,
                    "RMS of measured - predicted over the scored ticks, deg.")
      .def("__repr__", [](const IdentificationResult& r) {
        return "Identification(model=" + ModelRepr(r.params) +
               ", rms_residual_deg=" + std::string(py::repr(py::float_(r.rms_residual_deg))) + ")";
      });

  // The search ranges' defaults are the identification's (and identify.yaml's).
  const IdentificationOptions search;
  // The docstring's first line shows the search ranges' defaults as they are.
  static const std::string identify_doc =
      "identify(requests, measured, *, lag_range_ticks=(" + std::to_string(search.lag_min_ticks) +
      ", " + std::to_string(search.lag_max_ticks) + "), accel_range_ticks=(" +
      std::to_string(search.accel_min_ticks) + ", " + std::to_string(search.accel_max_ticks) +
      "), period_ticks=None) -> Identification\n" + kIdentifyDoc;
  m.def(
      "identify", &Identify, py::arg("requests"), py::arg("measured"), py::kw_only(),
      py::arg("lag_range_ticks") = py::make_tuple(search.lag_min_ticks, search.lag_max_ticks),
      py::arg("accel_range_ticks") = py::make_tuple(search.accel_min_ticks, search.accel_max_ticks),
      py::arg("period_ticks") = py::none(), identify_doc.c_str());
  m.def(
      "_key_range",
      [](const std::string& key) {
        for (const KeyRow& row : experiments::ExperimentKeys({})) {
          if (row.key == key) return py::make_tuple(row.doc.min, row.doc.max);
        }
        ThrowValueError("no config key '" + key + "'");
      },
      "_key_range(key) -> (min, max): an experiment config key's declared range");

  m.def(
      "floor",
      [](py::handle desired, py::handle model) -> py::object {
        const DoubleArray array = RealArray(desired, "desired_cycle");
        if (array.ndim() == 1) {
          const std::vector<double> d = ToFiniteVector(desired, "desired_cycle", 3);
          const JointModelParams params = ToModel(model, "model");
          py::gil_scoped_release release;
          std::vector<double> x = FloorTrajectory(d, params);
          py::gil_scoped_acquire acquire;
          return ToArray(x);
        }
        const std::vector<LegAngles> rows = ToAngleRows(desired, "desired_cycle");
        if (!(py::isinstance<py::list>(model) || py::isinstance<py::tuple>(model))) {
          ThrowTypeError("model: expected one JointModel per joint (3) for a (T, 3) cycle, got a " +
                         std::string(py::str(py::type::of(model).attr("__name__"))));
        }
        if (py::len(model) != kLegJoints) {
          ThrowValueError("model: expected one JointModel per joint (3) for a (T, 3) cycle, got " +
                          std::to_string(py::len(model)));
        }
        std::vector<JointModelParams> models;
        models.reserve(kLegJoints);
        for (int j = 0; j < kLegJoints; ++j) {
          models.push_back(ToModel(model[py::int_(j)], "model[" + std::to_string(j) + "]"));
        }
        std::vector<LegAngles> floor(rows.size());
        {
          py::gil_scoped_release release;
          for (int j = 0; j < kLegJoints; ++j) {
            std::vector<double> d(rows.size());
            for (size_t t = 0; t < rows.size(); ++t) d[t] = rows[t][j];
            const std::vector<double> x = FloorTrajectory(d, models[j]);
            for (size_t t = 0; t < rows.size(); ++t) floor[t][j] = x[t];
          }
        }
        return ToArray(floor);
      },
      py::arg("desired_cycle"), py::arg("model"), kFloorDoc);
}

}  // namespace leglab::python
