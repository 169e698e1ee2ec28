#!/usr/bin/python3
"""The whole servo loop on an emulated bus, per protocol, as a servo owner runs it: record BAM's
four excitations at one gain, fit them with `identify`, and run a pick-and-place motion that no
log holds with each method, on virtual time (the same bits every run).

Usage: PYTHONPATH=DIR/python /usr/bin/python3 scripts/bus_loop.py OUT [--build DIR]   (DIR: build)

Writes OUT/bus/<protocol>/: logs/ (record's), fit/ (identify's), inputs/pick.csv (the desired
motion) and one folder per run (run.csv, run.json): direct; best_lead (the desired angles sent
early by the lead that did best, in hindsight); paper_model_based_online (the paper's model);
model_based, model_based_online, optimal, optimal_online (the extended model). The emulated servos are an XL330-M288 on BAM's pendulum
(0.49 kg at 0.1 m, kp 400; Dynamixel 2.0) and an STS3215 with 0.5 kg at 0.12 m (kp 32;
Feetech), leglab.bus.physics: not the model leglab fits. docs/results/servos.md's bus-loop table is
read from the run.json files. Bad input: one line, exit status 2.
"""

import json
import os
import pathlib
import shutil
import subprocess
import sys

try:
    from leglab.bus import trajectories
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"bus_loop.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

SOURCE_DIR = pathlib.Path(__file__).resolve().parent.parent
ENV = dict(os.environ)

# protocol: (emulated model, the logs' motor name, kp register, mass_kg, length_m)
BENCHES = {"dynamixel": ("xl330-m288", "xl330", 400, 0.49, 0.1),
           "feetech": ("sts3215", "sts3215", 32, 0.5, 0.12)}
TRAJECTORIES = ("lift_and_drop", "sin_time_square", "up_and_down", "sin_sin")
RUNS = (("direct", ["--method", "direct"]),
        ("paper_model_based_online", ["--method", "model_based", "--online", "--rung", "paper"]),
        ("model_based", ["--method", "model_based"]),
        ("model_based_online", ["--method", "model_based", "--online"]),
        ("optimal", ["--method", "optimal"]),
        ("optimal_online", ["--method", "optimal", "--online"]))
"""(folder, run's flags) of each run, beside best_lead (below)."""
LEADS = range(0, 21)
"""The leads (ticks) best_lead tries: the desired angles sent early, the best in hindsight."""




def bus(*args):
    """python3 -m leglab.bus ARGS (the package of --build); its stderr and exit 2 on failure."""
    done = subprocess.run([sys.executable, "-m", "leglab.bus", *map(str, args)],
                          capture_output=True, text=True, env=ENV)
    if done.returncode != 0:
        sys.exit(f"bus_loop: {done.stderr.strip()}")


def loop(out, protocol, build):
    """One protocol's record, fit and runs into `out`."""
    model, motor, kp, mass, length = BENCHES[protocol]
    out.mkdir(parents=True, exist_ok=True)
    servo = ["--port", f"emulator:{model}", "--protocol", protocol, "--id", "1", "--kp", kp,
             "--mass-kg", mass, "--length-m", length]
    bus("record", *servo, "--motor", motor, "--trajectory", ",".join(TRAJECTORIES),
        "--out", out / "logs")
    fit = subprocess.run([build / "bin" / "identify", "--config",
                          SOURCE_DIR / "experiments/configs/identify_logs.yaml", "--out",
                          out / "fit", "--set", f"logs.train=[{out / 'logs'}]", "--set",
                          "logs.cross_validate=none"], capture_output=True, text=True)
    if fit.returncode != 0:
        sys.exit(f"bus_loop: identify: {fit.stderr.strip()}")
    desired = out / "inputs" / "pick.csv"
    desired.parent.mkdir(exist_ok=True)
    trajectories.write_desired_csv(desired, trajectories.pick_and_place_deg())
    common = [*servo, "--model", out / "fit" / "log_fit.json", "--desired", desired]
    for folder, flags in RUNS:
        bus("run", *common, *flags, "--out", out / folder)
    best_lead(out, common)


def best_lead(out, common):
    """best_lead/: the direct run whose lead (LEADS) gave the least error, chosen on the run
    itself (an oracle in hindsight, as identify's best shift)."""
    errors = {}
    (out / "leads").mkdir(exist_ok=True)
    for lead in LEADS:
        folder = out / "leads" / str(lead)
        bus("run", *common, "--method", "direct", "--lead-ticks", lead, "--out", folder)
        with open(folder / "run.json") as f:
            errors[lead] = json.load(f)["mae_deg"]
    best = min(errors, key=errors.get)
    shutil.rmtree(out / "best_lead", ignore_errors=True)
    shutil.copytree(out / "leads" / str(best), out / "best_lead")
    shutil.rmtree(out / "leads")


def main():
    """Runs every protocol's loop."""
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=pathlib.Path)
    parser.add_argument("--build", type=pathlib.Path, default=SOURCE_DIR / "build")
    args = parser.parse_args()
    ENV["PYTHONPATH"] = str(args.build / "python")
    if not args.out.is_dir():
        sys.exit(f"bus_loop: {args.out}: not a folder")
    for protocol in BENCHES:
        loop(args.out / "bus" / protocol, protocol, args.build)
    print(f"bus_loop: {len(BENCHES) * (len(RUNS) + len(LEADS))} runs in {args.out / 'bus'}")


if __name__ == "__main__":
    main()
