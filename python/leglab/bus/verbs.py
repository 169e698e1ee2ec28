"""The bodies of `python3 -m leglab.bus`'s verbs (the flags are cli.py's)."""

from __future__ import annotations

import argparse
import glob
import os
import signal
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any, Optional

import numpy as np
import numpy.typing as npt

from . import emulator, files, joints, record as recording, run as running, session, tables
from .bus import MAX_ID, Bus, BusError, BusStats, ServoInfo, first_line
from .cli import open_bus, say

_SCAN_ITEMS = (  # (column, item, format): what matters to the model, as scan shows it
    ("kp", "position_p_gain", "{:.0f}"), ("ki", "position_i_gain", "{:.0f}"),
    ("kd", "position_d_gain", "{:.0f}"), ("mode", "operating_mode", "{:.0f}"),
    ("delay_us", "return_delay_time", "{:.0f}"), ("prof_vel", "profile_velocity", "{:.0f}"),
    ("prof_acc", "profile_acceleration", "{:.0f}"), ("pos_min", "min_position_limit", "{:.1f}"),
    ("pos_max", "max_position_limit", "{:.1f}"), ("volts", "present_input_voltage", "{:.1f}"),
    ("temp_c", "present_temperature", "{:.0f}"), ("torque", "torque_enable", "{:.0f}"),
    ("pos_deg", "present_position", "{:.1f}"))


def latency_timer_ms(port: str) -> Optional[int]:
    """The USB serial adapter's latency timer behind `port` (ms), or None when it has none (a
    pseudo-terminal, a native UART)."""
    try:
        name = os.path.basename(os.path.realpath(port))
    except OSError:
        return None
    for path in glob.glob(f"/sys/bus/usb-serial/devices/{name}/latency_timer"):
        with open(path) as f:
            return int(f.read().strip())
    return None


def _scan_row(bus: Bus, info: ServoInfo) -> list[str]:
    cells = [str(info.id), info.table.model if info.table else f"#{info.model_number}",
             str(info.firmware_version)]
    for _, item, fmt in _SCAN_ITEMS:
        if info.table is None or item not in info.table.items:
            cells.append("-")
            continue
        value = bus.read(info.id, item)
        if item == "return_delay_time":
            value *= 1e6
        cells.append(fmt.format(value))
    return cells


def scan(args: argparse.Namespace) -> int:
    """Prints the servos on the port and their settings; warns of what spoils a tick."""
    bus, _ = open_bus(args)
    with bus:
        ids: Sequence[int] = args.ids or range(0, MAX_ID + 1)
        # A sweep of many ids waits 5 ms for each (a servo answers in well under 1 ms); a few
        # ids are asked with the bus's own timeout.
        found = bus.scan(ids, timeout_s=min(bus.timeout_s, 0.005) if len(ids) > 16 else None)
        if not found:
            raise session.SessionError(
                f"port {bus.port_name}: no servo answered a PING (ids "
                f"{_id_range(ids)}, {args.protocol} at {args.baud} baud): check the power, "
                "the protocol and the baud rate")
        header = ["id", "model", "firmware"] + [c for c, _, _ in _SCAN_ITEMS]
        rows = [_scan_row(bus, info) for info in found]
        widths = [max(len(r[c]) for r in rows + [header]) for c in range(len(header))]
        for row in [header] + rows:
            say("  ".join(cell.rjust(w) for cell, w in zip(row, widths)))
        for info in found:
            if info.error:
                say(f"warning: servo {info.id} reports {info.error}")
            if info.table is None:
                say(f"warning: servo {info.id}: model number {info.model_number} has no "
                    "control table in leglab; it can be pinged but not recorded or run")
            elif bus.read_raw(info.id, "return_delay_time") > 0:
                say(f"warning: servo {info.id}'s return delay is above 0: each reply waits; "
                    "record and run set it to 0")
        latency = latency_timer_ms(args.port)
        if latency is None:
            say(f"port {bus.port_name}: no latency timer (not a USB serial adapter)")
        elif latency <= 1:
            say(f"port {bus.port_name}: USB latency timer {latency} ms")
        else:
            say(f"warning: the USB adapter's latency timer is {latency} ms (above 1 ms, each "
                f"reply waits up to it): echo 1 | sudo tee /sys/bus/usb-serial/devices/"
                f"{os.path.basename(os.path.realpath(args.port))}/latency_timer")
    return 0


def _id_range(ids: Iterable[int]) -> str:
    ids = list(ids)
    return f"{ids[0]}-{ids[-1]}" if len(ids) > 1 else str(ids[0])


def _prepare(bus: Bus, clock: session.Clock, js: Sequence[joints.Joint], say_line: session.Say
             ) -> tuple[dict[int, float], list[dict[str, Any]]]:
    """The servos of `js` (Joints) found and set up as the model assumes; their zeros.
    Returns ({id: zero_servo_deg}, the set-up's changes)."""
    ids = [j.id for j in js]
    for j in js:
        gain = bus.table(j.id).item("position_p_gain")
        most = (1 << (8 * gain.size)) - 1
        if j.kp > most:
            raise session.SessionError(f"servo {j.id}: kp {j.kp}: its gain register holds at "
                                       f"most {most}")
    session.check_health(bus, ids)
    changes = session.set_up(bus, ids, {j.id: j.kp for j in js}, say_line)
    zeros = {j.id: j.zero_deg for j in js if j.zero_deg is not None}
    unknown = [i for i in ids if i not in zeros]
    if unknown:
        zeros.update(session.find_zero(bus, clock, unknown, say_line))
    return zeros, changes


def _session(bus: Bus, clock: session.Clock, args: argparse.Namespace, ids: Sequence[int],
             body: Callable[[], Any], stop: session.StopOnSignal) -> Any:
    """Runs `body()` with real time asked for; the torque goes off however it ends (then
    `stop` ignores further signals, so that the log is written). Returns what body returns;
    stop.unreached: the servos whose torque could not be turned off."""
    try:
        with session.RealTime(not args.no_realtime) as rt:
            if rt.warning and not isinstance(clock, emulator.VirtualClock):
                say(rt.warning)
            return body()
    finally:
        stop.finish()
        stop.unreached = session.torque_off(bus, ids, say)


def _ended(verb: str, ended: Optional[BaseException], what: str, unreached: Sequence[int]) -> int:
    """The exit status of a session that `ended` (None: completed), its one line said."""
    if ended is None and not unreached:
        return 0
    reason = "completed" if ended is None else session.quit_reason(ended)
    print(f"leglab.bus {verb}: {reason}; {session.torque_words(unreached)} and {what}",
          file=sys.stderr)
    return 2 if ended is None or isinstance(ended, (BusError, session.SessionError,
                                                     session.Stopped)) else 1


def _warn_latency(args: argparse.Namespace) -> None:
    """A USB adapter's latency timer above 1 ms, said before a session (scan explains it)."""
    latency = latency_timer_ms(args.port)
    if latency is not None and latency > 1:
        say(f"warning: the USB adapter's latency timer is {latency} ms: each reply waits up to "
            "it (python3 -m leglab.bus scan says how to set 1 ms)")


def record(args: argparse.Namespace) -> int:
    """Records each trajectory on every servo; one log per servo and trajectory."""
    js = joints.joints(args, verb="record")
    ids = [j.id for j in js]
    for j in js:
        if j.kp == 0:
            raise session.SessionError(f"servo {j.id}: kp 0: the servo would not hold (a log "
                                       "the model cannot be fitted on)")
    out = files.out_folder(args.out)
    paths = {(name, j.id): os.path.join(out, recording.log_name(name, j.kp, j.id))
             for name in args.trajectory for j in js}
    files.check_writable_all(out, paths.values())
    bus, clock = open_bus(args, js)
    _warn_latency(args)
    written: list[str] = []
    with bus, session.StopOnSignal() as stop:

        def body() -> Optional[BaseException]:
            zeros, changes = _prepare(bus, clock, js, say)
            _check_reach(bus, js, zeros, args.trajectory)
            for name in args.trajectory:
                samples, stats, ended = recording.record_trajectory(
                    bus, clock, ids, name, args.tick_s, zeros, say)
                with stop.held():
                    meta = {j.id: _log_meta(args, bus, name, j, zeros[j.id], changes, ended)
                            for j in js}
                    if any(samples.values()):
                        written.extend(recording.write_logs(paths, samples, stats, meta, bus))
                if ended is not None:
                    return ended
            return None

        ended = _session(bus, clock, args, ids, body, stop)
    for path in written:
        say(f"wrote {path}")
    return _ended("record", ended, "the logs are written up to there" if written else
                  "no log was written", stop.unreached)


def _check_reach(bus: Bus, js: Sequence[joints.Joint], zeros: Mapping[int, float],
                 names: Iterable[str]) -> None:
    """SessionError, before anything moves, when a trajectory leaves a servo's own position
    limits from its zero."""
    for j in js:
        low, high = session.position_limits_deg(bus, j.id, zeros[j.id])
        for name in names:
            least, most = recording.trajectories.amplitude_deg(name)
            if least < low or most > high:
                raise session.SessionError(
                    f"servo {j.id}: trajectory {name} spans [{least:g}, {most:g}] deg, beyond "
                    f"the servo's position limits from its zero, [{low:g}, {high:g}] deg: "
                    "nothing moved (mount the servo so that the load hangs mid-range, or set "
                    "its offset)")


def _log_meta(args: argparse.Namespace, bus: Bus, trajectory: str, joint: joints.Joint,
              zero_deg: float, changes: Sequence[Mapping[str, Any]],
              ended: Optional[BaseException]) -> dict[str, Any]:
    """A log's fields beside its entries: BAM's (mass, length, kp, vin, motor, trajectory),
    which identify reads, and the session's (docs/real-servos.md lists them)."""
    return dict(mass=joint.mass_kg, length=joint.length_m, kp=joint.kp,
                vin=_supply_volts(bus, joint.id, ended), motor=joint.motor,
                trajectory=trajectory, id=joint.id, model=bus.table(joint.id).model,
                protocol=args.protocol, port=bus.port_name, zero_deg=zero_deg,
                tick_s=args.tick_s, setup=[c for c in changes if c["id"] == joint.id],
                recorded_by="python3 -m leglab.bus record",
                ended="completed" if ended is None else session.quit_reason(ended))


def _supply_volts(bus: Bus, servo_id: int, ended: Optional[BaseException]) -> Optional[float]:
    """The servo's supply now (None when the session ended on a fault: the bus may be gone)."""
    if ended is not None:
        return None
    return bus.read(servo_id, "present_input_voltage")


def _load_joint(args: argparse.Namespace, fit: Any, joint: joints.Joint, servos: int
                ) -> tuple[Any, npt.NDArray[np.float64]]:
    """(model, desired on its tick) of one joint, the desired motion inside the joint's
    limits and its drive and the planner's options valid (its budget shared among the session's
    `servos`); SessionError naming the file, servo or flag, before anything opens the port."""
    from .. import servo

    files.check_input_file(joint.desired, f"servo {joint.id}: --desired")
    try:
        model = fit.model(joint.motor or None, rung=args.rung)
        desired = servo.read_desired(joint.desired, model.tick_s)
    except (ValueError, OSError) as e:
        reason = first_line(e) if str(e).strip() else (
            f"--desired '{joint.desired}': not a desired CSV or a servo log")
        raise session.SessionError(f"servo {joint.id}: {reason}") from None
    _check_inside(joint, desired, joint.min_deg, joint.max_deg, "[--min-deg, --max-deg]")
    drive = dict(kp=joint.kp, mass_kg=joint.mass_kg, length_m=joint.length_m)
    problem = servo._leglab._drive_problem(joint.kp, joint.mass_kg, joint.length_m)
    try:
        if model.rung == "extended" and problem:
            raise ValueError(problem)
        if args.online and args.method != "direct":  # its options checked as it is built
            servo.ServoPlanner(model, args.method, preview_ticks=args.preview_ticks,
                               min_deg=joint.min_deg, max_deg=joint.max_deg,
                               budget_s=budget_s(args, model.tick_s, servos), **drive)
    except ValueError as e:
        raise session.SessionError(f"servo {joint.id}: {first_line(e)}") from None
    return model, desired


def budget_s(args: argparse.Namespace, tick_s: float, servos: int) -> float:
    """Each servo's online planner's budget_s: --budget-ms; else none on an emulator's virtual
    time (the iteration cap alone: the same requests every run), and on a port half the model's
    tick shared among the servos (optimal spends its budget, and the planners run one after
    another in the tick)."""
    if args.budget_ms is not None:
        return float(args.budget_ms) / 1000.0
    return 0.0 if args.port.startswith("emulator:") else tick_s / 2.0 / servos


def _check_inside(joint: joints.Joint, desired: npt.NDArray[np.float64], low: float, high: float,
                  what: str) -> None:
    outside = (desired < low) | (desired > high)
    if outside.any():
        at = int(np.argmax(outside))
        raise session.SessionError(
            f"servo {joint.id}: --desired '{joint.desired}': the desired angle {desired[at]:g} "
            f"deg at tick {at} is outside {what} = [{low:g}, {high:g}] deg: nothing moved")


def _load_run_inputs(args: argparse.Namespace
                     ) -> tuple[list[joints.Joint], dict[int, tuple[Any, npt.NDArray[np.float64]]]]:
    """The joints and, per joint, its model and desired motion; all on one tick and of one
    length (SessionError otherwise)."""
    from .. import servo

    js = joints.joints(args, verb="run")
    if args.lead_ticks and args.method != "direct":
        raise session.SessionError(f"--lead-ticks {args.lead_ticks}: only with --method direct "
                                   "(the planned methods lead by the model's own lag)")
    if args.online and args.method == "direct":
        raise session.SessionError("--online: only with a planned method (direct sends the "
                                   "desired angles as they are)")
    if args.preview_ticks is not None and not args.online:
        raise session.SessionError("--preview-ticks: only with --online")
    if args.budget_ms is not None and not (args.online and args.method == "optimal"):
        raise session.SessionError("--budget-ms: only with --online --method optimal")
    files.check_input_file(args.model, "--model")
    try:
        fit = servo.LogFit.load(args.model)
    except (ValueError, OSError) as e:
        raise session.SessionError(f"--model: {first_line(e)}") from None
    loaded = {j.id: _load_joint(args, fit, j, len(js)) for j in js}
    first = loaded[js[0].id]
    for j in js[1:]:
        model, desired = loaded[j.id]
        if model.tick_s != first[0].tick_s or len(desired) != len(first[1]):
            raise session.SessionError(
                f"servo {j.id}: its model's tick ({model.tick_s:g} s) and motion ({len(desired)} "
                f"ticks) must be servo {js[0].id}'s ({first[0].tick_s:g} s, {len(first[1])} "
                "ticks): one loop drives them all")
    return js, loaded


def _plan_joints(args: argparse.Namespace, bus: Bus, js: Sequence[joints.Joint],
                 loaded: Mapping[int, tuple[Any, npt.NDArray[np.float64]]],
                 zeros: Mapping[int, float]) -> dict[int, tuple[Any, ...]]:
    """{id: (model, desired, Policy, predicted MAE, (low, high))}: each joint's requests kept
    within its limits and its servo's own position limits (the desired motion refused, before
    anything moves, where it leaves them)."""
    planned: dict[int, tuple[Any, ...]] = {}
    for j in js:
        model, desired = loaded[j.id]
        servo_low, servo_high = session.position_limits_deg(bus, j.id, zeros[j.id])
        low, high = max(j.min_deg, servo_low), min(j.max_deg, servo_high)
        _check_inside(j, desired, low, high, "the servo's position limits from its zero")
        drive = dict(kp=j.kp, mass_kg=j.mass_kg, length_m=j.length_m)
        try:
            policy = running.Policy(model, desired, args.method, args.online, args.preview_ticks,
                                    drive, (low, high), args.lead_ticks,
                                    budget_s(args, model.tick_s, len(js)))
            predicted = running.predicted_mae_deg(model, policy, drive)
        except ValueError as e:
            raise session.SessionError(f"servo {j.id}: {first_line(e)}") from None
        planned[j.id] = model, desired, policy, predicted, (low, high)
    return planned


def run(args: argparse.Namespace) -> int:
    """Drives the servos along their desired motions; writes run.csv and run.json."""
    js, loaded = _load_run_inputs(args)
    ids = [j.id for j in js]
    tick_s = loaded[ids[0]][0].tick_s
    out = files.out_folder(args.out)
    files.check_writable_all(out, running.output_paths(out, ids))
    files.check_inputs_apart(running.output_paths(out, ids),
                             [args.model, args.servos] + [j.desired for j in js])
    bus, clock = open_bus(args, js)
    _warn_latency(args)
    with bus, session.StopOnSignal() as stop:
        context: dict[str, Any] = {}

        def body() -> tuple[Any, session.TickStats, Optional[BaseException]]:
            context["zeros"], context["changes"] = _prepare(bus, clock, js, say)
            planned = context["planned"] = _plan_joints(args, bus, js, loaded, context["zeros"])
            speeds = {i: args.max_speed_deg_s or planned[i][0].top_speed_deg_s for i in ids}
            try:
                session.move_to(bus, clock, ids, context["zeros"],
                                {i: float(planned[i][1][0]) for i in ids}, tick_s,
                                speed_deg_s=min(60.0, *speeds.values()))
            except (Exception, session.Stopped) as e:  # before the motion: no rows
                return {i: [] for i in ids}, session.TickStats(tick_s), e
            bus.stats.reset()
            result = running.run_servos(bus, clock, ids, {i: planned[i][2] for i in ids},
                                        context["zeros"], {i: planned[i][4] for i in ids},
                                        speeds, tick_s)
            context["counts"] = dict(vars(bus.stats))  # before the torque goes off
            return result

        rows, stats, ended = _session(bus, clock, args, ids, body, stop)
        summary = _run_summary(args, js, context["planned"], rows, stats, ended,
                               context.get("counts", {}), context["zeros"], context["changes"])
        for path in running.write_run(out, rows, stats, summary):
            say(f"wrote {path}")
    say(f"{args.method}{' online' if args.online else ''}: mean abs error "
        f"{summary['mae_deg']:.3f} deg (the model predicted {summary['predicted_mae_deg']:.3f}),"
        f" {summary['ticks']} ticks, {summary['ticks_late']} late, "
        f"{summary['retries']} retries")
    return _ended("run", ended, "the log is written up to there", stop.unreached)


def _run_summary(args: argparse.Namespace, js: Sequence[joints.Joint],
                 planned: Mapping[int, tuple[Any, ...]], rows: Mapping[int, Any],
                 stats: session.TickStats, ended: Optional[BaseException],
                 counts: Mapping[str, int], zeros: Mapping[int, float],
                 changes: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """run.json's content (docs/real-servos.md lists its fields)."""
    all_rows = [r for servo_rows in rows.values() for r in servo_rows]
    policy = planned[js[0].id][2]
    per_servo = {str(j.id): dict(**running.errors(rows[j.id]), predicted_mae_deg=planned[j.id][3],
                                 **joints.settings(j, planned[j.id][0].motor, zeros[j.id]))
                 for j in js}
    return dict(
        method=args.method, online=args.online, rung=args.rung, lead_ticks=args.lead_ticks,
        preview_ticks=policy.planner.preview_ticks if policy.planner else None,
        **running.errors(all_rows),
        predicted_mae_deg=float(np.mean([planned[j.id][3] for j in js])),
        **stats.summary(), tick_s=planned[js[0].id][0].tick_s,
        **{k: counts.get(k, 0) for k in vars(BusStats())},
        ended="completed" if ended is None else session.quit_reason(ended),
        model=os.path.abspath(args.model), servos=per_servo, setup=changes)


def emulate(args: argparse.Namespace) -> int:
    """Serves an emulated bus on a pseudo-terminal until SIGINT or SIGTERM."""
    if args.link and os.path.lexists(args.link):
        raise session.SessionError(f"--link '{args.link}': exists; leglab makes only a new link "
                                   "(remove it, or name another)")
    if args.link and not os.path.isdir(os.path.dirname(os.path.abspath(args.link))):
        raise session.SessionError(f"--link '{args.link}': its folder does not exist")
    if args.silent_ids and not set(args.silent_ids) <= set(args.ids):
        raise session.SessionError(f"--silent-ids: not all among --ids {args.ids}")
    faults = emulator.Faults(drop_rate=args.drop_rate, corrupt_rate=args.corrupt_rate,
                             silent_after_s=args.silent_after_s,
                             silent_ids=tuple(args.silent_ids),
                             hardware_error_after_s=args.hardware_error_after_s, seed=args.seed)
    try:
        if args.kp is not None:
            gain = tables.TABLES[args.motor].item("position_p_gain")
            if args.kp > tables.raw_range(gain)[1]:
                raise ValueError(f"--kp {args.kp}: the {tables.TABLES[args.motor].model}'s gain "
                                 f"register holds at most {tables.raw_range(gain)[1]}")
        emulated = emulator.make_emulator(args.protocol, args.motor, args.ids, args.mass_kg,
                                          args.length_m, kp=args.kp, baud=args.baud,
                                          faults=faults)
    except ValueError as e:
        raise session.SessionError(first_line(e)) from None
    stop: list[bool] = []
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, lambda *_: stop.append(True))
    with session.RealTime(True) as rt:
        if rt.warning:
            print(rt.warning, file=sys.stderr)
        emulator.serve_pty(emulated, lambda path: say(path), lambda: bool(stop), link=args.link)
    return 0
