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

from __future__ import annotations

import importlib as _importlib
import os as _os
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Optional, Union

if TYPE_CHECKING:  # for the annotations only: importing leglab costs no more than it did
    import numpy as _np
    import numpy.typing as _npt

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


def __getattr__(name: str) -> Any:
    """A compiled name when the compiled module is missing: ImportError saying so."""
    if _missing is not None and (name in _COMPILED or name == "_leglab"):
        raise ImportError(f"leglab.{name}: the compiled module leglab._leglab is not in "
                          f"{_here} (build it, then set PYTHONPATH=<build>/python)",
                          name=__name__) from _missing
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

JOINT_NAMES: tuple[str, str, str] = ("rotator", "abductor", "knee")
"""The joints of a leg, in the order of every per-joint array."""

TICK_S: float = 0.008
"""One control tick, s."""


def data_dir() -> str:
    """The folder of leglab's data: robots/, experiments/configs/, data/servo_logs/.

    Returns
    -------
    str
        The value of the environment variable LEGLAB_DATA_DIR, which the package sets (when it
        is not set) to the data installed beside it.
    """
    return _os.environ["LEGLAB_DATA_DIR"]


def config_path(name: str) -> str:
    """The path of a shipped experiment config, e.g. config_path("track.yaml").

    Parameters
    ----------
    name : str
        The config's file name in experiments/configs/.

    Returns
    -------
    str
        The config file's path.

    Raises
    ------
    TypeError
        `name` is not a str.
    ValueError
        No shipped config has that name.
    """
    if not isinstance(name, str):
        raise TypeError(f"config_path(): name: expected str, got {type(name).__name__}")
    path = _os.path.join(data_dir(), "experiments", "configs", name)
    if not _os.path.isfile(path):
        raise ValueError(f"config_path: no shipped config {name!r} in {_os.path.dirname(path)}")
    return path


if _missing is None:
    PAPER_MODEL: JointModel = _leglab.PAPER_MODEL
    """The paper's Table 1: v_max 2.5 deg/tick, theta_0 7 deg, l 4 ticks, a 6 ticks."""
    PAPER_TABLE2: dict[str, tuple[float, float, float]] = _leglab.PAPER_TABLE2
    """The paper's Table 2, deg: {"L2(Des,Dir)": (rotator, abductor, knee), ...}, keyed as
    table2.json's joint norms."""
    PAPER_FOOT_CM: dict[str, dict[str, dict[str, float]]] = _leglab.PAPER_FOOT_CM
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

    Attributes
    ----------
    name : str
        The controller's name in the tables and file names: letters a-z, digits and _, not a
        built-in mode's name (None in the base class: a subclass must set it).
    """

    #: The controller's name in the tables and file names: letters a-z, digits and _, not a
    #: built-in mode's name.
    name: Optional[str] = None

    def reset(self, context: ControllerContext) -> None:
        """A new run starts at tick 0.

        Parameters
        ----------
        context : ControllerContext
            The desired cycle (`desired`, shape (T, 3)), `period`, the joint `models`,
            `limits_deg`, `warmup_steps`, the approximation P and `foot_mm(q_deg)`.
        """

    def request(self, tick: int, measured: _npt.NDArray[_np.float64]) -> _npt.ArrayLike:
        """The requested angles for tick `tick`.

        Parameters
        ----------
        tick : int
            The tick, counted from the run's first (warm-up included).
        measured : numpy.ndarray
            The angles measured right after the previous request, shape (3,), deg.

        Returns
        -------
        array_like
            3 finite angles, deg; they are clamped into the limits as the servos do.

        Raises
        ------
        NotImplementedError
            A subclass must define it.
        """
        raise NotImplementedError(f"{type(self).__name__}.request")

    def observe(self, request: _npt.NDArray[_np.float64], reading: Reading) -> None:
        """After each tick: what the plant did with the request.

        Parameters
        ----------
        request : numpy.ndarray
            The request as the plant applied it (clamped), shape (3,), deg.
        reading : Reading
            The Reading right after: its `measured` angles; `true` and the stand's instruments
            are NaN (a controller does not see them).
        """

    def end_of_step(self, step: int) -> None:
        """A walking step has ended.

        Parameters
        ----------
        step : int
            The step, 0, 1, ... from the run's first (warm-up steps included).
        """


class TrackRun:
    """What run_track computed: Table 2 and the traces, as `track` writes them.

    Parameters
    ----------
    parts : dict
        The parts the compiled run returns, under the attributes' names.

    Attributes
    ----------
    table2 : dict
        The dict `track` writes to table2.json (json.load of that file compares equal): steps,
        joints.<joint>.<row>.{mean, std}, foot_cm.<mode>.{L2, Linf}, ...
    traces : dict
        {mode: {column: array}}, the columns of trace_<mode>.csv (step, tick, joint,
        desired_deg, pwl_deg, request_deg, actual_deg, model_deg), one row per tick and joint.
    feet : dict
        {mode: {column: array}}, the columns of foot_<mode>.csv.
    models : dict
        {joint: JointModel}, the models the modes used (identified or given).
    walk_models : dict or None
        {joint: JointModel} fitted to the walk, when a mode used them; else None.
    models_identified : bool
        Whether the models were identified on the plant.
    markdown : str
        The tables as `track` prints them.
    config_yaml : str
        The keys the run used (track_config.yaml's text).
    plant_ticks : int
        The plant ticks run in all.
    """

    def __init__(self, parts: Mapping[str, Any]) -> None:
        self.table2: dict[str, Any] = parts["table2"]
        self.traces: dict[str, dict[str, _npt.NDArray[Any]]] = parts["traces"]
        self.feet: dict[str, dict[str, _npt.NDArray[Any]]] = parts["feet"]
        self.models: dict[str, JointModel] = parts["models"]
        self.walk_models: Optional[dict[str, JointModel]] = parts["walk_models"]
        self.models_identified: bool = parts["models_identified"]
        self.markdown: str = parts["markdown"]
        self.config_yaml: str = parts["config_yaml"]
        self.plant_ticks: int = parts["plant_ticks"]

    def __repr__(self) -> str:
        modes = ", ".join(self.table2.get("foot_cm", {}))
        return f"TrackRun(modes=[{modes}], steps={self.table2.get('steps')})"


def _controller_list(controllers: Union[Controller, Iterable[Controller]]) -> list[Controller]:
    """`controllers` as a list; TypeError for what is not a Controller or an iterable of them
    (anything with `request` and `reset`, as run_track takes them)."""
    if isinstance(controllers, Controller):
        return [controllers]
    if isinstance(controllers, (str, bytes, Mapping)) or not hasattr(controllers, "__iter__"):
        raise TypeError(f"run_track(): controllers: expected a sequence of Controller, got "
                        f"{type(controllers).__name__}")
    given = list(controllers)
    for controller in given:
        if not isinstance(controller, Controller) and not (
                hasattr(controller, "request") and hasattr(controller, "reset")):
            raise TypeError(f"run_track(): controllers: expected Controller instances, got "
                            f"{type(controller).__name__}")
    return given


def run_track(config: Union[str, _os.PathLike[str]], overrides: Optional[Mapping[str, Any]] = None,
              controllers: Union[Controller, Iterable[Controller]] = (),
              out: Union[str, _os.PathLike[str], None] = None, threads: int = 0) -> TrackRun:
    """Table 2's experiment, as the `track` program runs it, with your own controllers.

    Parameters
    ----------
    config : str or os.PathLike
        An experiment YAML file.
    overrides : dict, optional
        Config keys, as the programs' --set ({"steps": 5}).
    controllers : Controller or sequence of Controller, optional
        Run after the configured modes under the same plant, seed, warm-up and scoring; their
        rows appear under their `name`.
    out : str or os.PathLike, optional
        A folder to write what `track` writes (table2.json, trace_<mode>.csv, ...), the same
        way (all at once, on success only); None writes nothing.
    threads : int, optional
        Worker threads, 0 for one per core (0 to 4096); the numbers do not depend on it.

    Returns
    -------
    TrackRun
        Table 2, the traces and the models of the run.

    Raises
    ------
    TypeError
        An argument of the wrong type: `config` or `out` not a path, `overrides` not a dict,
        `controllers` not Controllers, `threads` not an integer.
    ValueError
        The program's one-line message for a bad config, key, robot or controller, or `threads`
        out of its range.
    OSError
        `out` could not be written.

    Notes
    -----
    What a controller raises comes out unchanged.
    """
    given = _controller_list(controllers)
    return TrackRun(_leglab._run_track(config, overrides, given, out, threads))


__all__ = [
    "Controller", "ControllerContext", "TrackRun", "run_track", "Identification", "JointModel",
    "Plant", "Reading", "Robot", "Walk", "floor", "identify", "JOINT_NAMES", "TICK_S",
    "PAPER_MODEL", "PAPER_TABLE2", "PAPER_FOOT_CM", "data_dir", "config_path",
]
