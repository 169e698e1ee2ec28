"""The bodies of `python3 -m leglab.bus`'s verbs (the flags are cli.py's)."""

import glob
import math
import os
import signal
import sys

import numpy as np

from . import emulator, files, joints, record as recording, run as running, session
from .bus import MAX_ID, BusError, BusStats
from .cli import open_bus, say

_SCAN_ITEMS = (  # (column, item, format): what matters to the model, as scan shows it
    ("kp", "position_p_gain", "{:.0f}"), ("ki", "position_i_gain", "{:.0f}"),
    ("kd", "position_d_gain", "{:.0f}"), ("mode", "operating_mode", "{:.0f}"),
    ("delay_us", "return_delay_time", "{:.0f}"), ("prof_vel", "profile_velocity", "{:.0f}"),
    ("prof_acc", "profile_acceleration", "{:.0f}"), ("pos_min", "min_position_limit", "{:.1f}"),
    ("pos_max", "max_position_limit", "{:.1f}"), ("volts", "present_input_voltage", "{:.1f}"),
    ("temp_c", "present_temperature", "{:.0f}"), ("torque", "torque_enable", "{:.0f}"),
    ("pos_deg", "present_position", "{:.1f}"))


def latency_timer_ms(port):
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


def _scan_row(bus, info):
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


def scan(args):
    """Prints the servos on the port and their settings; warns of what spoils a tick."""
    bus, _ = open_bus(args)
    with bus:
        ids = args.ids or range(0, MAX_ID + 1)
        found = bus.scan(ids, timeout_s=min(bus.timeout_s, 0.005))
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


def _id_range(ids):
    ids = list(ids)
    return f"{ids[0]}-{ids[-1]}" if len(ids) > 1 else str(ids[0])


def _prepare(bus, clock, js, say_line):
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
    zeros = {j.id: j.zero_deg for j in js if not math.isnan(j.zero_deg)}
    unknown = [i for i in ids if i not in zeros]
    if unknown:
        zeros.update(session.find_zero(bus, clock, unknown, say_line))
    return zeros, changes


def _session(bus, clock, args, ids, body):
    """Runs `body()` with the servos' torque turned off however it ends, real time asked for
    and signals caught; returns what body returns."""
    try:
        with session.StopOnSignal(), session.RealTime(not args.no_realtime) as rt:
            if rt.warning and not isinstance(clock, emulator.VirtualClock):
                say(rt.warning)
            return body()
    finally:
        # A second signal must not cut the way out short: held until the torque is off.
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
        try:
            session.torque_off(bus, ids, say)
        finally:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})


def _ended(verb, ended, what):
    """The exit status of a session that `ended` (None: completed), its line said."""
    if ended is None:
        return 0
    print(f"leglab.bus {verb}: {session.quit_reason(ended)}; the torque is off and {what} "
          "written up to there", file=sys.stderr)
    return 2 if isinstance(ended, (BusError, session.Stopped)) else 1


def record(args):
    """Records each trajectory on every servo; one log per servo and trajectory."""
    js = joints.joints(args, verb="record")
    ids = [j.id for j in js]
    out = files.out_folder(args.out)
    bus, clock = open_bus(args, js)
    written = []
    with bus:
        zeros, changes = _prepare(bus, clock, js, say)

        def body():
            for name in args.trajectory:
                samples, stats, ended = recording.record_trajectory(
                    bus, clock, ids, name, args.tick_s, zeros, say)
                meta = {j.id: _log_meta(args, bus, name, j, zeros[j.id], changes, ended)
                        for j in js}
                if any(samples.values()):
                    written.extend(recording.write_logs(out, samples, stats, meta, bus))
                if ended is not None:
                    return ended
            return None

        ended = _session(bus, clock, args, ids, body)
    for path in written:
        say(f"wrote {path}")
    return _ended("record", ended, "the logs are")


def _log_meta(args, bus, trajectory, joint, zero_deg, changes, ended):
    """A log's fields beside its entries: BAM's (mass, length, kp, vin, motor, trajectory),
    which identify reads, and the session's (docs/real-servos.md lists them)."""
    return dict(mass=joint.mass_kg, length=joint.length_m, kp=joint.kp,
                vin=_supply_volts(bus, joint.id, ended), motor=joint.motor,
                trajectory=trajectory, id=joint.id, model=bus.table(joint.id).model,
                protocol=args.protocol, port=bus.port_name, zero_deg=zero_deg,
                tick_s=args.tick_s, setup=[c for c in changes if c["id"] == joint.id],
                recorded_by="python3 -m leglab.bus record",
                ended="completed" if ended is None else session.quit_reason(ended))


def _supply_volts(bus, servo_id, ended):
    """The servo's supply now (None when the session ended on a fault: the bus may be gone)."""
    if ended is not None:
        return None
    return bus.read(servo_id, "present_input_voltage")


def _plan_joint(args, fit, joint):
    """(model, desired on its tick, Policy, predicted MAE) of one joint; SessionError naming
    the file, servo or flag, before anything opens the port."""
    from .. import servo

    try:
        model = fit.model(joint.motor or None, rung=args.rung)
        desired = servo.read_desired(joint.desired, model.tick_s)
    except (ValueError, OSError) as e:
        raise session.SessionError(f"servo {joint.id}: {str(e).splitlines()[0]}") from None
    outside = (desired < joint.min_deg) | (desired > joint.max_deg)
    if outside.any():
        at = int(np.argmax(outside))
        raise session.SessionError(
            f"servo {joint.id}: --desired '{joint.desired}': the desired angle {desired[at]:g} "
            f"deg at tick {at} is outside [--min-deg, --max-deg] = [{joint.min_deg:g}, "
            f"{joint.max_deg:g}]: nothing moved")
    drive = dict(kp=joint.kp, mass_kg=joint.mass_kg, length_m=joint.length_m)
    limits = (joint.min_deg, joint.max_deg)
    if args.lead_ticks and args.method != "direct":
        raise session.SessionError(f"--lead-ticks {args.lead_ticks}: only with --method direct "
                                   "(the planned methods lead by the model's own lag)")
    try:
        policy = running.Policy(model, desired, args.method, args.online, args.preview_ticks,
                                drive, limits, args.lead_ticks)
        predicted = running.predicted_mae_deg(model, policy, drive)
    except ValueError as e:
        raise session.SessionError(f"servo {joint.id}: {str(e).splitlines()[0]}") from None
    return model, desired, policy, predicted


def _load_run_inputs(args):
    """The joints and, per joint, its model, desired motion, Policy and predicted error; all
    on one tick and of one length (SessionError otherwise)."""
    from .. import servo

    js = joints.joints(args, verb="run")
    try:
        fit = servo.LogFit.load(args.model)
    except (ValueError, OSError) as e:
        raise session.SessionError(f"--model: {str(e).splitlines()[0]}") from None
    planned = {j.id: _plan_joint(args, fit, j) for j in js}
    first = planned[js[0].id]
    for j in js[1:]:
        model, desired = planned[j.id][:2]
        if model.tick_s != first[0].tick_s or len(desired) != len(first[1]):
            raise session.SessionError(
                f"servo {j.id}: its model's tick ({model.tick_s:g} s) and motion ({len(desired)} "
                f"ticks) must be servo {js[0].id}'s ({first[0].tick_s:g} s, {len(first[1])} "
                "ticks): one loop drives them all")
    return js, planned


def run(args):
    """Drives the servos along their desired motions; writes run.csv and run.json."""
    js, planned = _load_run_inputs(args)
    ids = [j.id for j in js]
    model = planned[ids[0]][0]
    out = files.out_folder(args.out)
    bus, clock = open_bus(args, js)
    with bus:
        zeros, changes = _prepare(bus, clock, js, say)
        policies = {i: planned[i][2] for i in ids}
        limits = {j.id: (j.min_deg, j.max_deg) for j in js}
        speeds = {i: args.max_speed_deg_s or planned[i][0].top_speed_deg_s for i in ids}

        def body():
            session.move_to(bus, clock, ids, zeros,
                            {i: float(planned[i][1][0]) for i in ids}, model.tick_s)
            bus.stats.reset()
            result = running.run_servos(bus, clock, ids, policies, zeros, limits, speeds,
                                        model.tick_s)
            in_loop.update(vars(bus.stats))  # before the torque goes off
            return result

        in_loop = {}
        rows, stats, ended = _session(bus, clock, args, ids, body)
        summary = _run_summary(args, js, planned, rows, stats, ended, in_loop, zeros, changes)
        for path in running.write_run(out, rows, stats, summary):
            say(f"wrote {path}")
    say(f"{args.method}{' online' if args.online else ''}: mean abs error "
        f"{summary['mae_deg']:.3f} deg (the model predicted {summary['predicted_mae_deg']:.3f}),"
        f" {summary['ticks']} ticks, {summary['ticks_late']} late, "
        f"{summary['retries']} retries")
    return _ended("run", ended, "the log is")


def _run_summary(args, js, planned, rows, stats, ended, counts, zeros, changes):
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


def emulate(args):
    """Serves an emulated bus on a pseudo-terminal until SIGINT or SIGTERM."""
    faults = emulator.Faults(drop_rate=args.drop_rate, corrupt_rate=args.corrupt_rate,
                             silent_after_s=args.silent_after_s,
                             silent_ids=tuple(args.silent_ids),
                             hardware_error_after_s=args.hardware_error_after_s, seed=args.seed)
    emulated = emulator.make_emulator(args.protocol, args.motor, args.ids, args.mass_kg,
                                      args.length_m, kp=args.kp, baud=args.baud, faults=faults)
    stop = []
    for s in (signal.SIGINT, signal.SIGTERM):
        signal.signal(s, lambda *_: stop.append(True))
    with session.RealTime(True) as rt:
        if rt.warning:
            print(rt.warning, file=sys.stderr)
        emulator.serve_pty(emulated, lambda path: say(path), lambda: bool(stop), link=args.link)
    return 0

