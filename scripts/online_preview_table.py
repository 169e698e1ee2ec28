"""The cost of a short preview for the online servo planner: `plan --online --preview-ticks N`
against the batch `plan`, on a motor's logs taken as desired motions.

    /usr/bin/python3 scripts/online_preview_table.py --model results/servo_logs/log_fit.json \
        --out results/servo_logs/online [--motor xl330] [--kp 400] [--build build]

Writes preview.md (the table docs/results.md shows), preview.json (every run's predicted
mean absolute error from the desired motion, deg, over all its ticks: plan.json's
predicted_mae_deg.planned) and preview_rms.json (the root mean square of the same errors,
predicted_rms_deg.planned: the optimal plans' objective as an angle) into --out; each run's own
files go to a temporary folder. Online optimal runs with --budget-ms 0 (its iteration cap
alone), so that the table is the same on every machine.
"""

import argparse
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile

from results_reader import read_json

MODEL_BASED_PREVIEWS = (0, 1, 2)
OPTIMAL_PREVIEWS = (2, 5, 10, 20, 40, 62, 120, 250)
DEFAULT = "default"  # plan's own preview for online optimal


def planned_errors(plan, args, log, method, out, preview=None, extra=()):
    """Runs plan on `log` and returns its predicted mean absolute and root mean square errors
    (deg)."""
    command = [str(plan), "--model", args.model, "--motor", args.motor, "--method", method,
               "--desired", str(log), "--out", str(out)]
    if preview is not None:
        command += ["--online"] + (["--preview-ticks", str(preview)] if preview != DEFAULT else [])
        if method == "optimal":
            command += ["--budget-ms", "0", *extra]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"online_preview_table: {' '.join(command)} failed: {done.stderr.strip()}")
    summary = read_json(out / "plan.json")
    if preview == DEFAULT:
        return summary.online.preview_ticks
    return summary["predicted_mae_deg"]["planned"], summary["predicted_rms_deg"]["planned"]


def main():
    """Parses the flags, runs every plan and writes the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", required=True, help="identify's log_fit.json")
    parser.add_argument("--out", required=True, help="folder for preview.md and preview.json")
    parser.add_argument("--motor", default="xl330", help="the motor (default xl330)")
    parser.add_argument("--kp", default="400", help="the gain setting of the logs (default 400)")
    parser.add_argument("--build", default="build", help="the build folder (default build)")
    args = parser.parse_args()
    plan = pathlib.Path(args.build) / "bin" / "plan"
    folders = {"xl330": "dynamixel-xl330", "sts3250": "feetech-sts3250"}
    logs = sorted((pathlib.Path("data/servo_logs") / folders.get(args.motor, args.motor))
                  .glob(f"*_kp{args.kp}_*.json"))
    if not logs:
        sys.exit(f"online_preview_table: no {args.motor} log at kp {args.kp}")
    out = pathlib.Path(args.out)
    runs = pathlib.Path(tempfile.mkdtemp(prefix="online_preview_"))
    lag = read_json(pathlib.Path(args.model)).models.extended[args.motor].lag_ticks
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
    names = [log.name.split(f"_kp{args.kp}_")[0] for log in logs]
    table, rms = {}, {}
    try:
        for label, method, preview, extra in rows:
            table[label], rms[label] = {}, {}
            for name, log in zip(names, logs):
                folder = runs / f"{name}_{method}_{'batch' if preview is None else preview}"
                table[label][name], rms[label][name] = planned_errors(
                    plan, args, log, method, folder, preview, extra)
    finally:
        shutil.rmtree(runs)
    out.mkdir(parents=True, exist_ok=True)
    (out / "preview.json").write_text(json.dumps(table, indent=2) + "\n")
    (out / "preview_rms.json").write_text(json.dumps(rms, indent=2) + "\n")
    lines = [f"| plan ({args.motor}, kp {args.kp}), MAE (RMS) | " + " | ".join(names) + " |",
             "|---" * (len(names) + 1) + "|"]
    for label, row in table.items():
        lines.append(f"| {label} | " + " | ".join(f"{row[n]:.2f} ({rms[label][n]:.2f})"
                                                  for n in names) + " |")
    lines += ["", above_model_based(rms, names, horizon)]
    (out / "preview.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


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
    main()
