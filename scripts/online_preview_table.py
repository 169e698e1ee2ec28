"""The cost of a short preview for the online servo planner: `plan --online --preview-ticks N`
against the batch `plan`, on a motor's logs taken as desired motions.

    /usr/bin/python3 scripts/online_preview_table.py --model results/servo_logs/log_fit.json \
        --out results/servo_logs/online [--motor xl330] [--kp 400] [--build build]

Writes preview.md (the table docs/results.md shows) and preview.json (every run's predicted
mean absolute error from the desired motion, deg, over all its ticks: plan.json's
predicted_mae_deg.planned) into --out; each run's own files go to a temporary folder.
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


def planned_mae(plan, args, log, method, out, preview=None):
    """Runs plan on `log` and returns its predicted mean absolute error (deg)."""
    command = [str(plan), "--model", args.model, "--motor", args.motor, "--method", method,
               "--desired", str(log), "--out", str(out)]
    if preview is not None:
        command += ["--online", "--preview-ticks", str(preview)]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        sys.exit(f"online_preview_table: {' '.join(command)} failed: {done.stderr.strip()}")
    return read_json(out / "plan.json")["predicted_mae_deg"]["planned"]


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
    rows = [("batch model_based", "model_based", None), ("batch optimal", "optimal", None)]
    rows += [(f"online model_based, preview {p}", "model_based", p) for p in MODEL_BASED_PREVIEWS]
    rows += [(f"online optimal, preview {p}", "optimal", p) for p in OPTIMAL_PREVIEWS]
    names = [log.name.split(f"_kp{args.kp}_")[0] for log in logs]
    table = {}
    try:
        for label, method, preview in rows:
            table[label] = {}
            for name, log in zip(names, logs):
                folder = runs / f"{name}_{method}_{'batch' if preview is None else preview}"
                table[label][name] = planned_mae(plan, args, log, method, folder, preview)
    finally:
        shutil.rmtree(runs)
    out.mkdir(parents=True, exist_ok=True)
    (out / "preview.json").write_text(json.dumps(table, indent=2) + "\n")
    lines = [f"| plan ({args.motor}, kp {args.kp}) | " + " | ".join(names) + " |",
             "|---" * (len(names) + 1) + "|"]
    for label, row in table.items():
        lines.append(f"| {label} | " + " | ".join(f"{row[n]:.2f}" for n in names) + " |")
    (out / "preview.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
