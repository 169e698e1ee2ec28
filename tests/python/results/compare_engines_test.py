#!/usr/bin/python3
"""leglab.results.compare_engines on two small runs written here by hand: the side-by-side values
and DART's differences are the ones put in (differences worked out by hand), and bad input is
one line, exit 2, nothing written.

Usage: PYTHONPATH=BUILD/python compare_engines_test.py
"""
import json
import os
import subprocess
import sys
import tempfile

COMMAND = ["/usr/bin/python3", "-m", "leglab.results.compare_engines"]
JOINTS = ("rotator", "abductor", "knee")


def write_run(folder, v_max, step_angles, foot_l2):
    os.makedirs(folder)
    joints = {j: {"v_max_deg_per_tick": v_max, "theta0_deg": 5.5, "lag_ticks": 4,
                  "accel_ticks": 6, "fit_rms_deg": 0.25} for j in JOINTS}
    with open(os.path.join(folder, "table1.json"), "w") as f:
        json.dump({"joints": joints}, f)
    with open(os.path.join(folder, "step_knee_40.csv"), "w") as f:
        f.write("tick,request_deg,actual_deg,model_deg\n")
        for t, angle in enumerate(step_angles):
            f.write(f"{t},40,{angle},0\n")
    norms = {"L2(Des,Dir)": {"mean": 2.0, "std": 0.1}}
    with open(os.path.join(folder, "table2.json"), "w") as f:
        json.dump({"joints": {j: norms for j in JOINTS},
                   "foot_cm": {"direct": {"L2": {"mean": foot_l2, "std": 0.0},
                                          "Linf": {"mean": 3.0, "std": 0.0}}}}, f)


def run(*args):
    return subprocess.run([*COMMAND, *args], capture_output=True, text=True,
                          check=False)


def main():
    failures = []
    with tempfile.TemporaryDirectory() as scratch:
        ode, dart = os.path.join(scratch, "ode"), os.path.join(scratch, "dart")
        write_run(ode, 2.5, [0.0, 1.0, 2.0, 3.0], 1.25)
        write_run(dart, 2.5125, [0.0, 1.5, 2.0, 2.0], 1.5)
        result = run(ode, dart)
        text = open(os.path.join(dart, "engines.md")).read() if result.returncode == 0 else ""
        # Step test: |differences| 0, 0.5, 0, 1: largest 1, mean 0.375.
        for needle in ("| rotator | 2.5000 | 2.5125 | 5.500 | 5.500 | 4, 4 | 6, 6 |",
                       "| knee_40 | 4 | 1.0000 | 0.37500 |",
                       "| direct | 1.250 | 1.500 | +0.2500 | 3.000 | 3.000 | +0.0000 |",
                       "| L2(Des,Dir) | 2.000 | 2.000 | 2.000 | 2.000 | 2.000 | 2.000 |"):
            if needle not in text:
                failures.append(f"engines.md lacks {needle!r}: {result.stderr}{text}")

        os.remove(os.path.join(dart, "engines.md"))
        for what, args, needle in (
                ("a missing folder", (ode, os.path.join(scratch, "none")), "is not a folder"),
                ("no --out folder", (ode, dart, "--out", os.path.join(scratch, "x")),
                 "--out"),
                ("no arguments", (), "required")):
            result = run(*args)
            lines = result.stderr.strip().splitlines()
            if result.returncode != 2 or needle not in result.stderr or "Traceback" in \
                    result.stderr or (what != "no arguments" and len(lines) != 1):
                failures.append(f"{what}: exit {result.returncode}, {result.stderr!r}")
        with open(os.path.join(dart, "table2.json"), "w") as f:
            f.write("{not json")
        result = run(ode, dart)
        if result.returncode != 2 or "table2.json" not in result.stderr:
            failures.append(f"a broken table2.json: exit {result.returncode}, {result.stderr!r}")
        if os.path.exists(os.path.join(dart, "engines.md")):
            failures.append("bad input wrote engines.md")
    for failure in failures:
        print(failure)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
