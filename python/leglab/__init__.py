"""leglab: model-based joint control of a simulated Aibo leg, from Python.

Angles are in degrees and time in 8 ms ticks (one call of Plant.tick per tick), as in the
paper (Stronger & Stone, "A Model-Based Approach to Robot Joint Control"). Arrays are numpy
float64; a leg's per-joint values are ordered rotator, abductor, knee.

    import leglab
    plant = leglab.Plant(leglab.config_path("track.yaml"), {"steps": 5})
    reading = plant.tick([10.0, 0.0, 20.0])

See docs/python.md for the whole API and examples/python/ for four short scripts; leglab.servo
is the real-servo workflow (docs/real-servos.md).
"""

import importlib as _importlib
import os as _os

try:
    from . import _paths
    _to_data = _paths.PACKAGE_TO_DATA
except ImportError:  # the source tree's python/ (no build wrote _paths.py): the repository's
    _to_data = _os.path.join(_os.pardir, _os.pardir)

_here = _os.path.dirname(_os.path.abspath(__file__))
# The C++ core finds robots/ and the configs through LEGLAB_DATA_DIR when it is set (as a
# program not installed beside leglab's own must); the package's data is where CMake put it.
_os.environ.setdefault("LEGLAB_DATA_DIR", _os.path.normpath(_os.path.join(_here, _to_data)))

# The compiled module's names. Without it (the source tree's python/, a copy of the pure-Python
# parts) the package still imports, for leglab.results, and a compiled name raises on use.
_COMPILED = ("ControllerContext", "Identification", "JointModel", "Plant", "Reading", "Robot",
             "Walk", "floor", "identify", "PAPER_MODEL", "PAPER_TABLE2", "PAPER_FOOT_CM")
try:
    _leglab = _importlib.import_module(f"{__name__}._leglab")
    _missing = None
except ModuleNotFoundError as _error:
    if _error.name != f"{__name__}._leglab":
        raise
    _missing = _error

if _missing is None:
    from ._leglab import (  # noqa: E402  (after the data folder is known)
        ControllerContext,
        Identification,
        JointModel,
        Plant,
        Reading,
        Robot,
        Walk,
    )
    from . import _one_line  # noqa: E402

    # A call the compiled module cannot match raises one line naming the argument.
    _one_line.wrap_module(_leglab, [n for n in dir(_leglab) if not n.startswith("__")])
    from ._leglab import floor, identify  # noqa: E402  (the wrapped functions)

    # help() and repr() name the classes as users import them.
    for _cls in (ControllerContext, Identification, JointModel, Plant, Reading, Robot, Walk):
        _cls.__module__ = "leglab"


def __getattr__(name):
    """A compiled name when the compiled module is missing: ImportError saying so."""
    if _missing is not None and (name in _COMPILED or name == "_leglab"):
        raise ImportError(f"leglab.{name}: the compiled module leglab._leglab is not in "
                          f"{_here} (build it, then set PYTHONPATH=<build>/python)",
                          name=__name__) from _missing
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

JOINT_NAMES = ("rotator", "abductor", "knee")
"""The joints of a leg, in the order of every per-joint array."""

TICK_S = 0.008
"""One control tick, s."""


def data_dir():
    """The folder of leglab's data: robots/, experiments/configs/, data/servo_logs/."""
    return _os.environ["LEGLAB_DATA_DIR"]


def config_path(name):
    """The path of a shipped experiment config, e.g. config_path("track.yaml")."""
    path = _os.path.join(data_dir(), "experiments", "configs", name)
    if not _os.path.isfile(path):
        raise ValueError(f"config_path: no shipped config {name!r} in {_os.path.dirname(path)}")
    return path


if _missing is None:
    PAPER_MODEL = _leglab.PAPER_MODEL
    """The paper's Table 1: v_max 2.5 deg/tick, theta_0 7 deg, l 4 ticks, a 6 ticks."""
    PAPER_TABLE2 = _leglab.PAPER_TABLE2
    """The paper's Table 2, deg: {"L2(Des,Dir)": (rotator, abductor, knee), ...}, keyed as
    table2.json's joint norms."""
    PAPER_FOOT_CM = _leglab.PAPER_FOOT_CM
    """The paper's foot table, cm: {"direct": {"L2": {"mean": 3.23, "std": 0.01}, "Linf": ...},
    ...}, shaped as table2.json's foot_cm."""


class Controller:
    """A request policy written in Python, run by run_track beside the built-in modes.

    Subclass it, set `name` and define `request`; `reset`, `observe` and `end_of_step` are
    optional. Per 8 ms tick the experiment calls, in order:

        r = request(tick, measured)     the 3 requested angles (deg) for this tick
        observe(request, reading)       what the plant did with them

    and after the last tick of every step (warm-up steps included) end_of_step(step).
    `tick` counts from the run's first tick, warm-up included, so

        class Direct(leglab.Controller):
            name = "my_direct"
            def reset(self, context):
                self.desired = context.desired
            def request(self, tick, measured):
                return self.desired[tick % len(self.desired)]

    is the built-in `direct` mode, number for number.
    """

    #: The controller's name in the tables and file names: letters a-z, digits and _, not a
    #: built-in mode's name.
    name = None

    def reset(self, context):
        """A new run starts at tick 0. `context` is a ControllerContext: the desired cycle
        (`desired`, shape (T, 3)), `period`, the joint `models`, `limits_deg`, `warmup_steps`,
        the approximation P and `foot_mm(q_deg)`."""

    def request(self, tick, measured):
        """The requested angles (3, deg) for tick `tick`, given the angles measured right
        after the previous request (`measured`, shape (3,), deg). Finite; they are clamped
        into the limits as the servos do."""
        raise NotImplementedError(f"{type(self).__name__}.request")

    def observe(self, request, reading):
        """After each tick: the request as the plant applied it (clamped, deg) and the
        Reading right after (its `measured` angles; `true` and the stand's instruments are
        NaN: a controller does not see them)."""

    def end_of_step(self, step):
        """Step `step` (0, 1, ... from the run's first, warm-up steps included) has ended."""


class TrackRun:
    """What run_track computed: Table 2 and the traces, as `track` writes them.

    Attributes:
        table2: the dict `track` writes to table2.json (json.load of that file compares
            equal): steps, joints.<joint>.<row>.{mean, std}, foot_cm.<mode>.{L2, Linf}, ...
        traces: {mode: {column: array}}, the columns of trace_<mode>.csv (step, tick, joint,
            desired_deg, pwl_deg, request_deg, actual_deg, model_deg), one row per tick and
            joint.
        feet: {mode: {column: array}}, the columns of foot_<mode>.csv.
        models: {joint: JointModel}, the models the modes used (identified or given).
        walk_models: {joint: JointModel} fitted to the walk, when a mode used them; else None.
        models_identified: whether the models were identified on the plant.
        markdown: the tables as `track` prints them.
        config_yaml: the keys the run used (track_config.yaml's text).
        plant_ticks: the plant ticks run in all.
    """

    def __init__(self, parts):
        self.table2 = parts["table2"]
        self.traces = parts["traces"]
        self.feet = parts["feet"]
        self.models = parts["models"]
        self.walk_models = parts["walk_models"]
        self.models_identified = parts["models_identified"]
        self.markdown = parts["markdown"]
        self.config_yaml = parts["config_yaml"]
        self.plant_ticks = parts["plant_ticks"]

    def __repr__(self):
        modes = ", ".join(self.table2.get("foot_cm", {}))
        return f"TrackRun(modes=[{modes}], steps={self.table2.get('steps')})"


def run_track(config, overrides=None, controllers=(), out=None, threads=0):
    """Table 2's experiment, as the `track` program runs it, with your own controllers.

    Args:
        config: an experiment YAML file (str or os.PathLike).
        overrides: a dict of config keys, as the programs' --set ({"steps": 5}).
        controllers: Controller instances, run after the configured modes under the same
            plant, seed, warm-up and scoring; their rows appear under their `name`.
        out: a folder to write what `track` writes (table2.json, trace_<mode>.csv, ...), the
            same way (all at once, on success only); None writes nothing.
        threads: worker threads, 0 for one per core; the numbers do not depend on it.

    Returns a TrackRun. Raises ValueError with the program's one-line message for a bad
    config, key, robot or controller, and what a controller raises, unchanged.
    """
    if isinstance(controllers, Controller):
        controllers = [controllers]
    return TrackRun(_leglab._run_track(config, overrides, list(controllers), out, threads))


__all__ = [
    "Controller", "ControllerContext", "TrackRun", "run_track", "Identification", "JointModel", "Plant", "Reading", "Robot", "Walk", "floor", "identify",
    "JOINT_NAMES", "TICK_S", "PAPER_MODEL", "PAPER_TABLE2", "PAPER_FOOT_CM", "data_dir", "config_path",
]
