"""`record`: the servos follow excitation trajectories while their angles are logged, in the
form `identify` and `leglab.servo.read_log` read with no extra keys (BAM's JSON log: the motor,
gain, load and trajectory travel in the file)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, Optional

from . import files, session, trajectories
from .bus import Bus

# A servo's samples: (t_s, measured_deg, request_deg, torque_on) a tick.
_Samples = dict[int, list[tuple[float, float, float, bool]]]


def log_name(trajectory: str, kp: float, servo_id: int) -> str:
    """The log's file name: <trajectory>_kp<kp>_id<id>.json."""
    return f"{trajectory}_kp{kp:g}_id{servo_id}.json"


def record_trajectory(bus: Bus, clock: session.Clock, ids: Sequence[int], name: str,
                      tick_s: float, zeros: Mapping[int, float], say: session.Say
                      ) -> tuple[_Samples, session.TickStats, Optional[BaseException]]:
    """Servos `ids` through trajectory `name`, one tick of `tick_s` at a time, from its first
    angle. Returns ({id: [(t_s, measured_deg, request_deg, torque_on)]}, TickStats, the
    exception that ended it early or None)."""
    samples: _Samples = {i: [] for i in ids}
    try:
        start_deg = trajectories.start_deg(name)
        session.move_to(bus, clock, ids, zeros, {i: start_deg for i in ids}, tick_s)
    except (Exception, session.Stopped) as e:  # before the trajectory: no samples
        return samples, session.TickStats(tick_s), e
    torque = [True]

    def tick(_k: int, t_s: float, _skipped: int) -> None:
        raw = bus.sync_read_raw(ids, "present_position")
        request_deg, torque_on = trajectories.sample(name, t_s)
        if torque_on != torque[0]:
            bus.sync_write_raw("torque_enable", {i: int(torque_on) for i in ids})
            torque[0] = torque_on
        goals = {i: session.to_count(request_deg, zeros[i]) for i in ids}
        if torque_on:
            bus.sync_write_raw("goal_position", goals)
        for i in ids:
            samples[i].append((t_s, session.from_count(raw[i], zeros[i]),
                               session.from_count(goals[i], zeros[i]), torque_on))

    count = math.ceil(trajectories.duration_s(name) / tick_s) + 1
    stats = session.TickStats(tick_s)
    try:
        with session.LoopTimeout(bus, tick_s):
            session.run_ticks(clock, tick_s, count, tick, stats)
    except (Exception, session.Stopped) as e:  # a fault or a signal: the samples are kept
        return samples, stats, e
    say(f"{name}: {len(stats.starts_s)} ticks, {sum(stats.late)} late, "
        f"{stats.skipped} skipped")
    return samples, stats, None


def log_json(samples: Sequence[tuple[float, float, float, bool]],
             meta: Mapping[str, Any]) -> dict[str, Any]:
    """A BAM-style log: `meta` (motor, kp, mass, length, trajectory, ...) and the entries
    (radians from the zero, as BAM's logs hold them)."""
    entries = [{"timestamp": t, "position": math.radians(m), "goal_position": math.radians(r),
                "torque_enable": bool(on)} for t, m, r, on in samples]
    return {**meta, "entries": entries}


def write_logs(paths: Mapping[tuple[str, int], str], samples: _Samples,
               stats: session.TickStats, meta_by_id: Mapping[int, Mapping[str, Any]],
               bus: Bus) -> list[str]:
    """One log per servo, at paths[(trajectory, id)]; returns the paths written."""
    written: list[str] = []
    for servo_id, rows in samples.items():
        meta = dict(meta_by_id[servo_id])
        meta.update(stats.summary(), retries=bus.stats.retries)
        path = paths[(meta["trajectory"], servo_id)]  # BAM's key
        files.write_json(path, log_json(rows, meta))
        written.append(path)
    return written
