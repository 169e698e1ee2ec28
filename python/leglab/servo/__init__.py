"""leglab.servo: your own servo, from its logs to its requests, offline and online.

The same numbers as the programs, to the bit: fit() is `identify` with a `logs` section
(LogFit.to_json() is its log_fit.json), plan() is `plan` (its requests.csv's columns), and a
ServoPlanner streams plan()'s requests one tick at a time for a loop that drives a servo.

    import leglab.servo as servo
    fit = servo.fit(leglab.config_path("identify_logs.yaml"))
    model = fit.model("xl330")                      # the extended rung
    planned = servo.plan(model, desired, kp=400, mass_kg=0.5, length_m=0.12)
    planner = servo.ServoPlanner(model, kp=400, mass_kg=0.5, length_m=0.12)
    planner.reset(angle_now)
    request = planner.request(desired[t:t + planner.horizon_ticks + 1], measured)

Angles are in degrees and times in seconds; arrays are numpy float64. A bad value raises
ValueError with the programs' one-line message, an argument of the wrong type TypeError. See
docs/real-servos.md ("From Python", "Online") and examples/python/your_servo.py.
"""

from __future__ import annotations

import json as _json
import os as _os
import tempfile as _tempfile
from typing import TYPE_CHECKING, Any, Callable, Mapping, Optional, Sequence, Union

import numpy as _np
import numpy.typing as _npt

if TYPE_CHECKING:  # the compiled module's stub, not leglab's variable `_leglab` (a ModuleType)
    import leglab._leglab as _leglab
else:
    from .. import _leglab
from .._leglab import ServoModel

ServoModel.__module__ = "leglab.servo"


# A log's arrays, named as leglab's CSV log names its columns (time, request, measured, torque).
_LOG_COLUMNS = _leglab._log_columns()


_Path = Union[str, "_os.PathLike[str]"]
_Vector = _npt.NDArray[_np.float64]


class ServoPlanner(_leglab.ServoPlanner):
    __doc__ = _leglab.ServoPlanner.__doc__

    def __init__(self, model: ServoModel, *args: Any, **kwargs: Any) -> None:
        if not isinstance(model, ServoModel):
            raise TypeError(f"ServoPlanner(): model: expected a ServoModel (LogFit.model), got "
                            f"{type(model).__name__}")
        # pybind11 takes bytes for a str: a method given as bytes is refused as plan() does.
        method = args[0] if args else kwargs.get("method", "model_based")
        if not isinstance(method, str):
            raise TypeError(f"ServoPlanner(): method: expected str ('model_based' or 'optimal'), "
                            f"got {type(method).__name__}")
        super().__init__(model, *args, **kwargs)

    def reset(self, angle_deg: float) -> None:
        """The servo at rest at an angle; the next request is tick 0.

        Parameters
        ----------
        angle_deg : float
            The angle, deg, finite.

        Raises
        ------
        TypeError
            `angle_deg` not a number (bool is not one).
        ValueError
            `angle_deg` out of range or not finite; the planner is left as it was.
        """
        # pybind11 takes a bool for a float: checked here as every other angle is.
        super().reset(_number(angle_deg, "angle_deg"))


_META_KEYS = ("motor", "kp", "mass_kg", "length_m")


def _not_an_array(values: object) -> bool:
    """Whether `values` is no array at all (None, text, a dict or set, one object): the
    argument's type is wrong, where an array of the wrong numbers is a wrong value."""
    if values is None or isinstance(values, (str, bytes, dict, set)):
        return True
    return not isinstance(values, (_np.ndarray, list, tuple)) and \
        _np.asarray(values).dtype.kind == "O"


def _real_vector(values: _npt.ArrayLike, what: str) -> _Vector:
    """`values` as a float64 copy: TypeError when it is no array, ValueError for the wrong
    numbers (bool, complex, text) or a shape other than 1-D."""
    if _not_an_array(values):
        raise TypeError(f"{what}: expected an array of numbers, got {type(values).__name__}")
    array = _np.asarray(values)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"{what}: expected real numbers, got dtype {array.dtype}")
    if array.ndim != 1:
        raise ValueError(f"{what}: expected a 1-D array, got shape {array.shape}")
    return _np.array(array, dtype=_np.float64, order="C", copy=True)  # not the caller's buffer


def _number(value: object, what: str) -> float:
    """`value` as a float; a TypeError naming `what` and the type given for anything that is not
    a real number (bool included), as the compiled module's own arguments."""
    if isinstance(value, (bool, _np.bool_)) or not isinstance(value, (int, float, _np.integer,
                                                                     _np.floating)):
        raise TypeError(f"{what}: expected a number, got {type(value).__name__}")
    return float(value)


class ServoLog:
    """A recorded run of one servo: what it was asked, what it did, and what it drove.

    It is checked as identify checks a file. Build one from your own recording:

        log = ServoLog(t, requests, measured, motor="my_servo", kp=32, mass_kg=0.2,
                       length_m=0.1, trajectory="sweep", file="sweep_1.csv")

    Parameters
    ----------
    time_s : array_like
        Time stamps, s, strictly increasing (1-D, one per sample).
    request_deg : array_like
        The position request sent, deg.
    measured_deg : array_like
        The position the servo reported, deg.
    torque_enabled : array_like of bool, optional
        False while the servo was limp (not scored, not fitted); None: on throughout.
    motor : str
        The servo type: one model is fitted per type.
    kp : float
        Its gain register.
    mass_kg, length_m : float, optional
        The load: a point mass on an arm, 0 deg hanging straight down.
    trajectory : str, optional
        The request's shape: cross-validation leaves each one out in turn.
    file : str, optional
        Where it was read from, or its name: log_<motor>_<stem of file>.csv is what identify
        writes for it.

    Attributes
    ----------
    time_s, request_deg, measured_deg : numpy.ndarray
        The samples, float64, one length.
    torque_enabled : numpy.ndarray
        bool, one per sample.
    motor, trajectory, file : str
        As given.
    kp, mass_kg, length_m : float
        As given.

    Raises
    ------
    TypeError
        An argument of the wrong type: an array argument that is no array, a `str` argument
        that is not one, a number that is not a number (bool included).
    ValueError
        Naming the sample and column: arrays of the wrong numbers or lengths, times not
        increasing, values identify refuses.
    """

    _fields: dict[str, Any]

    def __init__(self, time_s: _npt.ArrayLike, request_deg: _npt.ArrayLike,
                 measured_deg: _npt.ArrayLike, torque_enabled: Optional[_npt.ArrayLike] = None,
                 *, motor: str, kp: float, mass_kg: float = 0.0, length_m: float = 0.0,
                 trajectory: str = "", file: str = "") -> None:
        time, request, measured = (
            _real_vector(value, name)
            for value, name in zip((time_s, request_deg, measured_deg), _LOG_COLUMNS))
        if torque_enabled is None:
            torque_on = _np.ones(time.shape, dtype=bool)
        else:
            if _not_an_array(torque_enabled):
                raise TypeError(f"{_LOG_COLUMNS[3]}: expected an array of booleans, got "
                                f"{type(torque_enabled).__name__}")
            torque = _np.asarray(torque_enabled)
            if torque.dtype.kind not in "biu" or (torque.dtype.kind != "b" and
                                                  not _np.isin(torque, (0, 1)).all()):
                raise ValueError(f"{_LOG_COLUMNS[3]}: expected booleans (or 0 and 1)")
            torque_on = _np.array(torque, dtype=bool, order="C", copy=True)
        for name, value in (("motor", motor), ("trajectory", trajectory), ("file", file)):
            if not isinstance(value, str):
                raise TypeError(f"{name}: expected a str, got {type(value).__name__}")
        self._fields = {
            "file": file or trajectory or "log", "motor": motor, "trajectory": trajectory,
            "kp": _number(kp, "kp"), "mass_kg": _number(mass_kg, "mass_kg"),
            "length_m": _number(length_m, "length_m"),
            **dict(zip(_LOG_COLUMNS, (time, request, measured, torque_on))),
        }
        _leglab._check_log(self._fields)

    @classmethod
    def _from_fields(cls, fields: dict[str, Any]) -> ServoLog:
        log = cls.__new__(cls)
        log._fields = fields
        return log

    def __getattr__(self, name: str) -> Any:
        fields = self.__dict__.get("_fields", {})
        if name in fields:
            return fields[name]
        raise AttributeError(name)

    def __len__(self) -> int:
        return len(self._fields[_LOG_COLUMNS[0]])

    def __repr__(self) -> str:
        f = self._fields
        return (f"ServoLog(file={f['file']!r}, motor={f['motor']!r}, kp={f['kp']!r}, "
                f"samples={len(self)})")


def read_log(path: _Path, format: str = "auto", **meta: Any) -> ServoLog:
    """The servo log at `path`, as identify reads it.

    Parameters
    ----------
    path : str or os.PathLike
        BAM's JSON (`.json`) or leglab's CSV (`.csv`).
    format : {"auto", "csv", "bam_json"}, optional
        "auto" decides by the extension.
    **meta
        motor (str), kp, mass_kg, length_m (numbers): a CSV log does not say them (a BAM log's
        own are used, and these ignored).

    Returns
    -------
    ServoLog
        The log.

    Raises
    ------
    TypeError
        `path` not a path, `format` or `motor` not a str, a number of the wrong type, an
        unknown keyword.
    ValueError
        No such file, its content (naming the row and column), an unknown format, no motor or
        kp for a CSV log.
    """
    if not isinstance(format, str):
        raise TypeError(f"read_log(): format: expected str ('auto', 'csv' or 'bam_json'), got "
                        f"{type(format).__name__}")
    unknown = sorted(set(meta) - set(_META_KEYS))
    if unknown:
        # Python's own convention for a keyword a function does not take.
        raise TypeError(f"read_log(): unknown keyword {unknown[0]!r} (expected one of "
                        f"{', '.join(_META_KEYS)})")
    motor = meta.get("motor", "")
    if not isinstance(motor, str):
        raise TypeError(f"motor: expected a str, got {type(motor).__name__}")
    numbers = [_number(meta.get(key, 0.0), key) for key in _META_KEYS[1:]]
    fields = _leglab._read_log(path, format, motor, *numbers)
    # A CSV log names neither its motor nor its gain: without them it could be read but not
    # fitted, planned for or scored, so say so here, naming the keywords.
    if not fields["motor"]:
        raise ValueError(f"read_log '{fields['file']}': no motor (a CSV log takes it from "
                         f"motor=)")
    problem = _leglab._drive_problem(fields["kp"], fields["mass_kg"], fields["length_m"])
    if problem:
        raise ValueError(f"read_log '{fields['file']}': {problem} (a CSV log takes it from kp=)")
    return ServoLog._from_fields(fields)


def write_log(log: ServoLog, path: _Path) -> None:
    """Writes `log` in leglab's CSV form, all at once.

    The columns are time_s,request_deg,measured_deg,torque_enabled, every number as the
    shortest text that reads back as the same double. A failed write leaves no file behind and
    an existing one as it was. read_log(path, motor=..., kp=..., mass_kg=..., length_m=...)
    reads it back to the same samples.

    Parameters
    ----------
    log : ServoLog
        The log to write.
    path : str or os.PathLike
        A new name or a regular file.

    Raises
    ------
    TypeError
        `log` not a ServoLog, `path` not a path.
    ValueError
        A link, folder, FIFO or device at `path` (it is not replaced).
    FileNotFoundError
        No such folder.
    OSError
        A failed write (no file left behind).
    """
    if not isinstance(log, ServoLog):
        raise TypeError(f"write_log(): log: expected a ServoLog, got {type(log).__name__}")
    text = _leglab._log_csv_text(log._fields)
    if not isinstance(path, (str, _os.PathLike)):
        raise TypeError(f"write_log(): path: expected a path (str or os.PathLike), got "
                        f"{type(path).__name__}")
    path = _os.fspath(path)
    # A new name or a regular file only: a link, a folder, a FIFO or a device at the path is
    # the user's and is not replaced (as the programs' --out refuses them).
    if _os.path.lexists(path) and (_os.path.islink(path) or not _os.path.isfile(path)):
        raise ValueError(f"write_log '{path}': not a regular file (a link, a folder, a FIFO or a "
                         f"device); it is left as it is")
    folder = _os.path.dirname(_os.path.abspath(path))
    if not _os.path.isdir(folder):
        raise FileNotFoundError(f"write_log '{path}': the folder '{folder}' does not exist")
    fd, staging = _tempfile.mkstemp(prefix="." + _os.path.basename(path) + ".", dir=folder)
    try:
        with _os.fdopen(fd, "w", encoding="ascii", newline="") as out:
            out.write(text)
        _os.replace(staging, path)
    except BaseException:
        if _os.path.exists(staging):
            _os.unlink(staging)
        raise


class LogFit:
    """What fit() computed, as `identify` writes it.

    Parameters
    ----------
    text : str
        log_fit.json's text.
    markdown : str, optional
        log_fit.md's text.
    curves : dict, optional
        {name: {column: array}}, the curves of each log.
    source : str, optional
        What the text is, for messages.

    Attributes
    ----------
    json : dict
        log_fit.json as a dict (models, cross_validate, folds, logs).
    markdown : str
        log_fit.md's text.
    curves : dict
        {name: {column: array}}, the columns of each log_<name>.csv (time_s, request_deg,
        measured_deg, torque_enabled, direct_deg, best_shift_deg, paper_deg, extended_deg: the
        predictions held out where cross-validated); empty when loaded from a file.
    folds : list
        The cross-validation's fits (json["folds"]).
    rows : list
        Every scored log, in sample and held out (json["logs"]): file, role, held_out_by,
        motor, trajectory, kp, ticks_scored, best_shift_s, mae_deg, rms_deg and plan.
    motors : list of str
        The motors fitted.

    Raises
    ------
    TypeError
        `text` not a str.
    ValueError
        `text` not a JSON object, or a field of the wrong JSON type (`logs: 3`).
    """

    def __init__(self, text: str, markdown: str = "",
                 curves: Optional[dict[str, dict[str, _npt.NDArray[Any]]]] = None,
                 source: str = "LogFit") -> None:
        if not isinstance(text, str):
            raise TypeError(f"{source}: text: expected a str (log_fit.json's text), got "
                            f"{type(text).__name__}")
        self._text = text
        self._source = source
        try:
            self.json: dict[str, Any] = _json.loads(text)
        except ValueError as e:
            raise ValueError(f"{source}: not valid JSON ({e})") from None
        if not isinstance(self.json, dict):
            raise ValueError(f"{source}: expected a JSON object (a log_fit.json), got "
                             f"{type(self.json).__name__}")
        for field, kind in (("models", dict), ("folds", list), ("logs", list)):
            if not isinstance(self.json.get(field, kind()), kind):
                raise ValueError(f"{source}: {field}: expected a JSON "
                                 f"{'object' if kind is dict else 'array'}, got "
                                 f"{type(self.json[field]).__name__}")
        self.markdown = markdown
        self.curves = curves or {}
        self.folds: list[Any] = self.json.get("folds", [])
        self.rows: list[Any] = self.json.get("logs", [])
        extended = self.json.get("models", {}).get("extended", {})
        self.motors: list[str] = sorted(extended) if isinstance(extended, dict) else []

    @classmethod
    def load(cls, path: _Path) -> LogFit:
        """The log_fit.json `identify` wrote (its models, folds and rows; no curves).

        Parameters
        ----------
        path : str or os.PathLike
            The file.

        Returns
        -------
        LogFit
            Its fit.

        Raises
        ------
        TypeError
            `path` not a path.
        FileNotFoundError, IsADirectoryError, PermissionError
            As `open` raises them.
        ValueError
            Not UTF-8, not JSON, a field of the wrong type (`logs: 3`).
        """
        if not isinstance(path, (str, _os.PathLike)):
            raise TypeError(f"LogFit.load(): path: expected a path (str or os.PathLike), got "
                            f"{type(path).__name__}")
        path = _os.fspath(path)
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read()
        except UnicodeDecodeError as e:
            raise ValueError(f"LogFit.load '{path}': not UTF-8 text ({e.reason})") from None
        try:
            _json.loads(text)
        except ValueError as e:
            raise ValueError(f"LogFit.load '{path}': not valid JSON ({e})") from None
        return cls(text, source=f"LogFit.load '{path}'")

    def to_json(self) -> str:
        """log_fit.json's text, as identify writes it for the same logs and keys.

        Returns
        -------
        str
            The JSON text.
        """
        return self._text

    def model(self, motor: Optional[str] = None, rung: str = "extended") -> ServoModel:
        """A fitted model.

        Parameters
        ----------
        motor : str, optional
            The motor; None: the only one.
        rung : {"extended", "paper"}, optional
            The rung of the model ladder.

        Returns
        -------
        ServoModel
            The model of `motor` and `rung`.

        Raises
        ------
        TypeError
            `motor` or `rung` not a str.
        ValueError
            No such motor or rung, a field missing or out of its range.
        """
        if motor is not None and not isinstance(motor, str):
            raise TypeError(f"LogFit.model(): motor: expected a str or None, got "
                            f"{type(motor).__name__}")
        if not isinstance(rung, str):
            raise TypeError(f"LogFit.model(): rung: expected a str ('extended' or 'paper'), got "
                            f"{type(rung).__name__}")
        return _leglab._model_from_json(self._text, rung, motor or "", self._source)

    def __repr__(self) -> str:
        return (f"LogFit(motors={self.motors}, cross_validate={self.json.get('cross_validate')!r}"
                f", logs={len(self.rows)})")


#: A fit function of a ModelRung: (recordings, tick_s) -> parameters by name.
RungFit = Callable[[list[dict[str, Any]], float], Mapping[str, float]]
#: A predict function of a ModelRung: (parameters, recording, tick_s) -> angles (deg).
RungPredict = Callable[[dict[str, float], dict[str, Any], float], Any]


class ModelRung:
    """A model rung of your own, fitted and scored beside the ladder's (``fit(..., rungs=)``).

    Parameters
    ----------
    name : str
        Its key in log_fit.json (``mae_deg.<name>``, ``models.<name>``) and its CSV column
        (``<name>_deg``): a lower-case identifier no rung of the ladder has.
    fit : callable
        ``fit(recordings, tick_s) -> {parameter: value}``: the model fitted to one motor's
        training logs (per fold when cross-validated). Each recording is a dict of arrays on
        the motor's tick (``request_deg``, ``measured_deg``, ``driven``) and its drive
        (``kp``, ``mass_kg``, ``length_m``).
    predict : callable
        ``predict(parameters, recording, tick_s) -> angles``: the angle at every tick of the
        recording (deg), open loop from its requests and, where a driven run begins, its
        measured angle.
    label, description, column : str, optional
        Its table heading (default: the name with spaces), the phrase log_fit.md explains it
        by, its CSV column's description.

    Raises
    ------
    TypeError
        A name, label, description or column that is not a str; a fit or predict that is not
        callable.

    Notes
    -----
    Both functions are called from the fit's worker threads, one at a time (each call holds
    the GIL). A bad name is refused by ``fit`` (ValueError naming it).
    """

    def __init__(self, name: str, fit: RungFit, predict: RungPredict, *,
                 label: Optional[str] = None, description: Optional[str] = None,
                 column: Optional[str] = None) -> None:
        for what, value in (("name", name), ("label", label), ("description", description),
                            ("column", column)):
            if (what == "name" or value is not None) and not isinstance(value, str):
                raise TypeError(f"ModelRung(): {what}: expected str, got {type(value).__name__}")
        for what, function in (("fit", fit), ("predict", predict)):
            if not callable(function):
                raise TypeError(f"ModelRung(): {what}: expected a function, got "
                                f"{type(function).__name__}")
        self.name, self.fit, self.predict = name, fit, predict
        self.label: str = label or name.replace("_", " ")
        self.description: str = description or f"the rung {name}"
        self.column: str = column or f"the rung {name}'s prediction"

    def _fields(self) -> tuple[str, str, str, str, RungFit, RungPredict]:
        return (self.name, self.label, self.description, self.column, self.fit, self.predict)

    def __repr__(self) -> str:
        return f"ModelRung({self.name!r})"


def fit(config: Union[_Path, ServoLog, list[ServoLog], tuple[ServoLog, ...]],
        overrides: Optional[Mapping[str, Any]] = None, *, validate: Sequence[ServoLog] = (),
        threads: int = 0, rungs: Sequence[ModelRung] = ()) -> LogFit:
    """Fits and scores the model ladder on servo logs, as `identify` does with a `logs` section.

    Parameters
    ----------
    config : str, os.PathLike, ServoLog or list of ServoLog
        An experiment YAML file with a `logs` section, or the logs to fit on.
    overrides : dict, optional
        Config keys, as the programs' --set: {"logs.cross_validate": "none",
        "logs.iterations": 500}. With a list of logs, only logs.* keys.
    validate : sequence of ServoLog, optional
        Logs to score the fitted models on, unchanged (with a list of logs).
    threads : int, optional
        Worker threads, 0 for one per core; the numbers do not depend on it.
    rungs : sequence of ModelRung, optional
        Model rungs of your own, fitted and scored after the ladder's, written as theirs.

    Returns
    -------
    LogFit
        The fit.

    Raises
    ------
    TypeError
        An argument of the wrong type: a log that is not a ServoLog, `config` not a path,
        `overrides` not a dict, `threads` not an integer, a rung that is not a ModelRung; a
        rung's fit returning no dict of numbers.
    ValueError
        identify's one-line message for a bad config, key or log; `validate` with a config; a
        rung's bad name, or its predict returning the wrong number of angles or a non-finite
        one.
    """
    extra = []
    for rung in rungs:
        if not isinstance(rung, ModelRung):
            raise TypeError(f"fit(): rungs: expected ModelRung objects, got {type(rung).__name__}")
        extra.append(rung._fields())
    if isinstance(config, ServoLog):
        config = [config]
    if isinstance(config, (list, tuple)):
        given = []
        for role, logs in ((True, config), (False, validate)):
            for log in logs:
                if not isinstance(log, ServoLog):
                    raise TypeError(f"fit(): expected ServoLog objects, got {type(log).__name__}")
                given.append((log._fields, role))
        parts = _leglab._fit(None, overrides, given, threads, extra)
    else:
        if validate:
            raise ValueError("fit: validate= goes with a list of logs; a config names its "
                             "validation logs in logs.validate")
        parts = _leglab._fit(config, overrides, [], threads, extra)
    curves = {c.pop("name"): c for c in parts["curves"]}
    return LogFit(parts["json"], parts["markdown"], curves)


def plan(model: ServoModel, desired_deg: _npt.ArrayLike, method: str = "model_based", *,
         kp: Optional[float] = None, mass_kg: float = 0.0, length_m: float = 0.0,
         min_deg: float = -180.0, max_deg: float = 180.0) -> _Columns:
    """Requests for `model` to follow `desired_deg`, as the `plan` program computes them.

    Requests stay in [min_deg, max_deg] and change at most at the model's top speed.

    Parameters
    ----------
    model : ServoModel
        The servo's fitted model (LogFit.model).
    desired_deg : array_like
        One angle a tick of model.tick_s, deg, 1-D, finite.
    method : {"model_based", "optimal"}, optional
        The model inverted along the path, or the least squared predicted error.
    kp : float, optional
        The servo's gain register (required for the extended rung).
    mass_kg, length_m : float, optional
        The servo's load.
    min_deg, max_deg : float, optional
        The requests' bounds.

    Returns
    -------
    dict of numpy.ndarray
        The columns of plan's requests.csv (time_s, desired_deg, request_deg, predicted_deg,
        beyond_servo) and direct_deg, the model's prediction with the desired angles sent as
        they are. Each is also an attribute: plan(...).request_deg.

    Raises
    ------
    TypeError
        `model` not a ServoModel, `method` not a str, a scalar of the wrong type,
        `desired_deg` not an array.
    ValueError
        A value out of range, an unknown method, a model a plan refuses.
    MemoryError
        Naming `desired_deg`.
    """
    if not isinstance(model, ServoModel):
        raise TypeError(f"plan(): model: expected a ServoModel (LogFit.model), got "
                        f"{type(model).__name__}")
    if not isinstance(method, str):
        raise TypeError(f"plan(): method: expected str ('model_based' or 'optimal'), got "
                        f"{type(method).__name__}")
    return _Columns(_leglab._plan(model, desired_deg, method, kp, mass_kg, length_m, min_deg,
                                  max_deg))


def read_desired(path: _Path, tick_s: float) -> _Vector:
    """The desired motion in `path` on ticks of `tick_s`, as `plan --desired` reads it.

    Parameters
    ----------
    path : str or os.PathLike
        A CSV time_s,desired_deg (interpolated linearly), or a servo log (BAM .json, or the log
        CSV) whose requests are held from one sample to the next.
    tick_s : float
        The tick, s.

    Returns
    -------
    numpy.ndarray
        The desired angle of each tick, deg.

    Raises
    ------
    TypeError
        `path` not a path, `tick_s` not a number.
    ValueError
        No such file, its content (naming the row and column), a bad tick.
    """
    return _leglab._read_desired(path, _number(tick_s, "read_desired: tick_s"))


class _Columns(dict[str, Any]):
    """A dict of named arrays whose names are also attributes."""

    __slots__ = ()

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no '{name}' here (there are {', '.join(self)})") from None


__all__ = ["ServoLog", "read_log", "write_log", "fit", "ModelRung", "LogFit", "ServoModel", "plan",
           "ServoPlanner", "read_desired"]
