#!/usr/bin/python3
"""The measured tables of README.md and docs/results/*.md are a fresh run's
(scripts/docs_numbers.py), and the check finds a number changed by hand.

A fresh run of the programs whose JSON the blocks read, with the commands and folders of
scripts/reproduce.sh (leglab.servo.learned's networks, minutes of training, are left out: their
cells are the ones docs_numbers.py names as not checked). Then, on a copy of the docs: a joint-model
value, a servo error and a paper value changed by hand fail the check naming block and line,
--write puts the run's numbers back byte for byte, and bad input is one line, exit 2. The same
fresh run's CSV tables and JSON files have the columns and fields docs/outputs.md declares
(tools/check_outputs.py), and that check finds a column renamed, one added, a file no program
declares, and a JSON field renamed or added.

Usage: PYTHONPATH=BUILD_DIR/python docs_numbers_test.py SOURCE_DIR BIN_DIR BUILD_DIR
       SCRATCH_DIR
Exit 77 (skipped) when the leglab Python package, which holds the paper's values, is not built.
"""
import json
import os
import shutil
import subprocess
import sys

SOURCE, BIN, BUILD, SCRATCH = sys.argv[1:5]
SCRIPT = os.path.join(SOURCE, "scripts", "docs_numbers.py")
DOCS = ("README.md",) + tuple(os.path.join("docs", "results", f"{page}.md")
                              for page in ("paper", "beyond", "stand", "servos"))
# The blocks whose learned_fit.json this run does not make, each checked without its networks.
WITHOUT_NETWORKS = ("real-servos", "servo-learned")


def program(name, *args):
    subprocess.run([os.path.join(BIN, name), "--quiet", *args], check=True, cwd=SOURCE)


def script(name, *args):
    subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "scripts", name), *args],
                   check=True, cwd=SOURCE, stdout=subprocess.DEVNULL)


def fresh_run(out):
    """reproduce.sh's runs of the front and hind leg on ODE and DART, of the stand (its walk
    and Table 1 with the foot free and in the air), of the paper's regime and its walk fit, of
    adaptive, of three sweeps, of the two log fits and the online planner's previews,
    scripts/variants.py's runs and the emulated servos' loop (scripts/bus_loop.py)."""
    configs = os.path.join(SOURCE, "experiments", "configs")
    for folder, robot_set, walk in (("", [], "track.yaml"),
                                    ("hind", ["--set", "robot=ers210a_hind"], "track_hind.yaml")):
        for engine in ("", "dart"):
            where = os.path.join(out, folder, engine)
            engine_set = ["--set", "sim.engine=dart"] if engine else []
            program("identify", "--config", os.path.join(configs, "identify.yaml"), *robot_set,
                    *engine_set, "--out", where)
            program("track", "--config", os.path.join(configs, walk), *engine_set, "--out", where)
    program("track", "--config", os.path.join(configs, "track_stand.yaml"),
            "--out", os.path.join(out, "stand"))
    program("track", "--config", os.path.join(configs, "track_paper_regime.yaml"),
            "--out", os.path.join(out, "track_paper_regime"))
    program("fit_walk", "--config", os.path.join(configs, "track.yaml"),
            "--out", os.path.join(out, "walk_fit"))
    stand = os.path.join(configs, "identify_stand.yaml")
    program("identify", "--config", stand, "--out", os.path.join(out, "stand"))
    program("identify", "--config", stand, "--set", "robot=ers210a",
            "--out", os.path.join(out, "stand", "air70"))
    for start in ("adapt_cold_start", "adapt_wear"):
        program("track", "--config", os.path.join(configs, f"{start}.yaml"),
                "--out", os.path.join(out, start))
    program("track", "--config", os.path.join(configs, "adapt_wear.yaml"),
            "--out", os.path.join(out, "adapt_wear", "worn_model"), "--set", "plant_changes=[]",
            "--set", "servo.max_speed_deg_s=250", "--set", "servo.delay_ms=56",
            "--set", "controller.modes=[model_based]")
    for sweep in ("walk_speed", "stand_load", "servo_firmware"):
        program("sweep", "--config", os.path.join(SOURCE, "experiments", "sweeps", f"{sweep}.yaml"),
                "--out", os.path.join(out, "sweeps", sweep))
    logs = os.path.join(out, "servo_logs")
    program("identify", "--config", os.path.join(configs, "identify_logs.yaml"), "--out", logs)
    program("identify", "--config", os.path.join(configs, "identify_logs.yaml"),
            "--out", os.path.join(logs, "by_kp"),
            "--set", "logs.train=[data/servo_logs/dynamixel-xl330]",
            "--set", "logs.cross_validate=leave_one_kp_out")
    script("online_preview_table.py", "--model", os.path.join(logs, "log_fit.json"),
           "--out", os.path.join(logs, "online"), "--build", BUILD)
    script("variants.py", out, "--bin", BIN)
    script("bus_loop.py", out, "--build", BUILD)


def check(results, *args, docs=SOURCE):
    return subprocess.run(["/usr/bin/python3", SCRIPT, results, "--docs", docs, "--build", BUILD,
                           *args], capture_output=True, text=True, check=False)


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def edit(path, old, new):
    """Replaces the first `old` in the file (which must hold it) by `new`; returns its line."""
    text = read(path)
    at = text.index(old)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text[:at] + new + text[at + len(old):])
    return text.count("\n", 0, at) + 1


def check_outputs(results, expect):
    """tools/check_outputs.py on the fresh run, then on copies of a trace changed by hand."""
    def run(folder):
        return subprocess.run(["/usr/bin/python3", os.path.join(SOURCE, "tools",
                                                                 "check_outputs.py"), folder],
                              capture_output=True, text=True, check=False)

    result = run(results)
    expect(result.returncode == 0 and
           " CSV and JSON files have their declared columns and fields" in result.stdout,
           "the fresh run's CSV and JSON files are not what docs/outputs.md declares", result)
    bad = os.path.join(SCRATCH, "bad_outputs")
    os.makedirs(bad)
    with open(os.path.join(results, "trace_direct.csv"), encoding="utf-8") as f:
        trace = f.read()
    header, rest = trace.split("\n", 1)
    for name, text, needle in (
            ("trace_direct.csv", header.replace("actual_deg", "measured_deg") + "\n" + rest,
             "trace_direct.csv: declared columns missing or out of order: actual_deg"),
            ("trace_ilc.csv", header + ",extra_deg\n", "column 'extra_deg' is not declared"),
            ("mine.csv", header + "\n", "mine.csv: no declared file has this name")):
        folder = os.path.join(bad, name)
        os.makedirs(folder)
        with open(os.path.join(folder, name), "w", encoding="utf-8") as f:
            f.write(text)
        result = run(folder)
        expect(result.returncode == 1 and needle in result.stderr,
               f"check_outputs does not say {needle!r}", result)
    # A JSON file's fields: one renamed (table1.json's joints.<joint>.theta0_deg) and one added
    # in a list's elements (log_fit.json's logs[]) are not declared.
    for rel, change, needle in (
            ("table1.json", lambda t: t["joints"]["knee"].update(theta_0=t["joints"]["knee"].pop(
                "theta0_deg")), "table1.json: field 'joints.knee.theta_0' is not declared"),
            ("servo_logs/log_fit.json", lambda t: t["logs"][0].update(extra_deg=1.0),
             "log_fit.json: field 'logs[].extra_deg' is not declared")):
        with open(os.path.join(results, rel), encoding="utf-8") as f:
            table = json.load(f)
        change(table)
        folder = os.path.join(bad, "json_" + os.path.basename(rel))
        os.makedirs(folder)
        with open(os.path.join(folder, os.path.basename(rel)), "w", encoding="utf-8") as f:
            json.dump(table, f)
        result = run(folder)
        expect(result.returncode == 1 and needle in result.stderr and
               result.stderr.count("\n") == 1, f"check_outputs does not say {needle!r}", result)
    result = run(os.path.join(SCRATCH, "nowhere"))
    expect(result.returncode == 2 and result.stderr.count("\n") == 1,
           "check_outputs on a missing folder is not one line, exit 2", result)


def main():
    failures = []

    def expect(condition, what, result=None):
        if not condition:
            failures.append(what + (f"\n  exit {result.returncode}, stderr:\n{result.stderr}"
                                    if result is not None else ""))

    if not os.path.isdir(os.path.join(BUILD, "python", "leglab")):
        print("skipped: the leglab Python package is not built")
        return 77
    shutil.rmtree(SCRATCH, ignore_errors=True)
    results = os.path.join(SCRATCH, "results")
    fresh_run(results)

    # The committed docs hold the fresh run's numbers, every block checked.
    result = check(results)
    expect(result.returncode == 0, "the committed docs differ from a fresh run", result)
    expect("skipped" not in result.stderr, "a block was skipped by the fresh run", result)
    for name in WITHOUT_NETWORKS:
        expect(f"'{name}' checked without" in result.stderr,
               f"'{name}' not reported as checked without the networks", result)

    # Numbers changed by hand in a copy of the docs: each found, then written back.
    copy = os.path.join(SCRATCH, "docs_copy")
    for rel in DOCS:
        os.makedirs(os.path.dirname(os.path.join(copy, rel)), exist_ok=True)
        shutil.copyfile(os.path.join(SOURCE, rel), os.path.join(copy, rel))
    readme, stand, servos = (os.path.join(copy, DOCS[k]) for k in (0, 3, 4))
    theta = edit(readme, "| theta_0 (deg) | 7.0 | 5.65 |", "| theta_0 (deg) | 7.0 | 5.66 |")
    paper = edit(readme, "11.42 [31.0]", "11.42 [31.5]")
    kp = edit(servos, "| 100 | 2.61 |", "| 100 | 2.62 |")
    # A variant's number (scripts/variants.py's probe runs).
    probe = edit(stand, "; 3/6 -0.06 +0.71 | 0.451 |", "; 3/6 -0.06 +0.71 | 0.450 |")
    result = check(results, docs=copy)
    expect(result.returncode == 1, "four numbers changed by hand were not all found", result)
    for where in (f"README.md:{theta}: 'table1': column 3: '5.66' where the run gives '5.65'",
                  f"README.md:{paper}: 'table2-joints': column 2: '11.42 [31.5]' where the run "
                  f"gives '11.42 [31.0]'",
                  f"docs/results/servos.md:{kp}: 'servo-by-kp': column 2: '2.62' where the run "
                  f"gives '2.61'",
                  f"docs/results/stand.md:{probe}: 'probes': column 3: '0.450' where the run gives "
                  f"'0.451'"):
        expect(where in result.stderr, f"the check does not say {where!r}", result)
    result = check(results, "--write", docs=copy)
    expect(result.returncode == 0, "--write failed", result)
    for rel in DOCS:
        expect(read(os.path.join(copy, rel)) == read(os.path.join(SOURCE, rel)),
               f"--write did not put the run's numbers back in {rel}")

    # Bad input: one line, exit 2, the docs untouched.
    edit(readme, "<!-- numbers: foot -->", "<!-- numbers: feet -->")
    edited = read(readme)
    result = check(results, "--write", docs=copy)
    expect(result.returncode == 2 and "no block named 'feet'" in result.stderr
           and result.stderr.count("\n") == 1, "an unknown block is not one line, exit 2", result)
    expect(read(readme) == edited, "--write touched the docs after bad input")
    bad = os.path.join(SCRATCH, "bad")
    os.makedirs(bad)
    with open(os.path.join(bad, "table1.json"), "w", encoding="utf-8") as f:
        f.write("{not json")
    result = check(bad, "--only", "table1")
    expect(result.returncode == 2 and "table1.json: not readable as JSON" in result.stderr
           and result.stderr.count("\n") == 1, "a malformed table1.json is not one line, exit 2",
           result)
    result = check(os.path.join(SCRATCH, "nowhere"))
    expect(result.returncode == 2 and result.stderr.count("\n") == 1,
           "a missing results folder is not one line, exit 2", result)

    check_outputs(results, expect)

    for failure in failures:
        print("FAIL:", failure)
    if not failures:
        print("docs_numbers: the docs are a fresh run's; hand edits found and written back")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
