"""The cost of a short preview for the online servo planner: `plan --online --preview-ticks N`
against the batch `plan`, on a motor's logs taken as desired motions.

    /usr/bin/python3 scripts/online_preview_table.py --model results/servo_logs/log_fit.json \
        --out results/servo_logs/online [--motor xl330] [--kp 400] [--build build]

Writes preview.md (the table docs/results/servos.md shows), preview.json (every run's predicted
mean absolute error from the desired motion, deg, over all its ticks: plan.json's
predicted_mae_deg.planned) and preview_rms.json (the root mean square of the same errors,
predicted_rms_deg.planned: the optimal plans' objective as an angle) into --out; each run's own
files go to a temporary folder. Online optimal runs with --budget-ms 0 (its iteration cap
alone), so that the table is the same on every machine.

Bad input (a flag, the model file, a log plan refuses) prints one line naming it and exits 2; a
plan run that fails otherwise is a bug, exit 1. Either way nothing is written: the three files
are written once every run has succeeded.
"""

import json
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile

try:
    from leglab.results.reader import (ArgumentParser, non_finite_field, one_line, read_json,
                                       write_all_or_nothing)
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"online_preview_table.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

MODEL_BASED_PREVIEWS = (0, 1, 2)
OPTIMAL_PREVIEWS = (2, 5, 10, 20, 40, 62, 120, 250)
DEFAULT = "default"  # plan's own preview for online optimal
OUTPUTS = ("preview.md", "preview.json", "preview_rms.json")


class BadInput(Exception):
    """Bad input (a flag, the model file, a log plan refuses): one line, exit status 2."""


class PlanFailed(Exception):
    """plan failed other than on bad input, or wrote what it never writes: a bug, exit 1."""


def planned_errors(plan, args, log, method, out, preview=None, extra=()):
    """Runs plan on `log` and returns its predicted mean absolute and root mean square errors
    (deg); plan's refusal is BadInput, its failure PlanFailed, each its first error line
    prefixed with the log and the run."""
    command = [str(plan), "--model", args.model, "--motor", args.motor, "--method", method,
               "--desired", str(log), "--out", str(out)]
    if preview is not None:
        command += ["--online"] + (["--preview-ticks", str(preview)] if preview != DEFAULT else [])
        if method == "optimal":
            command += ["--budget-ms", "0", *extra]
    run = f"{log.name}, {method} {'batch' if preview is None else f'online, preview {preview}'}"
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        first = next((line for line in done.stderr.splitlines() if line.strip()),
                     "nothing on stderr")
        if done.returncode == 2:
            raise BadInput(f"{run}: {first}")
        raise PlanFailed(f"{run}: plan failed (exit {done.returncode}): {first}")
    try:
        summary = read_json(out / "plan.json")
        if preview == DEFAULT:
            return int(summary.online.preview_ticks)
        errors = summary["predicted_mae_deg"]["planned"], summary["predicted_rms_deg"]["planned"]
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as e:
        raise PlanFailed(f"{run}: plan.json is not plan's ({e})") from None
    if non_finite_field(list(errors)) is not None:
        raise PlanFailed(f"{run}: plan predicted a non-finite error {errors}")
    return errors


def plan_program(build):
    """bin/plan of the build folder `build`; BadInput when it is not there."""
    plan = pathlib.Path(build) / "bin" / "plan"
    if not plan.is_file() or not os.access(plan, os.X_OK):
        raise BadInput(f"--build {build}: no program bin/plan (build it first)")
    return plan


def model_lag(path, motor):
    """The lag (ticks) of `motor`'s extended model in identify's log fit at `path`; BadInput
    naming the file and the field when it is not one, or lacks the motor."""
    where = f"--model {path}"
    if not os.path.isfile(path):
        raise BadInput(f"{where}: {'not a file' if os.path.exists(path) else 'no such file'}")
    try:
        fit = read_json(path)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as e:
        raise BadInput(f"{where}: not identify's log fit ({e})") from None
    field = non_finite_field(fit)
    if field is not None:
        raise BadInput(f"{where}: {field} is not a finite number")
    try:
        motors = fit.models.extended
        if not isinstance(motors, dict):
            raise TypeError("not an object")
    except (AttributeError, TypeError) as e:
        raise BadInput(f"{where}: no models.extended as identify writes it ({e})") from None
    if not isinstance(motors.get(motor), dict):
        raise BadInput(f"--motor {motor}: not in {where} (its motors: "
                       f"{', '.join(map(str, motors)) or 'none'})")
    try:
        lag = motors[motor].lag_ticks
    except AttributeError as e:
        raise BadInput(f"{where}: models.extended.{motor}: {e}") from None
    if isinstance(lag, bool) or not isinstance(lag, int) or lag < 0:
        raise BadInput(f"{where}: models.extended.{motor}: its lag {lag!r} is not a whole "
                       "number of ticks")
    return lag


def output_folder(out):
    """`out` (a path), refused before any run when its outputs could not be written there: it,
    or the nearest folder above it that exists, is not a folder, or a folder takes an output's
    place."""
    existing = out
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise BadInput(f"--out {out}: {existing} is not a folder")
    taken = [name for name in OUTPUTS if (out / name).is_dir()]
    if taken:
        raise BadInput(f"--out {out}: {taken[0]} is a folder")
    return out


def write_outputs(out, texts):
    """Writes {name: text} into `out`, all or none (write_all_or_nothing)."""
    try:
        write_all_or_nothing({out / name: text for name, text in texts.items()})
    except OSError as e:
        raise BadInput(f"--out {out}: cannot be written ({e.strerror or e})") from None


def run_table(args, plan, logs, names, lag, runs):
    """Every plan of the table, run in folders under `runs`: ({label: {name: MAE}}, the same
    for RMS)."""
    horizon = lag + 1
    rows = [("batch model_based", "model_based", None, ()),
            ("batch optimal", "optimal", None, ())]
    rows += [(f"online model_based, preview {p}", "model_based", p, ())
             for p in MODEL_BASED_PREVIEWS]
    rows += [(f"online optimal, preview {p}", "optimal", p, ()) for p in OPTIMAL_PREVIEWS]
    own = planned_errors(plan, args, logs[0], "optimal", runs / "default", DEFAULT)
    rows.append((f"online optimal, preview {own} (its default)", "optimal", own, ()))
    # The longest preview, the last desired angle held as long again after it, and the hand-over
    # at its least (two horizons): the planner nearest the batch optimum.
    longest = OPTIMAL_PREVIEWS[-1]
    rows.append((f"online optimal, preview {longest}, hold {longest}, hand-over {2 * horizon}",
                 "optimal", longest,
                 ("--hold-ticks", str(longest), "--handover-ticks", str(2 * horizon))))
    table, rms = {}, {}
    for label, method, preview, extra in rows:
        table[label], rms[label] = {}, {}
        for name, log in zip(names, logs):
            folder = runs / f"{name}_{method}_{'batch' if preview is None else preview}"
            table[label][name], rms[label][name] = planned_errors(
                plan, args, log, method, folder, preview, extra)
    return table, rms


def texts_of(args, names, table, rms, horizon):
    """preview.md's lines and the three files' texts."""
    lines = [f"| plan ({args.motor}, kp {args.kp}), MAE (RMS) | " + " | ".join(names) + " |",
             "|---" * (len(names) + 1) + "|"]
    for label, row in table.items():
        lines.append(f"| {label} | " + " | ".join(f"{row[n]:.2f} ({rms[label][n]:.2f})"
                                                  for n in names) + " |")
    lines += ["", above_model_based(rms, names, horizon)]
    return lines, {"preview.json": json.dumps(table, indent=2, allow_nan=False) + "\n",
                   "preview_rms.json": json.dumps(rms, indent=2, allow_nan=False) + "\n",
                   "preview.md": "\n".join(lines) + "\n"}


def main():
    """Parses the flags, checks them, runs every plan and writes the table."""
    parser = ArgumentParser(prog="online_preview_table", description=__doc__.splitlines()[0])
    parser.add_argument("--model", required=True, help="identify's log_fit.json")
    parser.add_argument("--out", required=True, help="folder for preview.md and preview.json")
    parser.add_argument("--motor", default="xl330", help="the motor (default xl330)")
    parser.add_argument("--kp", default="400", help="the gain setting of the logs (default 400)")
    parser.add_argument("--build", default="build", help="the build folder (default build)")
    args = parser.parse_args()
    try:
        plan = plan_program(args.build)
        lag = model_lag(args.model, args.motor)
        if not re.fullmatch(r"[0-9]+(\.[0-9]+)?", args.kp):
            raise BadInput(f"--kp {args.kp}: expected a gain setting (a number)")
        folders = {"xl330": "dynamixel-xl330", "sts3250": "feetech-sts3250"}
        folder = pathlib.Path("data/servo_logs") / folders.get(args.motor, args.motor)
        logs = sorted(folder.glob(f"*_kp{args.kp}_*.json"))
        if not logs:
            raise BadInput(f"--kp {args.kp}: no {args.motor} log at kp {args.kp} in {folder}")
        out = output_folder(pathlib.Path(args.out))
        names = [log.name.split(f"_kp{args.kp}_")[0] for log in logs]
        runs = pathlib.Path(tempfile.mkdtemp(prefix="online_preview_"))
        try:
            table, rms = run_table(args, plan, logs, names, lag, runs)
        finally:
            shutil.rmtree(runs)
        lines, texts = texts_of(args, names, table, rms, lag + 1)
        write_outputs(out, texts)
    except BadInput as e:
        print(f"online_preview_table: {one_line(e)}", file=sys.stderr)
        return 2
    except PlanFailed as e:
        print(f"online_preview_table: {one_line(e)}", file=sys.stderr)
        return 1
    print("\n".join(lines))
    return 0


def above_model_based(rms, names, horizon):
    """One line: where online optimal's objective (RMS) is above online model_based's at its
    own horizon (the preview it needs), or that it is nowhere."""
    based = rms[f"online model_based, preview {min(horizon, MODEL_BASED_PREVIEWS[-1])}"]
    above = [f"{label.removeprefix('online optimal, ')} on {name} ({row[name]:.2f} > "
             f"{based[name]:.2f})"
             for label, row in rms.items() if label.startswith("online optimal")
             for name in names if row[name] > based[name]]
    if not above:
        return "Online optimal is at or below online model_based by the objective everywhere."
    return "Online optimal is above online model_based by the objective at " + \
        "; ".join(above) + "."


if __name__ == "__main__":
    sys.exit(main())
