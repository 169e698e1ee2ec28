"""How leglab.bus keeps its tick on a real port: `run` against the emulator on a pseudo-terminal,
in real time, quiet and with both cores kept busy.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/bus_tick_benchmark.py \
        [--ticks N] [--servos 1,6] [--out DIR]

For each servo count (default 1 and 6 XL330s at 1 Mbaud, Dynamixel 2.0):
  (a) the tick's work: one sync read, the online model_based planner per servo, one sync write,
      wire time included (the emulator holds each reply until it would have arrived on a real
      bus at the baud rate): median, p99 and max, ms. Targets: one servo within 2 ms, six
      within 4 ms;
  (b) --ticks ticks (default 10^4, 50 s) of a 5 ms tick: the share of late ticks (a tick whose
      write ended after the next tick began, or that followed skipped ticks), the period's
      median, p99 and max. Target: at most 1 %;
  (c) the same run while two busy loops at normal priority keep both cores busy (what a camera
      and a policy do to a robot's computer): the share of late ticks (target at most 2 %) and
      the run's mean absolute error against the quiet run's (target at most 1.25x).

The model is fitted first, on the emulator on virtual time (record the four BAM trajectories at
kp 400, identify). The motion is the tests' pick-and-place repeated to --ticks. `run` and the
emulator ask for real-time priority (SCHED_FIFO; as root here) and say when they get none.
Nothing is asserted: the targets are printed beside the figures.
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
BENCH = ["--kp", "400", "--mass-kg", "0.49", "--length-m", "0.1"]


def bus(*args):
    """python3 -m leglab.bus ARGS; exits with its stderr if it fails."""
    done = subprocess.run([sys.executable, "-m", "leglab.bus", *map(str, args)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bus_tick_benchmark: {done.stderr.strip()}")
    return done


def fit(folder, build):
    """Records the four BAM trajectories on the emulator (virtual time) and fits them."""
    bus("record", "--port", "emulator:xl330-m288", "--protocol", "dynamixel", "--id", "1",
        "--motor", "xl330", *BENCH, "--trajectory",
        "lift_and_drop,sin_time_square,up_and_down,sin_sin", "--out", folder / "logs")
    subprocess.run([build / "bin" / "identify", "--config",
                    ROOT / "experiments/configs/identify_logs.yaml", "--out", folder / "fit",
                    "--set", f"logs.train=[{folder / 'logs'}]", "--set",
                    "logs.cross_validate=none"], check=True, capture_output=True)
    return folder / "fit" / "log_fit.json"


def desired_csv(path, ticks):
    """The pick-and-place motion (leglab.bus.trajectories) repeated to `ticks` ticks of 5 ms."""
    from leglab.bus import trajectories  # pylint: disable=import-outside-toplevel
    cycle = trajectories.pick_and_place_deg()
    trajectories.write_desired_csv(path, np.resize(cycle, ticks))


def run_on_pty(model, desired, servos, out, load):
    """One real-time run on a fresh emulator; `load`: busy processes alongside. run.json."""
    ids = ",".join(str(i) for i in range(1, servos + 1))
    emulate = subprocess.Popen(
        [sys.executable, "-m", "leglab.bus", "emulate", "--protocol", "dynamixel", "--motor",
         "xl330-m288", "--ids", ids, "--mass-kg", "0.49", "--length-m", "0.1"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    busy = [subprocess.Popen(["sh", "-c", "while :; do :; done"]) for _ in range(load)]
    try:
        port = emulate.stdout.readline().strip()
        done = bus("run", "--port", port, "--protocol", "dynamixel", "--id", ids, "--model",
                   model, "--desired", desired, "--method", "model_based", "--online",
                   *BENCH, "--zero-deg", "180", "--out", out)
        warnings = [line for line in done.stdout.splitlines() if line.startswith("warning")]
    finally:
        for p in busy:
            p.kill()
        emulate.terminate()
        emulate.wait()
    with open(pathlib.Path(out) / "run.json") as f:
        return json.load(f), warnings


def main():
    """Measures and prints (a)-(c) for each servo count."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=10000)
    parser.add_argument("--servos", default="1,6")
    parser.add_argument("--build", type=pathlib.Path, default=ROOT / "build")
    parser.add_argument("--out", type=pathlib.Path)
    args = parser.parse_args()
    folder = args.out or pathlib.Path(tempfile.mkdtemp(prefix="bus_tick_"))
    folder.mkdir(parents=True, exist_ok=True)
    model = fit(folder, args.build)
    desired = folder / "desired.csv"
    desired_csv(desired, args.ticks)
    for servos in (int(n) for n in args.servos.split(",")):
        quiet, warnings = run_on_pty(model, desired, servos, folder / f"quiet_{servos}", 0)
        busy, _ = run_on_pty(model, desired, servos, folder / f"busy_{servos}", 2)
        for line in warnings:
            print(line)
        target = 2.0 if servos == 1 else 4.0
        w, p = quiet["work_ms"], quiet["period_ms"]
        print(f"{servos} servo(s), {quiet['ticks']} ticks of 5 ms:")
        print(f"  (a) work median {w['median']:.3f} ms, p99 {w['p99']:.3f}, max {w['max']:.3f} "
              f"(target p99 <= {target:g} ms)")
        print(f"  (b) quiet: {100 * quiet['ticks_late'] / quiet['ticks']:.2f} % late "
              f"(target <= 1 %), period median {p['median']:.3f} ms, p99 {p['p99']:.3f}, "
              f"max {p['max']:.3f}; MAE {quiet['mae_deg']:.3f} deg")
        p = busy["period_ms"]
        print(f"  (c) both cores busy: {100 * busy['ticks_late'] / busy['ticks']:.2f} % late "
              f"(target <= 2 %), period p99 {p['p99']:.3f} ms, max {p['max']:.3f}; MAE "
              f"{busy['mae_deg']:.3f} deg = {busy['mae_deg'] / quiet['mae_deg']:.3f}x the quiet "
              "run's (target <= 1.25x)")
    print(f"runs in {folder}")


if __name__ == "__main__":
    os.environ.setdefault("PYTHONPATH", str(ROOT / "build" / "python"))
    main()
