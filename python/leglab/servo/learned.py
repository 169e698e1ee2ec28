"""The learned rungs of the servo model ladder, held out as identify holds out the others.

    python3 -m leglab.servo.learned RUN [RUN ...] [--out DIR] [--size full|small]
                                    [--jobs N] [--learning-curve MOTOR]

RUN is a folder `identify` wrote with a `logs` section: its log_fit.json (the folds and every
scored log) and log_<motor>_<log>.csv (each log resampled to its servo's tick, torque_enabled
marking the driven ticks). For each of identify's models (the final one per motor and one per
fold) two networks are trained with PyTorch on exactly that model's training logs and scored on
the same logs as the other rungs, with the same mean absolute error over the driven ticks:

- mlp: Hwangbo et al. (2019)'s actuator network: the last N request-minus-angle errors and
  angle velocities, the gain kp and the load's torque (m g L sin M, m g L cos M) in, the next
  tick's angle change out (two hidden layers, tanh).
- lstm: Rudin et al. (2022)'s form: at each tick the request-minus-angle error, the angle
  velocity, kp and the load in, the angle change out, an LSTM's state carrying the history.

Both are rolled out open loop from each run of driven ticks (the first tick's measured angle
at rest, then the network's own angles fed back), as the other rungs are scored. Training is
teacher forcing first (the next change from the measured history), then the angle error of
short open-loop rollouts from measured starts, so that a network learns what its own errors do.
N and the width are chosen per model on its own training logs: each is trained on the first
75 % of every training log and scored open loop on the rest, the best kept and trained again on
all of them. The seed is fixed and each training runs on one thread: the same numbers every
run, whatever --jobs.

Writes learned_fit.json (the folds and each log's MAEs beside identify's rungs) and
learned_fit.md into each RUN (or --out, with one RUN); --learning-curve MOTOR adds the mlp
trained on every subset of the motor's other groups, for each held-out group. Needs PyTorch
(Debian: python3-torch), imported only when a network is trained; each log's load is read with
leglab.servo.read_log. (--build, which once named the package's folder, is accepted with no
effect.)

Bad input (a run that is not identify's: a field it reads missing or of another type, a number
or a cell that is not finite, a log with nothing to train on or score; an --out it cannot write)
is refused before any training: one line, exit status 2. A result that is not finite is a bug:
one line, exit status 1. Either way nothing is written.
"""

from __future__ import annotations

import csv
import importlib
import itertools
import json
import math
import multiprocessing
import os
import pathlib
import sys
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from .. import data_dir
from ..ladder import LADDER
from ..results.reader import (ArgumentParser, non_finite_field, one_line, read_finite_columns,
                              read_json, write_all_or_nothing)
from . import read_log

__all__ = ["SIZES", "Bug", "UserError", "cli", "curve_jobs", "main", "model_jobs", "score",
           "train"]

GRAVITY = 9.81  # m/s^2, as the extended model's

# Training sizes: "full" for the results, "small" for the tests (seconds a model).
SIZES = {
    "full": {"teacher_steps": 600, "teacher_batch": 32, "piece": 64, "steps": 150, "batch": 64,
             "window": 32, "grid_mlp": [(4, 16), (4, 32), (8, 16), (8, 32)],
             "grid_lstm": [(1, 32)], "curve_mlp": (4, 32)},
    "small": {"teacher_steps": 50, "teacher_batch": 16, "piece": 16, "steps": 30, "batch": 16,
              "window": 16, "grid_mlp": [(2, 8)], "grid_lstm": [(1, 8)], "curve_mlp": (2, 8)},
}
SEED = 20261128
LOAD_SCALE_NM = 0.5  # the loads' torques divided by this before they go in

# A log as read_run() reads it: its resampled `request`, `measured` and `driven` columns, `kp`,
# `load_nm`, `tick_s`, its log_fit.json `row` and the run's `cross_validate`.
_Log = Mapping[str, Any]
# A model's job: (motor, held-out group or None for the final model, training files, scored
# files).
_Job = tuple[str, Optional[str], list[str], list[str]]
# run_job's arguments: (job, {file: log}, training size, the forms trained).
_JobArguments = tuple[_Job, dict[str, _Log], Mapping[str, Any], tuple[str, ...]]
# The input and output scales: (error deg, velocity deg/tick, output deg/tick).
_Scale = tuple[float, float, float]
# A torch tensor (or module): torch is imported only when a network is trained.
_Tensor = Any
_Vector = npt.NDArray[np.float64]
_PathLike = Union[str, "os.PathLike[str]"]


class UserError(Exception):
    """Bad input: one line, exit status 2."""


class Bug(Exception):
    """A result this script never writes (a number that is not finite, from valid input): one
    line, exit status 1."""


# --- the logs, as identify resampled them ---------------------------------------------------

def _load_torque_nm(row: Mapping[str, Any]) -> float:
    """m g L of the log `row` names (its file, read by leglab as identify read it; a relative
    name not found here is looked for in leglab's data folder, data/servo_logs/...)."""
    path = pathlib.Path(row["file"])
    if not path.exists() and (pathlib.Path(data_dir()) / path).exists():
        path = pathlib.Path(data_dir()) / path
    try:
        log = read_log(str(path))
    except ValueError as e:
        raise UserError(f"{row['file']}: {e}") from None
    return log.mass_kg * GRAVITY * log.length_m


def expect(value: Any, kinds: tuple[type, ...], where: str) -> Any:
    """`value` when it is one of `kinds` (a bool is no number); UserError naming `where`
    otherwise."""
    if isinstance(value, bool) and bool not in kinds or not isinstance(value, kinds):
        raise UserError(f"{where}: expected {' or '.join(k.__name__ for k in kinds)}, got "
                        f"{type(value).__name__}")
    return value


NUMBER = (int, float)
# identify's rungs and the learned ones, in the ladder's order (servo/ladder.json).
RUNGS = tuple(r.name for r in LADDER if r.kind != "learned")
LEARNED_RUNGS = tuple(r.name for r in LADDER if r.kind == "learned")


def check_fit(path: pathlib.Path, fit: Mapping[str, Any]) -> None:
    """identify's log fit at `path` as this script reads it: every number finite, and each
    field it reads there and of its type; UserError naming the file and the field otherwise."""
    where = f"{path}:"
    field = non_finite_field(fit)
    if field is not None:
        raise UserError(f"{where} {field} is not a finite number")
    models = expect(expect(fit.get("models"), (dict,), f"{where} models").get("extended"),
                    (dict,), f"{where} models.extended")
    for motor, model in models.items():
        expect(expect(model, (dict,), f"{where} models.extended.{motor}").get("tick_s"),
               NUMBER, f"{where} models.extended.{motor}: its tick")
    expect(fit.get("cross_validate"), (str,), f"{where} cross_validate")
    for i, fold in enumerate(expect(fit.get("folds"), (list,), f"{where} folds")):
        expect(expect(fold, (dict,), f"{where} folds[{i}]").get("motor"), (str,),
               f"{where} folds[{i}].motor")
        expect(fold.get("held_out"), (str,) + NUMBER, f"{where} folds[{i}].held_out")
    logs = expect(fit.get("logs"), (list,), f"{where} logs")
    for i, row in enumerate(logs):
        at = f"{where} logs[{i}]"
        expect(row, (dict,), at)
        for name, kinds in (("file", (str,)), ("role", (str,)), ("held_out_by", (str,)),
                            ("motor", (str,)), ("trajectory", (str,)), ("kp", NUMBER),
                            ("ticks_scored", NUMBER), ("mae_deg", (dict,))):
            expect(row.get(name), kinds, f"{at}.{name}")
        for rung in RUNGS:
            expect(row["mae_deg"].get(rung), NUMBER, f"{at}.mae_deg.{rung}")
        if row["motor"] not in models:
            raise UserError(f"{at}.motor: '{row['motor']}' has no model in models.extended")
    if not any(row["role"] == "train" for row in logs):
        raise UserError(f"{where} logs: no log with the role train")


def read_run(run: _PathLike) -> tuple[dict[str, Any], dict[str, _Log]]:
    """identify's run in folder `run`: (log_fit.json as a dict, {file: log}) where a log holds
    its resampled request, measured and driven columns, kp, load and tick. UserError, before
    any training, when it is not one."""
    folder = pathlib.Path(run)
    path = folder / "log_fit.json"
    try:
        fit = read_json(path)  # checked against its declared fields
        if not isinstance(fit, dict):
            raise ValueError(f"expected a JSON object, got {type(fit).__name__}")
    except OSError as e:
        raise UserError(f"{path}: cannot be read ({e.strerror or e})") from None
    except (UnicodeDecodeError, ValueError, RecursionError) as e:
        raise UserError(f"{path}: not identify's log fit ({e})") from None
    check_fit(path, fit)
    rows, models = fit["logs"], fit["models"]["extended"]
    logs: dict[str, _Log] = {}
    for row in rows:
        if row["file"] in logs:
            continue
        name = f"log_{row['motor']}_{pathlib.Path(row['file']).stem}.csv"
        try:
            table = read_finite_columns(folder / name)  # its declared columns, finite numbers
            request, measured = np.array(table.request_deg), np.array(table.measured_deg)
            driven = np.array(table.torque_enabled) == 1
        except (OSError, UnicodeDecodeError, ValueError, AttributeError, csv.Error) as e:
            text = str(e)
            raise UserError(text if text.startswith(str(folder / name)) else
                            f"{folder / name}: cannot read its columns ({text})") from None
        logs[row["file"]] = {
            "request": request, "measured": measured, "driven": driven,
            "kp": float(row["kp"]), "load_nm": _load_torque_nm(row),
            "tick_s": float(models[row["motor"]]["tick_s"]), "row": row,
            "cross_validate": fit.get("cross_validate", "none"),
        }
    return fit, logs


def trainable(log: _Log) -> bool:
    """Whether `log` holds a run of 2 driven ticks or more in its first 75 % (what fit_form's
    grid trains on)."""
    first = log["driven"][:int(len(log["driven"]) * 0.75)]
    return any(end - start >= 2 for start, end in runs_of(first))


def check_jobs(run: str, jobs: Iterable[_Job], logs: Mapping[str, _Log]) -> None:
    """Refuses, before any training, a model whose training logs hold no run of 2 driven ticks
    in their first 75 % (nothing to train on) or a scored log without a driven tick (nothing to
    score)."""
    for motor, held_out, train_files, scored_files in jobs:
        model = f"{run}: {motor}'s model" + (f" holding out {held_out}" if held_out else "")
        if not any(trainable(logs[f]) for f in train_files):
            raise UserError(f"{model}: no run of 2 driven ticks in its training logs")
        for f in scored_files:
            if not logs[f]["driven"].any():
                raise UserError(f"{model}: {f} has no driven tick to score")


def fold_key(row: Mapping[str, Any], cross_validate: str) -> str:
    """What identify's fold of `row` is called (its `held_out`)."""
    if cross_validate == "leave_one_trajectory_out":
        return row["trajectory"]
    return f"kp {row['kp']:g}"


def model_jobs(fit: Mapping[str, Any]) -> list[_Job]:
    """Every model identify fitted, as the networks are trained for it.

    Parameters
    ----------
    fit : mapping
        A log_fit.json, parsed and checked (read_run()).

    Returns
    -------
    list of tuple
        (motor, held_out, training files, scored files) per model: held_out None for the final
        model of each motor (scored on its training logs: in sample), else the fold's held-out
        group.
    """
    cv = fit["cross_validate"]
    train = [r for r in fit["logs"] if r["role"] == "train"]
    motors = sorted({r["motor"] for r in train})
    jobs: list[_Job] = [(m, None, [r["file"] for r in train if r["motor"] == m],
                        [r["file"] for r in train if r["motor"] == m]) for m in motors]
    for fold in fit["folds"]:
        held = str(fold["held_out"])
        mine = [r for r in train if r["motor"] == fold["motor"]]
        jobs.append((fold["motor"], held, [r["file"] for r in mine if fold_key(r, cv) != held],
                     [r["file"] for r in mine if fold_key(r, cv) == held]))
    return jobs


# --- the networks and their open-loop rollout ------------------------------------------------

def make_net(form: str, history: int, width: int) -> _Tensor:
    import torch
    inputs = 2 * history + 3
    if form == "mlp":
        return torch.nn.Sequential(torch.nn.Linear(inputs, width), torch.nn.Tanh(),
                                   torch.nn.Linear(width, width), torch.nn.Tanh(),
                                   torch.nn.Linear(width, 1))
    return torch.nn.ModuleDict({"lstm": torch.nn.LSTM(inputs, width),
                                "out": torch.nn.Linear(width, 1)})


def features_of(errors: _Tensor, velocities: _Tensor, drive: _Tensor, angle: _Tensor) -> _Tensor:
    """A tick's inputs (scaled): the errors and velocities, kp and the load's torque at `angle`
    (deg); drive holds kp and m g L."""
    import torch
    radians = angle * (math.pi / 180.0)
    load = drive[..., 1:2] / LOAD_SCALE_NM
    return torch.cat([errors, velocities, drive[..., :1] / 1000.0, load * torch.sin(radians),
                      load * torch.cos(radians)], dim=-1)


def step(net: _Tensor, form: str, features: _Tensor, state: Any) -> tuple[_Tensor, Any]:
    """The network's scaled angle change for `features` (and the LSTM's state after it)."""
    if form == "mlp":
        return net(features), None
    output, state = net["lstm"](features.unsqueeze(0), state)
    return net["out"](output[0]), state


def rollout(net: _Tensor, form: str, history: int, scale: _Scale, requests: _Tensor, angles: _Tensor,
            drive: _Tensor, steps: int) -> _Tensor:
    """Open-loop angles for `steps` ticks after the start, a batch at once.

    requests: (B, history + steps) tensor, R(s - history + 1 .. s + steps); angles: (B,
    history + 1), the angles M(s - history .. s) the rollout starts from; drive: (B, 2), kp and
    m g L. Returns (B, steps): M(s + 1 .. s + steps), each tick's input built from the
    network's own angles. scale: (error deg, velocity deg/tick, output deg/tick).
    """
    import torch
    error_scale, velocity_scale, output_scale = scale
    state = None
    predicted = []
    for k in range(steps):
        last = angles[:, -1:]
        errors = (requests[:, k:k + history] - angles[:, 1:]) / error_scale
        velocities = (angles[:, 1:] - angles[:, :-1]) / velocity_scale
        change, state = step(net, form, features_of(errors, velocities, drive, last), state)
        angle = last + output_scale * change
        predicted.append(angle)
        angles = torch.cat([angles[:, 1:], angle], dim=1)
    return torch.cat(predicted, dim=1)


def runs_of(driven: npt.NDArray[np.bool_]) -> list[tuple[int, int]]:
    """[(start, end)) of each run of driven ticks."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], driven.astype(int), [0]])))
    return list(zip(edges[0::2], edges[1::2]))


def start_window(log: _Log, start: int, history: int, steps: int,
                 at_rest: bool) -> tuple[_Vector, _Vector]:
    """Requests and start angles of a rollout from tick `start` (see rollout): the requests
    before tick 0 are R(0); the angles before the start are the measured ones, or the start's
    own (at rest) when the rollout begins a run, as the other rungs begin it."""
    index = np.clip(np.arange(start - history + 1, start + steps + 1), 0, len(log["request"]) - 1)
    requests = log["request"][index][:history + steps]
    if at_rest:
        angles = np.full(history + 1, log["measured"][start])
    else:
        angles = log["measured"][np.clip(np.arange(start - history, start + 1), 0, None)]
    return requests, angles


def predict_runs(net: _Tensor, form: str, history: int, scale: _Scale, log: _Log,
                 runs: Sequence[tuple[int, int]]) -> _Vector:
    """The network's open-loop prediction over each of `runs`, every run at once (padded)."""
    import torch
    predicted = np.array(log["measured"], dtype=float)
    longest = max((end - start for start, end in runs), default=0)
    if longest <= 1:  # no run has a tick after its first: nothing to predict
        return predicted
    requests: list[_Vector] = []
    angles: list[_Vector] = []
    for start, end in runs:
        r, a = start_window(log, start, history, longest - 1, at_rest=True)
        requests.append(r)
        angles.append(a)
    drive = torch.tensor([[log["kp"], log["load_nm"]]] * len(runs), dtype=torch.float64)
    with torch.no_grad():
        out = rollout(net, form, history, scale, torch.tensor(np.array(requests)),
                      torch.tensor(np.array(angles)), drive, longest - 1).numpy()
    for i, (start, end) in enumerate(runs):
        predicted[start + 1:end] = out[i, :end - start - 1]
    return predicted


def score(net: Any, form: str, history: int, scale: _Scale, log: _Log,
          begin: int = 0) -> tuple[float, _Vector]:
    """A network's open-loop prediction of a log, scored as identify scores a log.

    Runs of driven ticks start at rest on their first tick's measured angle; then the network's
    own angles are fed back.

    Parameters
    ----------
    net : torch.nn.Module
        train()'s network.
    form : str
        "mlp" or "lstm".
    history : int
        The ticks of history the network takes (the mlp's N).
    scale : tuple of 3 floats
        train()'s input and output scales.
    log : mapping
        A log as read_run() reads it: `request`, `measured`, `driven`, `kp`, `load_nm`.
    begin : int
        Score the driven ticks from this tick on.

    Returns
    -------
    mae_deg : float
        The mean absolute error over the scored driven ticks, deg.
    predicted : numpy.ndarray
        The predicted angle at every tick, deg.
    """
    driven = log["driven"].copy()
    driven[:begin] = False
    runs = runs_of(driven)
    predicted = predict_runs(net, form, history, scale, log, runs)
    return float(np.mean(np.abs(predicted[driven] - log["measured"][driven]))), predicted


# --- training --------------------------------------------------------------------------------

def windows(logs: Iterable[_Log], history: int, steps: int,
            end_share: float) -> list[tuple[_Log, int, int]]:
    """Every training rollout start: (log, tick, end of its run) with `steps` ticks after it
    inside one run of driven ticks (fewer where the run is shorter) and inside the first
    `end_share` of the log."""
    starts: list[tuple[_Log, int, int]] = []
    for log in logs:
        limit = int(len(log["measured"]) * end_share)
        for start, end in runs_of(log["driven"][:limit]):
            starts += [(log, s, end) for s in range(start, max(start + 1, end - steps))]
    return starts


def scales(logs: Sequence[_Log]) -> _Scale:
    """Input and output scales from the training logs' measured motion (deg, deg/tick)."""
    errors = np.concatenate([(l["request"] - l["measured"])[l["driven"]] for l in logs])
    steps = np.concatenate([np.diff(l["measured"])[l["driven"][1:]] for l in logs])
    return (float(np.std(errors)) or 1.0, float(np.std(steps)) or 1.0,
            float(np.std(steps)) or 1.0)


def batch_of(starts: Sequence[tuple[_Log, int, int]], picks: Iterable[int], history: int,
             steps: int) -> list[_Tensor]:
    """A batch of rollouts from `starts[picks]`: (requests, start angles, target angles, the
    targets' mask, drive) as rollout takes them and the loss compares."""
    import torch
    requests: list[_Vector] = []
    angles: list[_Vector] = []
    targets: list[_Vector] = []
    masks: list[_Vector] = []
    drive: list[list[float]] = []
    for i in picks:
        log, start, run_end = starts[i]
        r, a = start_window(log, start, history, steps, at_rest=False)
        end = min(start + steps + 1, run_end)  # the loss never reaches past the run
        target = np.zeros(steps)
        target[:end - start - 1] = log["measured"][start + 1:end]
        mask = np.zeros(steps)
        mask[:end - start - 1] = 1.0
        requests.append(r)
        angles.append(a)
        targets.append(target)
        masks.append(mask)
        drive.append([log["kp"], log["load_nm"]])
    return [torch.tensor(np.array(x), dtype=torch.float64)
            for x in (requests, angles, targets, masks, drive)]


def teacher_pieces(logs: Iterable[_Log], history: int, scale: _Scale, length: int,
                   end_share: float) -> tuple[_Tensor, _Tensor, _Tensor]:
    """Teacher-forced training data: every run of driven ticks (in the first `end_share` of its
    log) cut into pieces of `length` ticks; each tick's inputs built from the measured angles as
    a rollout builds them from its own, and its target the measured next change (scaled).
    Returns inputs (P, length, F), targets and masks (P, length)."""
    import torch
    error_scale, velocity_scale, output_scale = scale
    inputs: list[_Tensor] = []
    targets: list[_Vector] = []
    masks: list[_Vector] = []
    for log in logs:
        m, r = log["measured"], log["request"]
        limit = int(len(m) * end_share)
        for start, end in runs_of(log["driven"][:limit]):
            for piece in range(start, end - 1, length):
                ticks = np.arange(piece, piece + length)
                valid = ticks < end - 1
                ticks = np.minimum(ticks, end - 2)
                back = np.clip(ticks[:, None] + np.arange(-history + 1, 1)[None, :], 0, None)
                errors = (r[back] - m[back]) / error_scale
                velocities = (m[back] - m[np.maximum(back - 1, 0)]) / velocity_scale
                drive = np.tile([log["kp"], log["load_nm"]], (length, 1))
                inputs.append(features_of(torch.tensor(errors), torch.tensor(velocities),
                                          torch.tensor(drive), torch.tensor(m[ticks])[:, None]))
                targets.append((m[ticks + 1] - m[ticks]) / output_scale)
                masks.append(valid.astype(float))
    return (torch.stack(inputs), torch.tensor(np.array(targets)),
            torch.tensor(np.array(masks)))


def pretrain(net: _Tensor, form: str, pieces: tuple[_Tensor, _Tensor, _Tensor],
             size: Mapping[str, Any], rng: np.random.Generator) -> None:
    """Teacher forcing: the next change from measured history, the quick first fit (Hwangbo et
    al. train so), before the rollouts teach the network its own errors."""
    import torch
    inputs, targets, masks = pieces
    optimiser = torch.optim.Adam(net.parameters(), lr=3e-3)
    for _ in range(size["teacher_steps"]):
        picks = torch.as_tensor(rng.integers(0, len(inputs), size["teacher_batch"]))
        x = inputs[picks]
        if form == "mlp":
            change = net(x)[..., 0]
        else:
            output, _ = net["lstm"](x.transpose(0, 1))
            change = net["out"](output)[..., 0].transpose(0, 1)
        mask = masks[picks]
        loss = (mask * (change - targets[picks]) ** 2).sum() / mask.sum().clamp(min=1.0)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()


def train(form: str, history: int, width: int, logs: Sequence[Mapping[str, Any]],
          size: Mapping[str, Any], seed: int, end_share: float = 1.0) -> tuple[Any, _Scale]:
    """A network trained on logs: teacher forcing, then open-loop rollouts.

    Teacher forcing first (pretrain), then Adam on the mean squared angle error of open-loop
    rollouts of `size['window']` ticks from measured starts. Imports torch.

    Parameters
    ----------
    form : str
        "mlp" or "lstm".
    history : int
        The ticks of history the network takes.
    width : int
        The hidden layers' width.
    logs : sequence of mapping
        Logs as read_run() reads them.
    size : mapping
        The training size, one of SIZES' values.
    seed : int
        The seed of torch and numpy: the same seed, the same network.
    end_share : float
        Train on this first share of each log (the rest is held out to choose N and the width).

    Returns
    -------
    net : torch.nn.Module
        The trained network (float64).
    scale : tuple of 3 floats
        The scales its inputs are divided by and its output multiplied by: (error deg,
        velocity deg/tick, output deg/tick).
    """
    import torch
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    net = make_net(form, history, width).double()
    scale = scales(logs)
    steps = size["window"]
    pretrain(net, form, teacher_pieces(logs, history, scale, size["piece"], end_share), size, rng)
    starts = windows(logs, history, steps, end_share)
    optimiser = torch.optim.Adam(net.parameters(), lr=1e-3)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimiser, size["steps"])
    for _ in range(size["steps"]):
        picks = rng.integers(0, len(starts), size["batch"])
        requests, angles, targets, masks, drive = batch_of(starts, picks, history, steps)
        predicted = rollout(net, form, history, scale, requests, angles, drive, steps)
        loss = (masks * (predicted - targets) ** 2).sum() / masks.sum().clamp(min=1.0)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        schedule.step()
    return net, scale


def parameter_count(net: _Tensor) -> int:
    """The network's number of trained parameters."""
    return int(sum(p.numel() for p in net.parameters()))


def fit_form(form: str, logs: Sequence[_Log], size: Mapping[str, Any],
             seed: int) -> tuple[_Tensor, _Scale, int, dict[str, Any]]:
    """The form's network for `logs`: each (history, width) of the grid trained on the first
    75 % of every log and scored open loop on the rest; the best trained again on all (a grid of
    one is trained on all at once)."""
    grid = size["grid_mlp"] if form == "mlp" else size["grid_lstm"]
    tried: list[tuple[float, int, int]] = []
    for history, width in grid if len(grid) > 1 else []:
        net, scale = train(form, history, width, logs, size, seed, end_share=0.75)
        errors = [score(net, form, history, scale, log, int(len(log["measured"]) * 0.75))[0]
                  for log in logs if log["driven"][int(len(log["measured"]) * 0.75):].any()]
        tried.append((float(np.mean(errors)), history, width))
    validation, history, width = min(tried) if tried else (None, *grid[0])
    net, scale = train(form, history, width, logs, size, seed)
    chosen = {"history_ticks": history, "width": width, "parameters": parameter_count(net),
              "validation_mae_deg": validation,
              "grid": [{"history_ticks": h, "width": w, "validation_mae_deg": e}
                       for e, h, w in tried]}
    return net, scale, history, chosen


def curve_jobs(fit: Mapping[str, Any], motor: str) -> list[_Job]:
    """The learning curve's models for a motor.

    For each of the motor's cross-validation groups held out, one model trained on every subset
    of k of the other groups (k = 1 .. all), scored on the held-out group's logs.

    Parameters
    ----------
    fit : mapping
        A log_fit.json, parsed and checked.
    motor : str
        The motor (log_fit.json's `motor`).

    Returns
    -------
    list of tuple
        (motor, held-out group, training files, scored files) per model.

    Raises
    ------
    UserError
        When the motor has fewer than 3 cross-validation groups.
    """
    cv = fit["cross_validate"]
    train = [r for r in fit["logs"] if r["role"] == "train" and r["motor"] == motor]
    groups = sorted({fold_key(r, cv) for r in train})
    if len(groups) < 3:
        raise UserError(f"--learning-curve {motor}: needs a motor with at least 3 cross-"
                        f"validation groups in the run, got {len(groups)}")
    jobs: list[_Job] = []
    for held in groups:
        others = [g for g in groups if g != held]
        for k in range(1, len(others) + 1):
            for subset in itertools.combinations(others, k):
                jobs.append((motor, held, [r["file"] for r in train if fold_key(r, cv) in subset],
                             [r["file"] for r in train if fold_key(r, cv) == held]))
    return jobs


def run_job(arguments: _JobArguments) -> dict[str, Any]:
    """One of identify's models: `forms` trained on its training logs, scored on its logs."""
    job, logs, size, forms = arguments
    import torch
    torch.set_num_threads(1)
    torch.use_deterministic_algorithms(True)
    motor, held_out, train_files, scored_files = job
    result: dict[str, Any] = {"motor": motor, "held_out": held_out, "forms": {}, "mae_deg": {},
                              "curves": {}}
    training = [logs[f] for f in train_files]
    for form in forms:
        net, scale, history, chosen = fit_form(form, training, size, SEED)
        result["forms"][form] = chosen
        for f in scored_files:
            mae, predicted = score(net, form, history, scale, logs[f])
            result["mae_deg"].setdefault(f, {})[form] = mae
            result["curves"].setdefault(f, {})[form] = predicted
    result["training_ticks"] = int(sum(l["driven"].sum() for l in training))
    result["trained_on"] = sorted({fold_key(l["row"], l["cross_validate"]) for l in training})
    return result


# --- output ----------------------------------------------------------------------------------

def rows_of(fit: Mapping[str, Any],
            results: Iterable[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """identify's scored rows with the learned rungs' MAEs beside its own."""
    learned: dict[tuple[str, str], Any] = {}
    for r in results:
        role = "train" if r["held_out"] is None else "validate"
        for f, maes in r["mae_deg"].items():
            learned[(f, role)] = maes
    rows: list[dict[str, Any]] = []
    for row in fit["logs"]:
        maes = dict(row["mae_deg"])
        maes.update(learned.get((row["file"], row["role"]), {}))
        rows.append({k: row[k] for k in ("file", "role", "held_out_by", "motor", "trajectory",
                                         "kp", "ticks_scored")} | {"mae_deg": maes})
    return rows


def markdown(fit: Mapping[str, Any], rows: Sequence[Mapping[str, Any]],
             folds: Iterable[Mapping[str, Any]]) -> str:
    """learned_fit.md: the scored logs' MAEs per rung, held out and in sample, and the models."""
    rungs = [*RUNGS, *LEARNED_RUNGS]
    lines = ["# Servo logs: the learned rungs beside identify's (mean absolute error, deg)", "",
             f"Cross-validation: {fit['cross_validate']}. mlp: Hwangbo et al.'s actuator "
             "network; lstm: Rudin et al.'s; both rolled out open loop as the other rungs. "
             "validate rows are held out.", ""]
    for role, title in (("validate", "Held out"), ("train", "In sample (the final models)")):
        lines += [f"## {title}", "", "| log | motor | kp | " + " | ".join(rungs) + " |",
                  "|---|---|---|" + "---|" * len(rungs)]
        chosen = [r for r in rows if r["role"] == role]
        for r in chosen:
            name = pathlib.Path(r["file"]).stem
            lines.append(f"| {name} | {r['motor']} | {r['kp']:g} | " +
                         " | ".join(f"{r['mae_deg'][k]:.2f}" for k in rungs) + " |")
        for motor in sorted({r["motor"] for r in chosen}):
            mine = [r for r in chosen if r["motor"] == motor]
            lines.append(f"| **mean** | **{motor}** | | " + " | ".join(
                f"**{np.mean([r['mae_deg'][k] for r in mine]):.2f}**" for k in rungs) + " |")
        lines.append("")
    lines += ["## Models", "", "| motor | held out | training ticks | mlp (N, width, parameters) "
              "| lstm (width, parameters) |", "|---|---|---|---|---|"]
    for f in folds:
        m, l = f["mlp"], f["lstm"]
        lines.append(f"| {f['motor']} | {f['held_out'] or 'none (final)'} | "
                     f"{f['training_ticks']} | {m['history_ticks']}, {m['width']}, "
                     f"{m['parameters']} | {l['width']}, {l['parameters']} |")
    return "\n".join(lines) + "\n"


def curve_points(curve: Iterable[Mapping[str, Any]]) -> tuple[list[dict[str, Any]], str]:
    """The learning curve's models as JSON, and its table: the mean held-out MAE by the number
    of groups trained on."""
    points = [{"motor": r["motor"], "held_out": r["held_out"], "trained_on": r["trained_on"],
               "groups": len(r["trained_on"]), "training_ticks": r["training_ticks"],
               "mae_deg": {pathlib.Path(f).stem: m["mlp"] for f, m in r["mae_deg"].items()}}
              for r in curve]
    lines = ["## Learning curve (mlp, N and width fixed)", "",
             "| groups trained on | models | mean training ticks | mean held-out MAE (deg) |",
             "|---|---|---|---|"]
    for k in sorted({p["groups"] for p in points}):
        mine = [p for p in points if p["groups"] == k]
        lines.append(f"| {k} | {len(mine)} | "
                     f"{np.mean([p['training_ticks'] for p in mine]):.0f} | " +
                     f"{np.mean([np.mean(list(p['mae_deg'].values())) for p in mine]):.2f} |")
    return points, "\n".join(lines) + "\n"


def outputs(out: pathlib.Path, fit: Mapping[str, Any], results: Sequence[Mapping[str, Any]],
            curve: Sequence[Mapping[str, Any]]) -> dict[_PathLike, str]:
    """{path: text} of learned_fit.json and learned_fit.md in `out`; Bug when a number in them
    is not finite (training on checked input never gives one)."""
    folds = [{"motor": r["motor"], "held_out": r["held_out"],
              "training_ticks": r["training_ticks"]} | r["forms"] for r in results]
    rows = rows_of(fit, results)
    document: dict[str, Any] = {"cross_validate": fit["cross_validate"], "seed": SEED,
                                "folds": folds, "logs": rows}
    text = markdown(fit, rows, folds)
    if curve:
        document["learning_curve"], table = curve_points(curve)
        text += "\n" + table
    field = non_finite_field(document)
    if field is not None:
        raise Bug(f"{out}: the result {field} is not a finite number; nothing written")
    return {out / "learned_fit.json": json.dumps(document, indent=2) + "\n",
            out / "learned_fit.md": text}


def write_outputs(texts: Mapping[_PathLike, str]) -> None:
    """Writes {path: text}, all or none (write_all_or_nothing)."""
    try:
        write_all_or_nothing(texts)
    except OSError as e:
        raise UserError(f"--out '{e.filename}': cannot write ({e.strerror})") from None


def check_out(out: pathlib.Path) -> None:
    """Refuses, before any training, an --out that could not be written: its nearest existing
    folder must be a writable folder, and no folder in the place of an output."""
    existing = out
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise UserError(f"--out '{out}': '{existing}' is not a folder it can write in")
    for name in ("learned_fit.json", "learned_fit.md"):
        if (out / name).is_dir() or (out / (name + ".partial")).is_dir():
            raise UserError(f"--out '{out}': {name} is a folder")


def main(argv: Sequence[str] | None = None) -> None:
    """The command, its errors raised: ``python3 -m leglab.servo.learned RUN [RUN ...] [--out DIR]
    [--size full|small] [--jobs N] [--learning-curve MOTOR]``.

    Every run is read and checked before any training; learned_fit.json and learned_fit.md are
    written into each RUN (or --out) after all of them, all or none.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default sys.argv[1:]).

    Raises
    ------
    UserError
        Bad input, or PyTorch missing: nothing written.
    Bug
        A result that is not finite: nothing written.
    SystemExit
        Status 2 on a usage error.
    """
    parser = ArgumentParser(prog="learned_fit", description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", metavar="RUN",
                        help="folders identify wrote with a logs section")
    parser.add_argument("--out", help="where learned_fit.json and .md go (default: the RUN; "
                        "with one RUN only)")
    parser.add_argument("--size", choices=sorted(SIZES), default="full")
    parser.add_argument("--build", default="build",
                        help="accepted for old command lines, no effect: the leglab package is "
                             "the one this module is part of")
    parser.add_argument("--jobs", type=int, default=0,
                        help="processes training models at once (0: one per core)")
    parser.add_argument("--learning-curve", metavar="MOTOR",
                        help="also the mlp's held-out error by the number of groups trained on")
    args = parser.parse_args(argv)
    if args.jobs < 0:
        raise UserError(f"--jobs must be >= 0, got {args.jobs}")
    if args.out and len(args.runs) > 1:
        raise UserError("--out goes with one RUN; with several, each run's folder gets its own")
    size = SIZES[args.size]
    fixed = size | {"grid_mlp": [size["curve_mlp"]]}
    # (out, fit, models, curve): every run read and checked before any training
    runs: list[tuple[pathlib.Path, dict[str, Any], list[_JobArguments], list[_JobArguments]]] = []
    for run in args.runs:
        out = pathlib.Path(args.out or run)
        check_out(out)
        fit, logs = read_run(run)
        models: list[_JobArguments] = [(job, logs, size, ("mlp", "lstm"))
                                      for job in model_jobs(fit)]
        curve: list[_JobArguments] = [] if args.learning_curve is None else [
            (job, logs, fixed, ("mlp",)) for job in curve_jobs(fit, args.learning_curve)]
        check_jobs(run, [job for job, *_ in models + curve], logs)
        runs.append((out, fit, models, curve))
    try:
        importlib.import_module("torch")
    except ImportError:
        raise UserError("learned_fit: PyTorch is not installed (Debian: python3-torch)") from None
    jobs = [job for _, _, models, curve in runs for job in models + curve]
    processes = max(1, min(args.jobs or os.cpu_count() or 1, len(jobs)))
    if processes == 1:
        results = [run_job(j) for j in jobs]
    else:
        with multiprocessing.get_context("fork").Pool(processes) as pool:
            results = pool.map(run_job, jobs, chunksize=1)
    texts: dict[_PathLike, str] = {}
    for out, fit, models, curve in runs:
        texts |= outputs(out, fit, results[:len(models)],
                         results[len(models):len(models) + len(curve)])
        results = results[len(models) + len(curve):]
    write_outputs(texts)


def cli(argv: Sequence[str] | None = None) -> int:
    """The command as ``python3 -m leglab.servo.learned`` runs it: main, its bad input and its
    bugs each one line on stderr.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default sys.argv[1:]).

    Returns
    -------
    int
        The exit status: 0, 2 on bad input, 1 on a bug.
    """
    try:
        main(argv)
    except (UserError, Bug) as e:
        text = one_line(e)
        print(text if text.startswith("learned_fit") else f"learned_fit: {text}", file=sys.stderr)
        return 2 if isinstance(e, UserError) else 1
    return 0


if __name__ == "__main__":
    sys.exit(cli())
