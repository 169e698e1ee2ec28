"""The bodies of `python3 -m leglab.bus`'s verbs (the flags are cli.py's)."""

import glob
import os
import signal
import sys

import numpy as np

from . import emulator, files, record as recording, run as running, session
from .bus import MAX_ID, BusError
from .cli import open_bus, say

_SCAN_ITEMS = (  # (column, item, format): what matters to the model, as scan shows it
    ("kp", "position_p_gain", "{:.0f}"), ("ki", "position_i_gain", "{:.0f}"),
    ("kd", "position_d_gain", "{:.0f}"), ("mode", "operating_mode", "{:.0f}"),
    ("delay_us", "return_delay_time", "{:.0f}"), ("prof_vel", "profile_velocity", "{:.0f}"),
    ("prof_acc", "profile_acceleration", "{:.0f}"), ("min_deg", "min_position_limit", "{:.1f}"),
    ("max_deg", "max_position_limit", "{:.1f}"), ("volts", "present_input_voltage", "{:.1f}"),
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
    bus, _ = open_bus(args, args.ids or [1])
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
        if latency is not None and latency > 1:
            say(f"warning: the USB adapter's latency timer is {latency} ms (above 1 ms, each "
                f"reply waits up to it): echo 1 | sudo tee /sys/bus/usb-serial/devices/"
                f"{os.path.basename(os.path.realpath(args.port))}/latency_timer")
    return 0


def _id_range(ids):
    ids = list(ids)
    return f"{ids[0]}-{ids[-1]}" if len(ids) > 1 else str(ids[0])


def _prepare(bus, clock, args, say_line):
    """The servos found and set up as the model assumes; the zeros. Returns {id: zero_deg}."""
    for servo_id in args.ids:
        table = bus.table(servo_id)
        gain = table.item("position_p_gain")
        if args.kp > (1 << (8 * gain.size)) - 1:
            raise session.SessionError(f"--kp {args.kp}: servo {servo_id}'s gain register holds "
                                       f"at most {(1 << (8 * gain.size)) - 1}")
    session.check_health(bus, args.ids)
    changes = session.set_up(bus, args.ids, {i: args.kp for i in args.ids}, say_line)
    if args.zero_deg is not None:
        zeros = {i: args.zero_deg for i in args.ids}
    else:
        zeros = session.find_zero(bus, clock, args.ids, say_line)
    return zeros, changes


def _session(bus, clock, args, body):
    """Runs `body()` with the servos' torque turned off however it ends, real time asked for
    and signals caught; a fault ends it with the one line it raised (exit 2)."""
    ids = args.ids
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


def record(args):
    """Records each trajectory on every servo; one log per servo and trajectory."""
    out = files.out_folder(args.out)
    bus, clock = open_bus(args, args.ids, args.mass_kg, args.length_m)
    written = []
    with bus:
        zeros, changes = _prepare(bus, clock, args, say)

        def body():
            for name in args.trajectory:
                samples, stats, ended = recording.record_trajectory(
                    bus, clock, args.ids, name, args.tick_s, zeros, say)
                meta = {i: _log_meta(args, bus, name, i, zeros[i], changes, ended)
                        for i in args.ids}
                if any(samples.values()):
                    written.extend(recording.write_logs(out, samples, stats, meta, bus))
                if ended is not None:
                    return ended
            return None

        ended = _session(bus, clock, args, body)
    for path in written:
        say(f"wrote {path}")
    if ended is not None:
        print(f"leglab.bus record: {session.quit_reason(ended)}; the torque is off and the "
              "logs are written up to there", file=sys.stderr)
        return 2 if isinstance(ended, (BusError, session.Stopped)) else 1
    return 0


def _log_meta(args, bus, trajectory, servo_id, zero_deg, changes, ended):
    table = bus.table(servo_id)
    return {"mass": args.mass_kg, "length": args.length_m, "kp": args.kp,
            "vin": _supply_volts(bus, servo_id, ended), "motor": args.motor,
            "trajectory": trajectory, "id": servo_id, "model": table.model,
            "protocol": args.protocol, "port": bus.port_name, "zero_deg": zero_deg,
            "tick_s": args.tick_s, "setup": [c for c in changes if c["id"] == servo_id],
            "recorded_by": "python3 -m leglab.bus record",
            "ended": "completed" if ended is None else session.quit_reason(ended)}


def _supply_volts(bus, servo_id, ended):
    """The servo's supply now (None when the session ended on a fault: the bus may be gone)."""
    if ended is not None:
        return None
    return bus.read(servo_id, "present_input_voltage")


def _load_run_inputs(args):
    """The model, the desired motion on its tick and the policies' inputs; SessionError
    (naming the file or flag) before anything opens the port."""
    from .. import servo

    try:
        model = servo.LogFit.load(args.model).model(args.motor or None)
        desired = servo._leglab._read_desired(args.desired, model.tick_s)["desired_deg"]
    except (ValueError, OSError) as e:
        raise session.SessionError(str(e).splitlines()[0]) from None
    if args.min_deg >= args.max_deg:
        raise session.SessionError(f"--min-deg {args.min_deg:g} is not below --max-deg "
                                   f"{args.max_deg:g}")
    low, high = float(np.min(desired)), float(np.max(desired))
    if low < args.min_deg or high > args.max_deg:
        at = int(np.argmax((desired < args.min_deg) | (desired > args.max_deg)))
        raise session.SessionError(
            f"--desired '{args.desired}': the desired angle {desired[at]:g} deg at tick {at} is "
            f"outside [--min-deg, --max-deg] = [{args.min_deg:g}, {args.max_deg:g}]: nothing moved")
    drive = {"kp": args.kp, "mass_kg": args.mass_kg, "length_m": args.length_m}
    limits = (args.min_deg, args.max_deg)
    try:
        policy = running.Policy(model, desired, args.method, args.online, args.preview_ticks,
                                drive, limits)
        predicted = running.predicted_mae_deg(model, desired, args.method, drive, limits)
    except ValueError as e:
        raise session.SessionError(str(e).splitlines()[0]) from None
    return model, desired, drive, limits, policy, predicted


def run(args):
    """Drives the servos along --desired; writes run.csv and run.json."""
    model, desired, drive, limits, policy, predicted = _load_run_inputs(args)
    out = files.out_folder(args.out)
    bus, clock = open_bus(args, args.ids, args.mass_kg, args.length_m)
    with bus:
        zeros, changes = _prepare(bus, clock, args, say)
        policies = {i: policy if n == 0 else running.Policy(
            model, desired, args.method, args.online, args.preview_ticks, drive, limits)
            for n, i in enumerate(args.ids)}
        speed = args.max_speed_deg_s or model.top_speed_deg_s

        def body():
            session.move_to(bus, clock, args.ids, zeros, {i: float(desired[0]) for i in args.ids},
                            model.tick_s)
            bus.stats.reset()
            return running.run_servos(bus, clock, args.ids, policies, zeros, limits, speed,
                                      model.tick_s)

        rows, stats, ended = _session(bus, clock, args, body)
        summary = _run_summary(args, model, rows, stats, ended, bus, zeros, changes, predicted,
                               policy)
        for path in running.write_run(out, rows, stats, summary):
            say(f"wrote {path}")
    say(f"{args.method}{' online' if args.online else ''}: mean abs error "
        f"{summary['mae_deg']:.3f} deg (the model predicted {predicted:.3f}), "
        f"{summary['ticks']} ticks, {summary['ticks_late']} late, "
        f"{summary['retries']} retries")
    if ended is not None:
        print(f"leglab.bus run: {session.quit_reason(ended)}; the torque is off and the "
              "log is written up to there", file=sys.stderr)
        return 2 if isinstance(ended, (BusError, session.Stopped)) else 1
    return 0


def _run_summary(args, model, rows, stats, ended, bus, zeros, changes, predicted, policy):
    all_rows = [r for servo_rows in rows.values() for r in servo_rows]
    per_servo = {str(i): {**running.errors(r), "zero_deg": zeros[i]} for i, r in rows.items()}
    return {
        "method": args.method, "online": args.online,
        "preview_ticks": policy.planner.preview_ticks if policy.planner else None,
        **running.errors(all_rows), "predicted_mae_deg": predicted,
        **stats.summary(), "tick_s": model.tick_s, "retries": bus.stats.retries,
        "errors": bus.stats.errors, "missing": bus.stats.missing, "corrupt": bus.stats.corrupt,
        "ended": "completed" if ended is None else session.quit_reason(ended),
        "model": os.path.abspath(args.model), "motor": model.motor, "kp": args.kp,
        "mass_kg": args.mass_kg, "length_m": args.length_m,
        "limits": {"min_deg": args.min_deg, "max_deg": args.max_deg},
        "servos": per_servo, "setup": changes}


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

