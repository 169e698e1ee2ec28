"""What a session on a bus does to its servos: set them up as the model assumes, find the
load's zero, keep a tick, and the two loops built on them (`record` and `run`, in record.py and
run.py).

Angles here are degrees from the zero (the load hanging still, the shipped logs' convention)
unless named `*_servo_deg` (the servo's own 0-360 deg scale over 4096 counts).
"""

from __future__ import annotations

import contextlib
import ctypes
import gc
import math
import os
import signal
import statistics
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Optional, Protocol

from . import tables
from .bus import Bus, BusError


class Clock(Protocol):
    """What a loop keeps its tick on: emulator.VirtualClock or emulator.RealClock."""

    def now(self) -> float:
        """Seconds since the clock's start."""

    def sleep(self, seconds: float) -> None:
        """Passes `seconds`."""


Say = Callable[[str], None]  # a line of progress (cli.say)

COUNTS_PER_REV = 4096
DEG_PER_COUNT = 360.0 / COUNTS_PER_REV


class SessionError(Exception):
    """The user's input or the bench refuses the session: one line, exit status 2."""


class Stopped(BaseException):
    """A signal to stop arrived (SIGINT, SIGTERM, SIGHUP, SIGQUIT): the session ends as on a
    fault, torque off and log kept. A BaseException, as KeyboardInterrupt is, so that no
    `except Exception` on the way (pyserial's, ours) takes it for a fault of the bus."""


# ---- set-up ----

def model_settings(table: tables.ControlTable, kp: int) -> dict[str, int]:
    """{item: raw} a servo of `table` is set to before it moves, in the order written: the
    EEPROM items first (with the torque off), then the RAM ones. What the model assumes:
    position control by the firmware's P law alone at gain `kp` (no I or D term, no profile
    shaping the request), and a reply at once (return delay 0)."""
    position_mode = 3 if table.protocol == "dynamixel" else 0  # X series: 3; STS: mode 0
    wanted = {"operating_mode": position_mode, "return_delay_time": 0,
              "profile_velocity": 0, "profile_acceleration": 0,
              "position_p_gain": kp, "position_i_gain": 0, "position_d_gain": 0}
    present = {k: v for k, v in wanted.items() if k in table.items}
    eeprom = {k: v for k, v in present.items() if table.items[k].memory == "EEPROM"}
    ram = {k: v for k, v in present.items() if table.items[k].memory != "EEPROM"}
    return {**eeprom, **ram}


def set_up(bus: Bus, ids: Sequence[int], kp_by_id: Mapping[int, float],
           say: Say) -> list[dict[str, Any]]:
    """Torque off, then every servo set to model_settings; each register that changed is
    said (`say(line)`). Returns the changes: [{id, item, before, after, unit}]."""
    bus.sync_write_raw("torque_enable", {i: 0 for i in ids})
    changes: list[dict[str, Any]] = []
    for servo_id in ids:
        table = bus.table(servo_id)
        kp = kp_by_id[servo_id]
        if kp != int(kp):
            raise SessionError(f"servo {servo_id}: kp {kp!r}: a gain register holds a whole "
                               "number")
        settings = model_settings(table, int(kp))
        unlock = table.protocol == "feetech" and "lock" in table.items and any(
            table.items[k].memory == "EEPROM" for k in settings)
        if unlock:
            bus.write_raw(servo_id, "lock", 0)  # Feetech: EEPROM writes kept only unlocked
        for item, raw in settings.items():
            before = bus.read_raw(servo_id, item)
            if before == raw:
                continue
            bus.write_raw(servo_id, item, raw)
            it = table.items[item]
            change = {"id": servo_id, "item": item, "before": before, "after": raw,
                      "unit": it.unit}
            changes.append(change)
            say(f"servo {servo_id}: {item} {before} -> {raw}" + (f" ({it.unit})" if it.unit else ""))
        if unlock:
            bus.write_raw(servo_id, "lock", 1)
    if not changes:
        say("set-up: every servo already as the model assumes")
    return changes


def check_health(bus: Bus, ids: Sequence[int]) -> None:
    """SessionError when a servo is too hot, its supply outside its limits, or it reports a
    hardware error: what a run must not start with."""
    for servo_id in ids:
        table = bus.table(servo_id)
        if "hardware_error_status" in table.items:
            error = bus.read_raw(servo_id, "hardware_error_status")
            if error:
                raise SessionError(f"port {bus.port_name}: servo {servo_id} reports a hardware "
                                   f"error ({bus.protocol.hardware_error_text(error)}): power it off "
                                   "and on, and find the cause")
        volts = bus.read(servo_id, "present_input_voltage")
        low = bus.read(servo_id, "min_voltage_limit")
        high = bus.read(servo_id, "max_voltage_limit")
        if not low <= volts <= high:
            raise SessionError(f"port {bus.port_name}: servo {servo_id}'s supply is {volts:g} V, "
                               f"outside its limits [{low:g}, {high:g}] V")
        temperature = bus.read(servo_id, "present_temperature")
        limit = bus.read(servo_id, "temperature_limit")
        if temperature > limit - 5:
            raise SessionError(f"port {bus.port_name}: servo {servo_id} is at {temperature:g} C, "
                               f"within 5 C of its limit ({limit:g} C): let it cool")


def find_zero(bus: Bus, clock: Clock, ids: Sequence[int], say: Say, settle_s: float = 0.5,
              timeout_s: float = 15.0) -> dict[int, float]:
    """{id: zero_servo_deg}: with the torque off, the reading once the load hangs still (its
    readings over `settle_s` within one count), averaged over that time."""
    bus.sync_write_raw("torque_enable", {i: 0 for i in ids})
    window = max(2, round(settle_s / 0.02))
    history: dict[int, list[int]] = {i: [] for i in ids}
    first: Optional[dict[int, int]] = None
    start = clock.now()
    while True:
        raw = bus.sync_read_raw(ids, "present_position")
        first = first or dict(raw)
        for i in ids:  # counts from the first reading, across the encoder's 0/4096 seam
            history[i] = (history[i] + [first[i] + wrapped(raw[i] - first[i])])[-window:]
        if all(len(h) == window and max(h) - min(h) <= 1 for h in history.values()):
            zeros = {i: DEG_PER_COUNT * (statistics.fmean(h) % COUNTS_PER_REV)
                     for i, h in history.items()}
            say("zero (the load hanging still, torque off): " + ", ".join(
                f"servo {i} at {z:.2f} deg" for i, z in zeros.items()))
            return zeros
        if clock.now() - start > timeout_s:
            moving = [i for i, h in history.items() if max(h) - min(h) > 1]
            raise SessionError(f"port {bus.port_name}: servo {moving[0]}'s load did not come to "
                               f"rest within {timeout_s:g} s with the torque off: steady it, or "
                               "give --zero-deg")
        clock.sleep(0.02)


def wrapped(counts: int) -> int:
    """`counts` (a difference of positions) within half a turn: [-2048, 2048)."""
    return (counts + COUNTS_PER_REV // 2) % COUNTS_PER_REV - COUNTS_PER_REV // 2


def to_count(angle_deg: float, zero_servo_deg: float) -> int:
    """The goal count of `angle_deg` from the zero (on the servo's scale: the caller keeps it
    within the servo's position limits, position_limits_deg)."""
    return round((angle_deg + zero_servo_deg) / DEG_PER_COUNT)


def from_count(count: float, zero_servo_deg: float) -> float:
    """The angle from the zero of a position count, deg, within half a turn of it: a reading
    across the encoder's 0/4096 seam is the angle next to the zero, not a turn away."""
    offset = count - zero_servo_deg / DEG_PER_COUNT
    return (offset - COUNTS_PER_REV * math.floor(offset / COUNTS_PER_REV + 0.5)) * DEG_PER_COUNT


def position_limits_deg(bus: Bus, servo_id: int, zero_servo_deg: float) -> tuple[float, float]:
    """The servo's own position limits (its min/max position registers), as angles from the
    zero: the range a goal must stay in. Limits that hold no range (Feetech's 0, 0 of its
    multi-turn mode) count as one whole turn."""
    low = bus.read_raw(servo_id, "min_position_limit")
    high = bus.read_raw(servo_id, "max_position_limit")
    if high <= low:
        low, high = 0, COUNTS_PER_REV - 1
    zero = zero_servo_deg / DEG_PER_COUNT
    return (low - zero) * DEG_PER_COUNT, (high - zero) * DEG_PER_COUNT


def torque_on_where_it_is(bus: Bus, ids: Sequence[int]) -> dict[int, int]:
    """Goal = present position, then torque on: the servos hold where they are."""
    present = bus.sync_read_raw(ids, "present_position")
    bus.sync_write_raw("goal_position", present)
    bus.sync_write_raw("torque_enable", {i: 1 for i in ids})
    return present


def move_to(bus: Bus, clock: Clock, ids: Sequence[int], zeros: Mapping[int, float],
            target_deg: Mapping[int, float], tick_s: float, speed_deg_s: float = 60.0,
            settle_s: float = 1.0) -> None:
    """Torque on where the servos are, then each goal ramped to `target_deg[id]` at
    `speed_deg_s`, then held `settle_s`."""
    present = torque_on_where_it_is(bus, ids)
    start = {i: from_count(present[i], zeros[i]) for i in ids}
    ramp_s = max(abs(target_deg[i] - start[i]) for i in ids) / speed_deg_s
    steps = max(1, math.ceil(ramp_s / tick_s))
    for k in range(1, steps + 1):
        f = k / steps
        bus.sync_write_raw("goal_position", {
            i: to_count(start[i] + f * (target_deg[i] - start[i]), zeros[i]) for i in ids})
        clock.sleep(tick_s)
    clock.sleep(settle_s)


def torque_off(bus: Bus, ids: Sequence[int], say: Say) -> list[int]:
    """Torque off on every servo of `ids` that answers; never raises (the way out of a fault).
    A sync write first (one packet), then each servo alone (a write that is answered; a
    hardware alert in its reply does not mean the write failed). Returns the ids whose torque
    this session turned on and that it could not reach."""
    was_on = set(bus.torque_on)
    try:
        bus.sync_write_raw("torque_enable", {i: 0 for i in ids})
    except Exception:  # the port itself may be gone: each is tried below
        pass
    unreached = []
    for servo_id in ids:
        try:
            bus.write_raw(servo_id, "torque_enable", 0, check=False)
        except Exception:  # a silent servo: go on to the others
            if servo_id in was_on:
                unreached.append(servo_id)
    return unreached


# ---- the tick ----

@dataclass
class TickStats:
    """How a loop kept its tick."""

    tick_s: float
    starts_s: list[float] = field(default_factory=list)  # each tick's start, s from the start
    work_s: list[float] = field(default_factory=list)  # each tick's work (read, plan, write), s
    late: list[int] = field(default_factory=list)  # 1 when the tick's write ended after the
    # next tick's start, or ticks were skipped before it
    skipped: int = 0                               # ticks that passed with no request sent

    def summary(self) -> dict[str, Any]:
        """The period's and the work's median, p99 and max (ms), ticks, late and skipped."""
        periods = [b - a for a, b in zip(self.starts_s, self.starts_s[1:])] or [0.0]
        return {"ticks": len(self.starts_s), "ticks_late": sum(self.late),
                "ticks_skipped": self.skipped,
                "period_ms": _quantiles_ms(periods), "work_ms": _quantiles_ms(self.work_s or [0])}


def _quantiles_ms(values: Sequence[float]) -> dict[str, float]:
    ordered = sorted(values)
    p99 = ordered[min(len(ordered) - 1, math.ceil(0.99 * len(ordered)) - 1)]
    return {"median": round(1e3 * statistics.median(ordered), 4), "p99": round(1e3 * p99, 4),
            "max": round(1e3 * ordered[-1], 4)}


def run_ticks(clock: Clock, tick_s: float, count: int, body: Callable[[int, float, int], object],
              stats: Optional[TickStats] = None) -> TickStats:
    """Calls `body(k, t_s, skipped)` for ticks k = 0..count-1 on the clock, tick k at
    start + k * tick_s: t_s is the time since the loop's start, `skipped` the ticks that passed
    since the last call with no call (the loop woke too late; those k are never called).
    Returns `stats` (a new TickStats if None), filled tick by tick: when body raises, it holds
    the ticks before."""
    stats = TickStats(tick_s) if stats is None else stats
    start = clock.now()
    k = 0
    while k < count:
        now = clock.now()
        target = start + k * tick_s
        skipped = 0
        if now < target:
            clock.sleep(target - now)
        else:
            behind = int((now - start) / tick_s)
            if behind > k:
                skipped, k = behind - k, behind
                if k >= count:
                    stats.skipped += count - (k - skipped)
                    break
        stats.skipped += skipped
        began = clock.now()
        body(k, began - start, skipped)
        ended = clock.now()
        stats.starts_s.append(began - start)
        stats.work_s.append(ended - began)
        stats.late.append(1 if skipped or ended > start + (k + 1) * tick_s else 0)
        k += 1
    return stats


class LoopTimeout:
    """While entered, the bus waits at most half a tick for a reply (never more than its own
    timeout, never under 1 ms): a reply lost on the wire costs one retry within the tick, not
    several ticks."""

    def __init__(self, bus: Bus, tick_s: float) -> None:
        self.bus = bus
        self.timeout_s = min(bus.timeout_s, max(0.001, tick_s / 2))

    def __enter__(self) -> LoopTimeout:
        self._saved = self.bus.timeout_s
        self.bus.timeout_s = self.timeout_s
        return self

    def __exit__(self, *exc: object) -> None:
        self.bus.timeout_s = self._saved


class RealTime:
    """The loop's process made fit to keep a tick while it is entered: real-time scheduling
    (SCHED_FIFO) where the system allows it, its memory locked, the garbage collector paused.
    `warning` says what could not be had (empty when all was)."""

    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled
        self.warning = ""
        self._policy: Optional[tuple[int, Any]] = None

    def __enter__(self) -> RealTime:
        gc.collect()
        gc.disable()
        if not self.enabled:
            return self
        missing = []
        try:
            self._policy = (os.sched_getscheduler(0), os.sched_getparam(0))
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(50))
        except (PermissionError, OSError, AttributeError) as e:
            self._policy = None
            missing.append(f"real-time priority ({getattr(e, 'strerror', None) or e})")
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.mlockall(3) != 0:  # MCL_CURRENT | MCL_FUTURE
            missing.append(f"locked memory ({os.strerror(ctypes.get_errno())})")
        if missing:
            self.warning = ("warning: no " + " and no ".join(missing) +
                            ": ticks may be late when the machine is busy (run as root, or "
                            "grant rtprio and memlock in /etc/security/limits.conf)")
        return self

    def __exit__(self, *exc: object) -> None:
        gc.enable()
        if self._policy is not None:
            try:
                os.sched_setscheduler(0, *self._policy)
            except OSError:
                pass


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGQUIT)
"""The signals that end a session as a fault does: Ctrl-C, kill, a closed terminal, Ctrl-\\."""


class StopOnSignal:
    """While entered, STOP_SIGNALS end the session as a fault does: the first one raises
    Stopped where the session is, so that the torque goes off and the log is written on the
    way out. Inside `held()` (a file being written) a signal waits until the block ends; after
    `finish()` (the way out under way) signals are noted and ignored. The handlers are restored
    on leaving."""

    def __init__(self) -> None:
        self._saved: dict[int, Any] = {}
        self.unreached: list[int] = []  # set by the session: servos whose torque stayed on
        self._holding = 0
        self._pending: Optional[int] = None
        self._finished = False

    def __enter__(self) -> StopOnSignal:
        self._saved = {s: signal.getsignal(s) for s in STOP_SIGNALS}
        for s in self._saved:
            signal.signal(s, self._handle)
        return self

    def _handle(self, signum: int, _frame: object) -> None:
        if self._finished:
            return
        if self._holding:
            self._pending = self._pending or signum
            return
        self._finished = True
        raise Stopped(f"stopped by {signal.Signals(signum).name}")

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """A block no signal interrupts: one that arrives in it is raised when it ends."""
        self._holding += 1
        try:
            yield
        finally:
            self._holding -= 1
        if not self._holding and self._pending is not None and not self._finished:
            self._finished = True
            raise Stopped(f"stopped by {signal.Signals(self._pending).name}")

    def finish(self) -> None:
        """From now on signals are ignored: the torque is going off and the log being written."""
        self._finished = True

    def __exit__(self, *exc: object) -> None:
        for s, handler in self._saved.items():
            signal.signal(s, handler)


def torque_words(unreached: Sequence[int]) -> str:
    """What became of the torque, for the session's last line."""
    if not unreached:
        return "the torque is off"
    them = ", ".join(map(str, unreached))
    return (f"the torque is off but in servo(s) {them}, which did not answer: cut their power "
            "now")


def quit_reason(error: BaseException) -> str:
    """The one line a session ends with on `error`."""
    if isinstance(error, (BusError, SessionError, Stopped)):
        return str(error)
    return f"{type(error).__name__}: {error}"
