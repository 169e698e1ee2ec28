"""`run`: servos follow a desired motion with requests from a fitted model (or the desired
angles sent as they are), tick by tick on the real clock, and what they did is written beside
what the model predicted."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import Any, Optional

import numpy as np
import numpy.typing as npt

from .. import servo
from . import files, outputs, session
from .bus import Bus

# A servo's rows of run.csv without `late`: time_s, desired_deg, request_deg, measured_deg.
_Rows = dict[int, list[tuple[float, float, float, float]]]

METHODS = ("direct", "model_based", "optimal")
"""What run sends: the desired angles as they are, or the model's planned requests."""

RUN_COLUMNS = outputs.column_names(outputs.RUN_CSV)
"""run.csv's columns (leglab.bus.outputs.RUN_CSV)."""


class Policy:
    """One servo's requests, tick by tick: the batch plan's, the online planner's, or the
    desired angles. `request(k, skipped, measured_deg)` is tick k's request (deg), `skipped`
    the ticks since the last one on which none was sent."""

    def __init__(self, model: servo.ServoModel, desired_deg: npt.ArrayLike, method: str,
                 online: bool, preview_ticks: Optional[int], drive: Mapping[str, Any],
                 limits: tuple[float, float], lead_ticks: int = 0,
                 budget_s: Optional[float] = None) -> None:
        self.desired = np.ascontiguousarray(desired_deg, dtype=np.float64)
        self.method = method
        self.planner: Optional[servo.ServoPlanner] = None
        self.limits = dict(min_deg=limits[0], max_deg=limits[1])
        min_deg, max_deg = limits
        if method == "direct":  # D(t + lead), the last angle held: the paper's time shift
            self.requests = self.desired[np.minimum(np.arange(len(self.desired)) + lead_ticks,
                                                    len(self.desired) - 1)]
        elif online:
            self.planner = servo.ServoPlanner(model, method, preview_ticks=preview_ticks,
                                              min_deg=min_deg, max_deg=max_deg,
                                              budget_s=budget_s, **drive)
            self.planner.reset(float(self.desired[0]))
            self.window = self.planner.preview_ticks + 1
        else:
            self.requests = servo.plan(model, self.desired, method, min_deg=min_deg,
                                       max_deg=max_deg, **drive).request_deg

    def request(self, k: int, skipped: int, measured_deg: float) -> float:
        """Tick k's request, deg."""
        if self.planner is None:
            return float(self.requests[k])
        for j in range(k - skipped, k):
            self.planner.hold(self.desired[j:j + self.window])
        return self.planner.request(self.desired[k:k + self.window], measured_deg)


def predicted_mae_deg(model: servo.ServoModel, policy: Policy, drive: Mapping[str, Any]) -> float:
    """What the model predicts for the run: its mean absolute error under the policy's batch
    requests (online: the batch plan of the same method, which online model_based equals when
    the servo is the model), deg."""
    if policy.method == "direct":
        angles = model.simulate(policy.requests, start_deg=float(policy.desired[0]), **drive)
    else:
        angles = servo.plan(model, policy.desired, policy.method, **drive, **policy.limits
                            ).predicted_deg
    return float(np.mean(np.abs(angles - policy.desired)))


def run_servos(bus: Bus, clock: session.Clock, ids: Sequence[int], policies: Mapping[int, Policy],
               zeros: Mapping[int, float], limits: Mapping[int, tuple[float, float]],
               max_speed_deg_s: Mapping[int, float], tick_s: float
               ) -> tuple[_Rows, session.TickStats, Optional[BaseException]]:
    """The loop: each tick one sync read, each servo's request (clamped to its `limits[id]`
    and to `max_speed_deg_s[id]` from the last one sent), one sync write. Returns ({id: rows},
    TickStats, the exception that ended it or None); rows as RUN_COLUMNS without `late`."""
    rows: _Rows = {i: [] for i in ids}
    sent = {i: float(policies[i].desired[0]) for i in ids}
    goals: dict[int, int] = {}
    stopped: list[BaseException] = []

    def tick(k: int, t_s: float, skipped: int) -> None:
        raw = bus.sync_read_raw(ids, "present_position")
        for i in ids:
            measured = session.from_count(raw[i], zeros[i])
            request = policies[i].request(k, skipped, measured)
            step = max_speed_deg_s[i] * tick_s * (1 + skipped)
            low, high = limits[i]
            request = min(max(request, sent[i] - step, low), sent[i] + step, high)
            goals[i] = session.to_count(request, zeros[i])
            sent[i] = session.from_count(goals[i], zeros[i])
            rows[i].append((t_s, float(policies[i].desired[k]), sent[i], measured))
        bus.sync_write_raw("goal_position", goals)

    count = len(next(iter(policies.values())).desired)
    stats = session.TickStats(tick_s)
    try:
        with session.LoopTimeout(bus, tick_s):
            session.run_ticks(clock, tick_s, count, tick, stats)
    except (Exception, session.Stopped) as e:  # a fault or a signal: what ran is kept
        stopped.append(e)
    return rows, stats, (stopped[0] if stopped else None)


def errors(rows: Sequence[tuple[float, float, float, float]]) -> dict[str, float]:
    """mae_deg, rms_deg and max_abs_deg of measured - desired over `rows`."""
    if not rows:
        return {"mae_deg": math.nan, "rms_deg": math.nan, "max_abs_deg": math.nan}
    e = np.array([r[3] - r[1] for r in rows])
    return {"mae_deg": float(np.mean(np.abs(e))), "rms_deg": float(np.sqrt(np.mean(e * e))),
            "max_abs_deg": float(np.max(np.abs(e)))}


def csv_text(rows: Sequence[tuple[float, ...]], late: Sequence[int]) -> str:
    """run.csv's text."""
    lines = [",".join(RUN_COLUMNS)]
    for row, is_late in zip(rows, late):
        lines.append(",".join(files.number(v) for v in row) + f",{is_late}")
    return "\n".join(lines) + "\n"


def output_paths(out: str, ids: Sequence[int]) -> list[str]:
    """The files `run` writes into `out` for servos `ids`."""
    names = ["run.csv"] if len(ids) == 1 else [f"run_id{i}.csv" for i in ids]
    return [os.path.join(out, name) for name in names + ["run.json"]]


def write_run(out: str, rows: _Rows, stats: session.TickStats,
              summary: Mapping[str, Any]) -> list[str]:
    """run.csv (one servo) or run_id<N>.csv (several), and run.json; returns the paths."""
    paths: list[str] = []
    late = stats.late + [0] * max(0, max(len(r) for r in rows.values()) - len(stats.late))
    for servo_id, servo_rows in rows.items():
        name = "run.csv" if len(rows) == 1 else f"run_id{servo_id}.csv"
        path = os.path.join(out, name)
        files.write_text(path, csv_text(servo_rows, late))
        paths.append(path)
    path = os.path.join(out, "run.json")
    files.write_json(path, summary)
    return paths + [path]
