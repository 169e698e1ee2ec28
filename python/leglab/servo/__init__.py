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

Angles are in degrees and times in seconds; arrays are numpy float64. Bad input raises
ValueError with the programs' one-line message. See docs/real-servos.md ("From Python",
"Online") and examples/python/your_servo.py.
"""

import json as _json
import os as _os
import tempfile as _tempfile

import numpy as _np

from .. import _leglab
from .._leglab import ServoModel

ServoModel.__module__ = "leglab.servo"


# A log's arrays, named as leglab's CSV log names its columns (time, request, measured, torque).
_LOG_COLUMNS = _leglab._log_columns()


class ServoPlanner(_leglab.ServoPlanner):
    __doc__ = _leglab.ServoPlanner.__doc__

    def __init__(self, model, *args, **kwargs):
        if not isinstance(model, ServoModel):
            raise ValueError(f"ServoPlanner: expected a ServoModel (LogFit.model), got "
                             f"{type(model).__name__}")
        super().__init__(model, *args, **kwargs)

_META_KEYS = ("motor", "kp", "mass_kg", "length_m")


def _real_vector(values, what):
    array = _np.asarray(values)
    if array.dtype.kind not in "fiu":
        raise ValueError(f"{what}: expected real numbers, got dtype {array.dtype}")
    if array.ndim != 1:
        raise ValueError(f"{what}: expected a 1-D array, got shape {array.shape}")
    return _np.array(array, dtype=_np.float64, order="C", copy=True)  # not the caller's buffer


def _number(value, what):
    """`value` as a float; a TypeError naming `what` and the type given for anything that is not
    a real number (bool included), as the compiled module's own arguments."""
    if isinstance(value, (bool, _np.bool_)) or not isinstance(value, (int, float, _np.integer,
                                                                     _np.floating)):
        raise TypeError(f"{what}: expected a number, got {type(value).__name__}")
    return float(value)


class ServoLog:
    """A recorded run of one servo: what it was asked, what it did, and what it drove.

    Attributes (arrays of one length, one sample each):
        time_s: time stamps, s, strictly increasing.
        request_deg: the position request sent, deg.
        measured_deg: the position the servo reported, deg.
        torque_enabled: bool, False while the servo was limp (not scored, not fitted).
    and motor (the servo type: one model is fitted per type), kp (its gain register), mass_kg
    and length_m (the load: a point mass on an arm, 0 deg hanging straight down), trajectory
    (the request's shape: cross-validation leaves each one out in turn) and file (where it was
    read from, or its name: log_<motor>_<stem of file>.csv is what identify writes for it).

    Build one from your own recording:

        log = ServoLog(t, requests, measured, motor="my_servo", kp=32, mass_kg=0.2,
                       length_m=0.1, trajectory="sweep", file="sweep_1.csv")

    It is checked as identify checks a file: ValueError naming the sample and column.
    """

    def __init__(self, time_s, request_deg, measured_deg, torque_enabled=None, *, motor, kp,
                 mass_kg=0.0, length_m=0.0, trajectory="", file=""):
        time_s, request_deg, measured_deg = (
            _real_vector(value, name)
            for value, name in zip((time_s, request_deg, measured_deg), _LOG_COLUMNS))
        if torque_enabled is None:
            torque_enabled = _np.ones(time_s.shape, dtype=bool)
        else:
            torque = _np.asarray(torque_enabled)
            if torque.dtype.kind not in "biu" or (torque.dtype.kind != "b" and
                                                  not _np.isin(torque, (0, 1)).all()):
                raise ValueError(f"{_LOG_COLUMNS[3]}: expected booleans (or 0 and 1)")
            torque_enabled = _np.array(torque, dtype=bool, order="C", copy=True)
        for name, value in (("motor", motor), ("trajectory", trajectory), ("file", file)):
            if not isinstance(value, str):
                raise TypeError(f"{name}: expected a str, got {type(value).__name__}")
        self._fields = {
            "file": file or trajectory or "log", "motor": motor, "trajectory": trajectory,
            "kp": _number(kp, "kp"), "mass_kg": _number(mass_kg, "mass_kg"),
            "length_m": _number(length_m, "length_m"),
            **dict(zip(_LOG_COLUMNS, (time_s, request_deg, measured_deg, torque_enabled))),
        }
        _leglab._check_log(self._fields)

    @classmethod
    def _from_fields(cls, fields):
        log = cls.__new__(cls)
        log._fields = fields
        return log

    def __getattr__(self, name):
        fields = self.__dict__.get("_fields", {})
        if name in fields:
            return fields[name]
        raise AttributeError(name)

    def __len__(self):
        return len(self._fields[_LOG_COLUMNS[0]])

    def __repr__(self):
        f = self._fields
        return (f"ServoLog(file={f['file']!r}, motor={f['motor']!r}, kp={f['kp']!r}, "
                f"samples={len(self)})")


def read_log(path, format="auto", **meta):
    """The servo log at `path`: BAM's JSON (`.json`) or leglab's CSV (`.csv`), as identify reads
    it. format: "auto" (by extension), "csv" or "bam_json". A CSV log does not say its motor, kp,
    mass_kg and length_m: give them as keywords (a BAM log's own are used, and these ignored)."""
    if not isinstance(format, str):
        raise TypeError(f"read_log(): format: expected str ('auto', 'csv' or 'bam_json'), got "
                        f"{type(format).__name__}")
    unknown = sorted(set(meta) - set(_META_KEYS))
    if unknown:
        raise ValueError(f"read_log: unknown keyword {unknown[0]!r} (expected one of "
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


def write_log(log, path):
    """Writes `log` in leglab's CSV form (time_s,request_deg,measured_deg,torque_enabled; every
    number as the shortest text that reads back as the same double), all at once: a failed write
    leaves no file behind and an existing one as it was. `path` must be a new name or a regular
    file (ValueError otherwise: a link, folder, FIFO or device there is not replaced).
    read_log(path, motor=..., kp=..., mass_kg=..., length_m=...) reads it back to the same
    samples."""
    if not isinstance(log, ServoLog):
        raise ValueError(f"write_log: expected a ServoLog, got {type(log).__name__}")
    text = _leglab._log_csv_text(log._fields)
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

    Attributes:
        json: log_fit.json as a dict (models, cross_validate, folds, logs).
        markdown: log_fit.md's text.
        curves: {name: {column: array}}, the columns of each log_<name>.csv (time_s,
            request_deg, measured_deg, torque_enabled, direct_deg, best_shift_deg, paper_deg,
            extended_deg: the predictions held out where cross-validated); empty when loaded
            from a file.
        folds: the cross-validation's fits (json["folds"]).
        rows: every scored log, in sample and held out (json["logs"]): file, role,
            held_out_by, motor, trajectory, kp, ticks_scored, best_shift_s, mae_deg, rms_deg
            and plan.
        motors: the motors fitted.
    """

    def __init__(self, text, markdown="", curves=None, source="LogFit"):
        self._text = text
        self._source = source
        self.json = _json.loads(text)
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
        self.folds = self.json.get("folds", [])
        self.rows = self.json.get("logs", [])
        extended = self.json.get("models", {}).get("extended", {})
        self.motors = sorted(extended) if isinstance(extended, dict) else []

    @classmethod
    def load(cls, path):
        """The log_fit.json `identify` wrote (its models, folds and rows; no curves)."""
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

    def to_json(self):
        """log_fit.json's text, as identify writes it for the same logs and keys."""
        return self._text

    def model(self, motor=None, rung="extended"):
        """The fitted ServoModel of `motor` (None: the only one) and `rung` ("extended" or
        "paper")."""
        return _leglab._model_from_json(self._text, rung, motor or "", self._source)

    def __repr__(self):
        return (f"LogFit(motors={self.motors}, cross_validate={self.json.get('cross_validate')!r}"
                f", logs={len(self.rows)})")


class ModelRung:
    """A model rung of your own, fitted and scored beside the ladder's (``fit(..., rungs=)``).

    Args:
        name: its key in log_fit.json (mae_deg.<name>, models.<name>) and its CSV column
            (<name>_deg): a lower-case identifier no rung of the ladder has.
        fit: fit(recordings, tick_s) -> dict of float parameters by name: the model fitted to
            one motor's training logs (per fold when cross-validated). Each recording is a dict
            of arrays on the motor's tick (request_deg, measured_deg, driven) and its drive
            (kp, mass_kg, length_m).
        predict: predict(parameters, recording, tick_s) -> the angle at every tick of the
            recording (deg), open loop from its requests and, where a driven run begins, its
            measured angle.
        label, description, column: its table heading (default: the name with spaces), the
            phrase log_fit.md explains it by, its CSV column's description.

    Both functions are called from the fit's worker threads, one at a time (each holds the GIL).
    """

    def __init__(self, name, fit, predict, *, label=None, description=None, column=None):
        for what, value in (("name", name), ("label", label), ("description", description),
                            ("column", column)):
            if value is not None and not isinstance(value, str):
                raise TypeError(f"ModelRung: {what}: expected str, got {type(value).__name__}")
        for what, value in (("fit", fit), ("predict", predict)):
            if not callable(value):
                raise TypeError(f"ModelRung: {what}: expected a function, got "
                                f"{type(value).__name__}")
        self.name, self.fit, self.predict = name, fit, predict
        self.label = label or name.replace("_", " ")
        self.description = description or f"the rung {name}"
        self.column = column or f"the rung {name}'s prediction"

    def _fields(self):
        return (self.name, self.label, self.description, self.column, self.fit, self.predict)

    def __repr__(self):
        return f"ModelRung({self.name!r})"


def fit(config, overrides=None, *, validate=(), threads=0, rungs=()):
    """Fits and scores the model ladder on servo logs, as `identify` does with a `logs` section.

    Args:
        config: an experiment YAML file with a `logs` section (str or os.PathLike), or a list
            of ServoLog to fit on.
        overrides: a dict of config keys, as the programs' --set: {"logs.cross_validate":
            "none", "logs.iterations": 500}. With a list of logs, only logs.* keys.
        validate: ServoLogs to score the fitted models on, unchanged (with a list of logs).
        threads: worker threads, 0 for one per core; the numbers do not depend on it.
        rungs: ModelRungs of your own, fitted and scored after the ladder's, written as theirs.

    Returns a LogFit. Raises ValueError with identify's one-line message for a bad config,
    key or log.
    """
    extra = []
    for rung in rungs:
        if not isinstance(rung, ModelRung):
            raise TypeError(f"fit: rungs: expected ModelRung objects, got {type(rung).__name__}")
        extra.append(rung._fields())
    if isinstance(config, ServoLog):
        config = [config]
    if isinstance(config, (list, tuple)):
        given = []
        for role, logs in ((True, config), (False, validate)):
            for log in logs:
                if not isinstance(log, ServoLog):
                    raise ValueError(f"fit: expected ServoLog objects, got {type(log).__name__}")
                given.append((log._fields, role))
        parts = _leglab._fit(None, overrides, given, threads, extra)
    else:
        if validate:
            raise ValueError("fit: validate= goes with a list of logs; a config names its "
                             "validation logs in logs.validate")
        parts = _leglab._fit(config, overrides, [], threads, extra)
    curves = {c.pop("name"): c for c in parts["curves"]}
    return LogFit(parts["json"], parts["markdown"], curves)


def plan(model, desired_deg, method="model_based", *, kp=None, mass_kg=0.0, length_m=0.0,
         min_deg=-180.0, max_deg=180.0):
    """Requests for `model` to follow `desired_deg` (one angle a tick of model.tick_s, deg), as
    the `plan` program computes them.

    method: "model_based" (the model inverted along the path) or "optimal" (least squared
    predicted error). kp, mass_kg, length_m: the servo's gain register and load (kp required
    for the extended rung). Requests stay in [min_deg, max_deg] and change at most at the
    model's top speed.

    Returns a dict of arrays: the columns of plan's requests.csv (time_s, desired_deg,
    request_deg, predicted_deg, beyond_servo) and direct_deg, the model's prediction with the
    desired angles sent as they are. Each is also an attribute: plan(...).request_deg.
    """
    if not isinstance(model, ServoModel):
        raise ValueError(f"plan: expected a ServoModel (LogFit.model), got {type(model).__name__}")
    if not isinstance(method, str):
        raise TypeError(f"plan(): method: expected str ('model_based' or 'optimal'), got "
                        f"{type(method).__name__}")
    return _Columns(_leglab._plan(model, desired_deg, method, kp, mass_kg, length_m, min_deg,
                                  max_deg))


def read_desired(path, tick_s):
    """The desired motion in `path` on ticks of `tick_s` (s), deg, as `plan --desired` reads
    it: a CSV time_s,desired_deg interpolated linearly, or a servo log (BAM .json, or the log
    CSV) whose requests are held from one sample to the next. ValueError naming the file, row
    and column."""
    return _leglab._read_desired(path, _number(tick_s, "read_desired: tick_s"))


class _Columns(dict):
    """A dict of named arrays whose names are also attributes."""

    __slots__ = ()

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no '{name}' here (there are {', '.join(self)})") from None


__all__ = ["ServoLog", "read_log", "write_log", "fit", "ModelRung", "LogFit", "ServoModel", "plan",
           "ServoPlanner", "read_desired"]
