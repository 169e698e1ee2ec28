"""Your own servo: fit its logs, plan a motion it never made, and drive it on its bus.

Fits the extended servo model to logs (default: the 12 shipped Dynamixel XL330 logs), makes a
pick-and-place motion that is in no log, inside the angles the logs reached, and prints the
model's predicted error of the desired angles sent as they are and of servo.plan's requests.
Then drives a servo on its bus tick by tick (leglab.bus), the desired angles sent as they are
and then servo.ServoPlanner's requests, and prints what the servo did. Without --port the servo
is leglab.bus's emulated XL330 (a DC motor, gearbox, friction and the firmware's P law, not the
model fitted here) on virtual time; with --port, yours. Last, it writes the log of the run in
the CSV form a recording loop of your own should write (servo.write_log).

Run from the repository root after building the package:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/your_servo.py
    PYTHONPATH=build/python /usr/bin/python3 examples/python/your_servo.py \\
        --port /dev/ttyUSB0 --protocol dynamixel --id 1 --zero-deg 180
    PYTHONPATH=build/python /usr/bin/python3 examples/python/your_servo.py my_logs/*.csv \\
        --motor my_servo --kp 32 --mass-kg 0.2 --length-m 0.1 --port /dev/ttyUSB0 \\
        --protocol feetech --id 1

A CSV log does not say its motor, gain and load: --motor, --kp, --mass-kg and --length-m give
them (a BAM .json log has its own). The motion is driven at the first log's kp, mass and length
unless those flags are given. The fit takes about 5 s on the shipped logs (--iterations 300).
On a real servo the torque is on while the script runs: mind the load's swing.
"""

import argparse
import os
import tempfile
import time

import numpy as np

import leglab
import leglab.servo as servo
from leglab import bus
from leglab.bus import session

MOVE_S, HOLD_S = 0.5, 0.4     # each move's duration and each hold's, s
POSES = (0.5, 0.8, 0.2, 0.5)  # home, pick, place, home: fractions of the logs' angle range


def log_files(paths):
    """The log files given: a folder stands for every .json and .csv log in it."""
    files = []
    for path in paths:
        if os.path.isdir(path):
            files += sorted(os.path.join(path, f) for f in os.listdir(path)
                            if f.endswith((".json", ".csv")))
        else:
            files.append(path)
    return files


def pick_and_place(low_deg, high_deg, tick_s):
    """Desired angles, one a tick: hold, ease in/out to the next pose, hold, ..."""
    poses_deg = [low_deg + f * (high_deg - low_deg) for f in POSES]
    s = np.linspace(0.0, 1.0, round(MOVE_S / tick_s) + 1)[1:]
    ease = 3 * s ** 2 - 2 * s ** 3  # smoothstep: zero speed at both ends
    hold = np.ones(round(HOLD_S / tick_s))
    parts = [poses_deg[0] * hold]
    for start_deg, end_deg in zip(poses_deg, poses_deg[1:]):
        parts += [start_deg + (end_deg - start_deg) * ease, end_deg * hold]
    return np.concatenate(parts), poses_deg


def mae(angles_deg, desired_deg):
    """Mean absolute error, deg."""
    return np.mean(np.abs(np.asarray(angles_deg) - desired_deg))


def open_bus(args, drive):
    """(Bus, clock): your port, or the emulated XL330 with the drive's load on virtual time."""
    if args.port:
        return bus.Bus(args.port, args.protocol), bus.RealClock()
    emulated = bus.make_emulator("dynamixel", "xl330-m288", [args.id], drive["mass_kg"],
                                 drive["length_m"])
    clock = bus.VirtualClock()
    return bus.Bus(bus.VirtualPort(emulated, clock), "dynamixel"), clock


def drive_on_bus(the_bus, clock, servo_id, zero_deg, model, method, desired_deg, drive):
    """Moves the servo to the motion's start, then one tick of model.tick_s at a time: read
    its angle, ask for a request (the desired angle for "direct", else a ServoPlanner's), write
    it. Returns the measured angles and the requests sent (deg from the zero), and how many
    ticks were late."""
    session.move_to(the_bus, clock, [servo_id], {servo_id: zero_deg},
                    {servo_id: desired_deg[0]}, model.tick_s)
    planner = None
    if method != "direct":
        planner = servo.ServoPlanner(model, method, **drive)
        planner.reset(desired_deg[0])
    window = (planner.preview_ticks if planner else 0) + 1
    measured_deg, requests_deg = [], []

    def tick(k, _t_s, skipped):
        count = the_bus.sync_read_raw([servo_id], "present_position")[servo_id]
        measured = session.from_count(count, zero_deg)
        if planner is None:
            request = desired_deg[k]
        else:
            for j in range(k - skipped, k):  # ticks the loop missed: the servo kept its request
                planner.hold(desired_deg[j:j + window])
            request = planner.request(desired_deg[k:k + window], measured)
        count = session.to_count(request, zero_deg)
        the_bus.sync_write_raw("goal_position", {servo_id: count})
        measured_deg.append(measured)
        requests_deg.append(session.from_count(count, zero_deg))  # as sent, to the count

    stats = session.run_ticks(clock, model.tick_s, len(desired_deg), tick)
    return np.array(measured_deg), np.array(requests_deg), sum(stats.late)


def on_the_bus(args, model, desired_deg, drive):
    """Sets the servo up as the model assumes, finds its zero, drives it with each method;
    returns {method: (measured, requests)}. The torque goes off however it ends."""
    the_bus, clock = open_bus(args, drive)
    with the_bus:
        try:
            session.set_up(the_bus, [args.id], {args.id: drive["kp"]}, print)
            zero_deg = (args.zero_deg if args.zero_deg is not None else
                        session.find_zero(the_bus, clock, [args.id], print)[args.id])
            runs = {}
            for method in ("direct", "model_based"):
                measured, requests, late = drive_on_bus(the_bus, clock, args.id, zero_deg,
                                                        model, method, desired_deg, drive)
                runs[method] = measured, requests
                print(f"  {method:<12} {mae(measured, desired_deg):6.3f} deg measured "
                      f"({late} ticks late)")
            return runs
        finally:
            session.torque_off(the_bus, [args.id], print)


def main():
    """Fits, plans, runs the online loop and writes a log; prints each step's numbers."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="*", help="log files or folders (default: the XL330's)")
    parser.add_argument("--motor", default="", help="the motor of the CSV logs")
    parser.add_argument("--kp", type=float, help="the CSV logs' gain register, and the motion's")
    parser.add_argument("--mass-kg", type=float, help="the load's mass, kg (CSV logs, motion)")
    parser.add_argument("--length-m", type=float, help="the load's arm, m (CSV logs, motion)")
    parser.add_argument("--iterations", type=int, default=300, help="fit iterations (300)")
    parser.add_argument("--port", help="your servo's port (default: an emulated XL330)")
    parser.add_argument("--protocol", default="dynamixel", choices=("dynamixel", "feetech"))
    parser.add_argument("--id", type=int, default=1, help="your servo's id (1)")
    parser.add_argument("--zero-deg", type=float,
                        help="the zero on the servo's 0-360 scale (default: found limp)")
    args = parser.parse_args()

    # 1. Read the logs.
    shipped = os.path.join(leglab.data_dir(), "data", "servo_logs", "dynamixel-xl330")
    meta = {"motor": args.motor, "kp": args.kp or 0.0, "mass_kg": args.mass_kg or 0.0,
            "length_m": args.length_m or 0.0}
    logs = [servo.read_log(f, **meta) for f in log_files(args.logs or [shipped])]

    # 2. Fit the model on every log (no cross-validation: this is the model to use).
    start = time.perf_counter()
    fit = servo.fit(logs, {"logs.iterations": args.iterations, "logs.cross_validate": "none"})
    model = fit.model(logs[0].motor)
    print(f"{len(logs)} logs of {model.motor} fitted in {time.perf_counter() - start:.1f} s: "
          f"tick {1e3 * model.tick_s:.1f} ms, lag {model.lag_ticks} ticks, top speed "
          f"{model.top_speed_deg_s:.0f} deg/s")
    print(f"the model's mean abs error on the logs (in sample): "
          f"{np.mean([row['mae_deg']['extended'] for row in fit.rows]):.2f} deg")

    # 3. A motion in no log, inside the angles the logs at the drive's gain reached.
    first = logs[0]
    drive = {"kp": args.kp or first.kp,
             "mass_kg": first.mass_kg if args.mass_kg is None else args.mass_kg,
             "length_m": first.length_m if args.length_m is None else args.length_m}
    reached = [log.measured_deg[log.torque_enabled] for log in logs if log.kp == drive["kp"]]
    reached = np.concatenate(reached or [log.measured_deg[log.torque_enabled] for log in logs])
    desired_deg, poses_deg = pick_and_place(reached.min(), reached.max(), model.tick_s)
    print(f"pick and place at kp {drive['kp']:g}, {drive['mass_kg']:g} kg at "
          f"{drive['length_m']:g} m: poses {', '.join(f'{p:.1f}' for p in poses_deg)} deg, "
          f"{len(desired_deg)} ticks ({len(desired_deg) * model.tick_s:.2f} s)")

    # 4. Offline: the model's predicted error, desired angles sent as they are vs planned.
    plans = {m: servo.plan(model, desired_deg, m, **drive) for m in ("model_based", "optimal")}
    print("\noffline (servo.plan), the model's predicted mean abs error:")
    print(f"  {'direct':<12} {mae(plans['optimal']['direct_deg'], desired_deg):6.3f} deg "
          "(the desired angles sent as they are)")
    for method, planned in plans.items():
        print(f"  {method:<12} {mae(planned['predicted_deg'], desired_deg):6.3f} deg "
              f"({planned['beyond_servo'].sum()} ticks beyond the servo)")

    # 5. On the bus: the loop your servo runs, one read and one write a tick.
    where = args.port or "the emulated XL330 (virtual time)"
    print(f"\non the bus, {where}, a tick of {1e3 * model.tick_s:.2f} ms:")
    runs = on_the_bus(args, model, desired_deg, drive)

    # 6. The CSV your own recording loop writes: one row a tick, read back for servo.fit.
    measured_deg, requests_deg = runs["model_based"]
    log = servo.ServoLog(plans["model_based"].time_s, requests_deg, measured_deg,
                         motor=model.motor, trajectory="pick_and_place", **drive)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "pick_and_place.csv")
        servo.write_log(log, path)
        with open(path) as f:
            print(f"\n{path} (servo.write_log), first rows:\n" + "".join(f.readlines()[:4]),
                  end="")
        back = servo.read_log(path, motor=model.motor, **drive)
        assert np.array_equal(back.measured_deg, log.measured_deg)
        print(f"read back: {back!r}")


if __name__ == "__main__":
    main()
