// leglab.Robot, leglab.Walk, leglab.Reading and leglab.Plant: the leg a config describes, the
// walk it follows, and the plant that takes one request per 8 ms tick.
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "bindings.h"
#include "convert.h"
#include "leglab/core/plant.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/rig.h"
#include "leglab/experiments/robot.h"
#include "leglab/model/kinematics.h"

namespace leglab::python {
namespace {

using experiments::ExperimentConfig;
using experiments::Robot;

// Foot positions (body frame, mm) of one pose (3,) or of rows of poses (N, 3), deg.
py::object FootMm(const LegGeometry& geometry, py::handle q_deg) {
  const DoubleArray array = RealArray(q_deg, "q_deg");
  if (array.ndim() == 1) {
    const LegAngles q = ToLegAngles(q_deg, "q_deg");
    const Eigen::Vector3d foot = experiments::FootMm(geometry, q);
    return ToArray(LegAngles{foot.x(), foot.y(), foot.z()});
  }
  const std::vector<LegAngles> rows = ToAngleRows(q_deg, "q_deg");
  std::vector<LegAngles> feet(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    const Eigen::Vector3d foot = experiments::FootMm(geometry, rows[i]);
    feet[i] = {foot.x(), foot.y(), foot.z()};
  }
  return ToArray(feet);
}

ExperimentConfig LoadConfig(py::handle config, py::handle overrides) {
  return experiments::LoadExperimentConfig(ToPath(config, "config"), ToOverrides(overrides));
}

// The desired walk of a config: its cycle of joint angles and the foot path they draw.
struct Walk {
  Robot robot;
  experiments::DesiredMotion motion;
};

// A plant with the config and robot it was made from. One thread at a time drives it: a
// second caller while one is inside (e.g. in run(), which releases the GIL) gets an error
// instead of a race.
struct PlantHandle {
  ExperimentConfig config;
  Robot robot;
  std::unique_ptr<Plant> plant;
  std::mutex busy;

  std::unique_lock<std::mutex> Lock() {
    std::unique_lock<std::mutex> lock(busy, std::try_to_lock);
    if (!lock) throw std::runtime_error("Plant: in use by another thread");
    return lock;
  }
};

py::dict RunRequests(PlantHandle& h, py::handle requests) {
  const std::vector<LegAngles> rows = ToAngleRows(requests, "requests");
  const auto lock = h.Lock();
  const size_t n = rows.size();
  std::vector<LegAngles> measured(n), truth(n), applied(n), force(n);
  std::array<std::vector<double>, kStandColumns.size()> stand;
  for (std::vector<double>& column : stand) column.resize(n);
  {
    py::gil_scoped_release release;
    Plant& plant = *h.plant;
    for (size_t t = 0; t < n; ++t) {
      const PlantReading& r = plant.Tick(rows[t]);
      measured[t] = r.measured_deg;
      truth[t] = r.true_deg;
      applied[t] = r.applied_deg;
      force[t] = r.telemetry.contact_force_n;
      for (size_t c = 0; c < stand.size(); ++c) stand[c][t] = kStandColumns[c].value(r.telemetry);
    }
  }
  py::dict out;
  out["measured"] = ToArray(measured);
  out["true"] = ToArray(truth);
  out["applied"] = ToArray(applied);
  out["contact_force_n"] = ToArray(force);
  for (size_t c = 0; c < stand.size(); ++c) {
    out[py::str(std::string(kStandColumns[c].doc.name))] = ToArray(stand[c]);
  }
  return out;
}

std::vector<PlantSetting> ToSettings(py::handle settings) {
  if (!py::isinstance<py::dict>(settings)) {
    ThrowValueError("settings: expected a dict {key: number}, e.g. {\"servo.delay_ms\": 24}");
  }
  std::vector<PlantSetting> result;
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(settings)) {
    if (!py::isinstance<py::str>(key)) ThrowValueError("settings: a key is not a str");
    const std::string name = key.cast<std::string>();
    const DoubleArray number = RealArray(value, name);
    if (number.ndim() != 0) ThrowValueError(name + ": expected one number");
    result.push_back({name, *number.data()});
  }
  return result;
}

std::string ReadingRepr(const PlantReading& r) {
  const auto angles = [](const LegAngles& a) {
    return std::string(py::repr(py::make_tuple(a[0], a[1], a[2])));
  };
  return "Reading(measured=" + angles(r.measured_deg) + ", true=" + angles(r.true_deg) +
         ", applied=" + angles(r.applied_deg) + ")";
}

// Robot: a leg's geometry and its forward kinematics.
void BindRobot(py::module_& m) {
  py::class_<Robot>(m, "Robot", R"doc(
A leg as the experiments see it: read from its URDF (the one source of its geometry).
Make one with Robot(config) from an experiment config, or take Plant.robot.
)doc")
      .def(py::init([](py::handle config, py::handle overrides) {
             return experiments::LoadRobot(LoadConfig(config, overrides).sim.urdf_path);
           }),
           py::arg("config"), py::arg("overrides") = py::none(),
           "Robot(config, overrides=None)\n\n"
           "The robot an experiment config names (its `robot:` and `urdf` keys).")
      .def_readonly("name", &Robot::name, "The URDF's <robot name>.")
      .def_readonly("urdf_path", &Robot::urdf_path, "The URDF it was read from.")
      .def_readonly("leg_mass_kg", &Robot::leg_mass_kg, "The moving links' masses, kg.")
      .def_property_readonly(
          "limits_deg", [](const Robot& r) { return ToLimitsArray(r.geometry.limits); },
          "Each joint's (lower, upper) software limit, deg, shape (3, 2).")
      .def(
          "foot_mm", [](const Robot& r, py::handle q_deg) { return FootMm(r.geometry, q_deg); },
          py::arg("q_deg"),
          "foot_mm(q_deg) -> numpy.ndarray\n\n"
          "Forward kinematics: the foot (ball centre) in the body frame (x forward, y left,\n"
          "z up), mm, for joint angles in degrees: shape (3,) for (3,), (N, 3) for (N, 3).")
      .def("__repr__", [](const Robot& r) {
        return "Robot(name=" + std::string(py::repr(py::str(r.name))) + ")";
      });
}

// Walk: a config's desired cycle of joint angles and its foot path.
void BindWalk(py::module_& m) {
  py::class_<Walk>(m, "Walk", R"doc(
The desired walk of an experiment config: one step's cycle of joint angles (desired.csv, or
the half-elliptical foot locus through inverse kinematics) and the foot path they draw.
)doc")
      .def(py::init([](py::handle config, py::handle overrides) {
             const ExperimentConfig c = LoadConfig(config, overrides);
             Walk walk{experiments::LoadRobot(c.sim.urdf_path), {}};
             walk.motion = experiments::LoadDesiredMotion(c.track, walk.robot.geometry);
             return walk;
           }),
           py::arg("config"), py::arg("overrides") = py::none(),
           "Walk(config, overrides=None)\n\nThe desired walk of an experiment config.")
      .def_property_readonly(
          "angles_deg", [](const Walk& w) { return ToArray(w.motion.angles_deg); },
          "The desired joint angles, deg, shape (T, 3): tick t of every step.")
      .def_property_readonly(
          "foot_mm",
          [](const Walk& w) {
            std::vector<LegAngles> feet;
            feet.reserve(w.motion.foot_mm.size());
            for (const Eigen::Vector3d& f : w.motion.foot_mm) feet.push_back({f.x(), f.y(), f.z()});
            return ToArray(feet);
          },
          "The desired foot path, body frame, mm, shape (T, 3).")
      .def_property_readonly(
          "period", [](const Walk& w) { return w.motion.angles_deg.size(); }, "T: ticks per step.")
      .def_readonly("robot", &Walk::robot, "The Robot that walks it.");
}

// Reading: what a plant reports at the end of a tick, the stand's instruments included.
void BindReading(py::module_& m) {
  auto reading =
      py::class_<PlantReading>(m, "Reading", R"doc(
What a plant reports at the end of a tick. Angles in degrees, shape (3,): rotator, abductor,
knee. A controller is given only `measured` (and the `applied` request); `true` and the
stand's instruments are for scoring and plotting.
)doc")
          .def_property_readonly(
              "measured", [](const PlantReading& r) { return ToArray(r.measured_deg); },
              "The sensors' reading, deg.")
          .def_property_readonly(
              "true", [](const PlantReading& r) { return ToArray(r.true_deg); },
              "The exact joint angles, deg.")
          .def_property_readonly(
              "applied", [](const PlantReading& r) { return ToArray(r.applied_deg); },
              "The latest request as the servos took it (clamped to the limits), deg.")
          .def_property_readonly(
              "contact_force_n",
              [](const PlantReading& r) { return ToArray(r.telemetry.contact_force_n); },
              "The floor's force on the foot, mean over the tick, N, body axes; zeros in the air.")
          .def("__repr__", &ReadingRepr);
  // The stand's instruments, named and described as PlantTelemetry declares them.
  for (const TelemetryColumn& c : kStandColumns) {
    const std::string doc = std::string(c.doc.description) + " (" + std::string(c.doc.unit) + ").";
    reading.def_property_readonly(
        std::string(c.doc.name).c_str(),
        [value = c.value](const PlantReading& r) { return value(r.telemetry); }, doc.c_str());
  }
}

// Robot, Walk and Reading: what a Plant's users read.
void BindRobotWalkReading(py::module_& m) {
  BindRobot(m);
  BindWalk(m);
  BindReading(m);
}

// Plant.run()'s docstring, the stand's arrays named from their declarations.
const std::string& RunDoc() {
  static const std::string doc = [] {
    std::string names;
    for (const TelemetryColumn& c : kStandColumns) {
      if (!names.empty()) names += &c == &kStandColumns.back() ? " and " : ", ";
      names += '"' + std::string(c.doc.name) + '"';
    }
    return "run(requests) -> dict\n\nTicks through `requests`, shape (T, 3), deg, one row a "
           "tick, with the GIL released.\n\nReturns a dict of arrays, one row a tick: "
           "\"measured\", \"true\", \"applied\" (T, 3) deg, \"contact_force_n\" (T, 3) N, "
           "and " +
           names + " (T,) mm. Every request is checked (finite) before the first tick.";
  }();
  return doc;
}

}  // namespace

void BindPlant(py::module_& m) {
  BindRobotWalkReading(m);
  py::class_<PlantHandle>(m, "Plant", R"doc(
The plant an experiment config describes: `plant: sim` (the simulated leg, any robot, the
test stand) or `plant: model` (the joint model as an ideal plant). It takes one request per
8 ms tick and reports its angles, as the programs drive it.

Args:
    config: an experiment YAML file (str or os.PathLike), e.g. leglab.config_path("track.yaml").
    overrides: a dict of config keys, as the programs' --set: {"servo.delay_ms": 24,
        "plant": "model"}.

Raises ValueError with the programs' one-line message for a bad config, key or robot.
The plant starts at rest at q = 0 (or the pose nearest it inside the limits).
)doc")
      .def(py::init([](py::handle config, py::handle overrides) {
             auto h = std::make_unique<PlantHandle>();
             h->config = LoadConfig(config, overrides);
             h->robot = experiments::LoadRobot(h->config.sim.urdf_path);
             h->plant = experiments::MakePlant(h->config, h->robot);
             return h;
           }),
           py::arg("config"), py::arg("overrides") = py::none(),
           "Plant(config, overrides=None)\n\nThe plant an experiment config describes.")
      .def(
          "reset",
          [](PlantHandle& h, py::handle pose) {
            const LegAngles q = ToLegAngles(pose, "pose");
            const auto lock = h.Lock();
            h.plant->Reset(q);
          },
          py::arg("pose"),
          "reset(pose) -> None\n\n"
          "Puts the leg at rest at `pose` (3 angles, deg, within the limits) with its servos\n"
          "holding it. Does not advance time.")
      .def(
          "tick",
          [](PlantHandle& h, py::handle request) {
            const LegAngles r = ToLegAngles(request, "request");
            const auto lock = h.Lock();
            return h.plant->Tick(r);
          },
          py::arg("request"),
          "tick(request) -> Reading\n\n"
          "One 8 ms tick: `request` (3 angles, deg; clamped into the limits as the servos do)\n"
          "goes to the servos, the leg moves, and the Reading at the end of the tick is\n"
          "returned.")
      .def("run", &RunRequests, py::arg("requests"), RunDoc().c_str())
      .def(
          "change_settings",
          [](PlantHandle& h, py::handle settings) {
            const std::vector<PlantSetting> s = ToSettings(settings);
            const auto lock = h.Lock();
            h.plant->ChangeSettings(s);
          },
          py::arg("settings"),
          "change_settings(settings) -> None\n\n"
          "Changes settings of the running plant between ticks, as wear or a swapped part\n"
          "would: a dict {key: value} with robot.yaml's keys (servo.*, sensor.*;\n"
          "plant_model.* for plant: model). All are checked before any is applied.")
      .def_property_readonly(
          "reading",
          [](PlantHandle& h) {
            const auto lock = h.Lock();
            return h.plant->Read();
          },
          "The latest Reading (after reset(), or at the end of the latest tick).")
      .def_property_readonly(
          "name", [](const PlantHandle& h) { return std::string(h.plant->name()); },
          "The kind of plant: \"sim\" or \"model\".")
      .def_readonly("robot", &PlantHandle::robot, "The Robot this plant is.")
      .def_property_readonly(
          "config_yaml", [](const PlantHandle& h) { return h.config.merged_yaml; },
          "The keys it was made from, YAML (the config over its bases and the robot file, "
          "with the overrides).")
      .def_property_readonly(
          "tick_s", [](const PlantHandle&) { return kTickMs / 1000.0; },
          "The length of one tick, s (0.008).");
}

}  // namespace leglab::python
