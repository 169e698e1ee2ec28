"""Small, valid inputs of the scripts that read the programs' files, written here by hand, and the
contract every script keeps on bad input, checked: exit status 0 or 2; on 2 one line on stderr,
no traceback and nothing in its folder created or changed; on 0 no NaN or infinity in a JSON,
Markdown or CSV file it wrote.

Imported by scripts_bad_input_test.py and scripts_properties_test.py (from their own folder).
"""
import csv
import hashlib
import importlib.util
import json
import math
import os
import re
import subprocess

PY = "/usr/bin/python3"  # Debian's: the scripts need its numpy and matplotlib
JOINTS = ("rotator", "abductor", "knee")
# A servo log shipped in data/: leglab.servo.learned reads its load.
LOG_FILE = "data/servo_logs/dynamixel-xl330/up_and_down_kp400_2026-01-15_10h29m29.json"
LOG_CSV = "log_xl330_up_and_down_kp400_2026-01-15_10h29m29.csv"
NON_FINITE = re.compile(r"\b(nan|inf|infinity)\b", re.IGNORECASE)


def command(source, name):
    """The command line (a list) that runs `name`: a module of the leglab package
    (leglab.results.report: `python3 -m`, the package found through the test's PYTHONPATH) or a
    file of the source tree `source` (scripts/variants.py, tools/check_links.py)."""
    return [PY, "-m", name] if name.startswith("leglab.") else [PY, os.path.join(source, name)]


def compiled_package():
    """Whether the leglab package on PYTHONPATH has its compiled module: leglab.servo.learned
    runs only with it (a build without the Python package, the sanitizers', has none)."""
    return importlib.util.find_spec("leglab._leglab") is not None


def reader(source):
    """leglab.results.reader (of the package on PYTHONPATH: `source`'s, linked into its build)."""
    from leglab.results import reader as results
    return results


def write_csv(path, header, rows):
    with open(path, "w", newline="", encoding="utf-8") as f:
        csv.writer(f, lineterminator="\n").writerows([header] + rows)


def log_table(source, ticks=20):
    """A log as identify writes it (log_<motor>_<name>.csv): (header, rows), every tick driven."""
    header = reader(source).declared_columns(LOG_CSV)
    rows = []
    for t in range(ticks):
        request = 10.0 * math.sin(t / 3.0)
        measured = 10.0 * math.sin((t - 1) / 3.0)
        rows.append([t * 0.005, request, measured, 1] + [measured] * (len(header) - 4))
    return header, rows


def plan_table(source, ticks=10):
    """requests.csv as plan writes it: (header, rows)."""
    header = reader(source).declared_columns("requests.csv")
    return header, [[t * 0.005, t, t + 1.0, t - 0.5, t % 2] for t in range(ticks)]


def log_fit(motor="xl330"):
    """identify's log_fit.json of one log (LOG_FILE), as plan and leglab.servo.learned read it."""
    extended = {"tick_s": 0.0053, "gain_per_deg_kp": 4.3e-05, "v_max_deg_s": 1065.0,
                "v_max_given": False, "stall_torque_nm": 0.77, "friction_duty": 0.0054,
                "friction_load_ratio": 0.48, "velocity_lag_s": 0.119, "lag_ticks": 0}
    paper = {"tick_s": 0.0053, "v_max_deg_per_tick": 0.56, "theta0_deg": 101.9, "lag_ticks": 0,
             "accel_ticks": 1, "v_max_deg_s": 105.6}
    rungs = {"direct": 26.3, "best_shift": 21.1, "paper": 16.4, "extended": 0.66}
    row = {"file": LOG_FILE, "role": "train", "held_out_by": "none", "motor": motor,
           "trajectory": "up_and_down", "kp": 400.0, "ticks_scored": 20, "best_shift_s": 0.8,
           "mae_deg": rungs, "rms_deg": dict(rungs)}
    return {"models": {"paper": {motor: paper}, "extended": {motor: extended}},
            "fit_sample": {motor: {"training_ticks": 20, "fitted_ticks": 20}},
            "cross_validate": "none", "folds": [], "logs": [row]}


def write_log_run(source, folder):
    """A folder identify wrote with a logs section: log_fit.json and its log's CSV."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "log_fit.json"), "w", encoding="utf-8") as f:
        json.dump(log_fit(), f)
    write_csv(os.path.join(folder, LOG_CSV), *log_table(source))


def sweep_table():
    """A sweep.csv of two modes over one key: (header, rows), three points ok and one not."""
    header = ["index", "servo.delay_ms", "status", "direct_rotator_l2_deg", "direct_foot_l2_cm",
              "model_based_rotator_l2_deg", "model_based_foot_l2_cm", "floor_rotator_l2_deg",
              "floor_foot_l2_cm", "model_source"]
    rows = [[i, 24 + 16 * i, "ok", 15.0 + i, 2.0 + 0.1 * i, 5.0, 0.8 + 0.1 * i, 4.0, 0.7,
             "identified"] for i in range(3)]
    rows.append([3, 999, "servo.delay_ms must be in [0; 500]", "", "", "", "", "", "", ""])
    return header, rows


def table_run(folder, v_max=2.5, foot_l2=1.25, step_angles=(0.0, 1.0, 2.0, 3.0)):
    """A folder identify and track wrote: table1.json, one step test and table2.json."""
    os.makedirs(folder, exist_ok=True)
    joints = {j: {"v_max_deg_per_tick": v_max, "theta0_deg": 5.5, "lag_ticks": 4,
                  "accel_ticks": 6, "fit_rms_deg": 0.25} for j in JOINTS}
    with open(os.path.join(folder, "table1.json"), "w", encoding="utf-8") as f:
        json.dump({"joints": joints}, f)
    write_csv(os.path.join(folder, "step_knee_40.csv"),
              ["tick", "request_deg", "actual_deg", "model_deg"],
              [[t, 40, a, 0] for t, a in enumerate(step_angles)])
    norms = {"L2(Des,Dir)": {"mean": 2.0, "std": 0.1}}
    with open(os.path.join(folder, "table2.json"), "w", encoding="utf-8") as f:
        json.dump({"steps": 4, "joints": {j: norms for j in JOINTS},
                   "foot_cm": {"direct": {"L2": {"mean": foot_l2, "std": 0.0},
                                          "Linf": {"mean": 3.0, "std": 0.0}}}}, f)


def snapshot(top):
    """Everything below `top`: {relative path: what it is} (a file by its bytes' digest)."""
    found = {}
    if not os.path.lexists(top):
        return found
    for folder, dirs, files in os.walk(top):
        for name in dirs + files:
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, top)
            if os.path.islink(path):
                found[rel] = "link " + os.readlink(path)
            elif os.path.isdir(path):
                found[rel] = "folder"
            else:
                with open(path, "rb") as f:
                    found[rel] = hashlib.sha256(f.read()).hexdigest()
    return found


def run(command, cwd=None, env=None, timeout=120):
    return subprocess.run(command, capture_output=True, text=True, errors="replace", cwd=cwd,
                          env=env, timeout=timeout, check=False)


def contract_problems(result, before, after, allowed=(0, 2)):
    """What `result` (a finished script) and its folder's snapshots `before` and `after` break
    of the contract, as a list of sentences."""
    problems = []
    lines = result.stderr.strip().splitlines()
    if result.returncode not in allowed:
        problems.append(f"exit {result.returncode}, expected one of {allowed}")
    if "Traceback" in result.stderr:
        problems.append("a traceback")
    if result.returncode == 2:
        if len(lines) != 1:
            problems.append(f"{len(lines)} lines on stderr, expected 1")
        if before != after:
            changed = sorted(set(before.items()) ^ set(after.items()))
            problems.append(f"files created or changed: {sorted({c[0] for c in changed})}")
    return problems


def written_non_finite(top, before, after):
    """The JSON, Markdown and CSV files created or changed below `top` that hold a NaN or an
    infinity."""
    bad = []
    for rel, digest in after.items():
        if before.get(rel) == digest or not rel.endswith((".json", ".md", ".csv")):
            continue
        with open(os.path.join(top, rel), encoding="utf-8", errors="replace") as f:
            if NON_FINITE.search(f.read()):
                bad.append(rel)
    return bad
