#!/usr/bin/python3
"""scripts/report.py and scripts/animate.py under hostile input: every case is one line on
stderr naming the item, exit status 2, no traceback, and nothing written (report.py writes
every page or none).

Usage: scripts_bad_input_test.py SOURCE_DIR TRACK OUT_DIR
Exit 0: passed; 1: failed (every failure printed).
"""
import json
import os
import shutil
import subprocess
import sys

PY = "/usr/bin/python3"  # Debian's: the scripts need its numpy and matplotlib
failures = []


def run(*command):
    return subprocess.run(command, capture_output=True, text=True, timeout=120)


def expect_refused(what, command, needle):
    result = run(*command)
    lines = result.stderr.strip().splitlines()
    if result.returncode != 2 or len(lines) != 1 or needle not in result.stderr or \
            "Traceback" in result.stderr:
        failures.append(f"{what}: expected exit 2 and one line with {needle!r}, got "
                        f"{result.returncode}: {result.stderr!r}")


def written_pages(top):
    return [os.path.join(d, f) for d, _, files in os.walk(top) for f in files
            if f == "index.html" or f.startswith(".index.html")]


def report_cases(source, out):
    report = os.path.join(source, "scripts", "report.py")
    top = os.path.join(out, "report")
    sub = os.path.join(top, "sub")
    os.makedirs(sub)
    with open(os.path.join(top, "log_fit.json"), "w") as f:
        json.dump({"models": "not a map", "logs": []}, f)  # content a program never writes
    with open(os.path.join(sub, "plan.json"), "w") as f:
        f.write("[" * 100000 + "]" * 100000)  # nested too deep to read
    with open(os.path.join(sub, "table1.json"), "w") as f:
        json.dump({"plant": {"robot": "x"}}, f)
    os.symlink("..", os.path.join(sub, "up"))  # a loop of links
    open(os.path.join(os.fsencode(top), b"name-not-utf8-\xff.json"), "w").close()
    # A sub-run's index.html that is a folder: refused, and no page written anywhere.
    os.makedirs(os.path.join(sub, "index.html"))
    expect_refused("report.py, index.html a folder", [PY, report, top], "index.html is a folder")
    if written_pages(top):
        failures.append(f"report.py wrote {written_pages(top)} though it refused")
    os.rmdir(os.path.join(sub, "index.html"))
    result = run(PY, report, top)
    if result.returncode != 0 or "Traceback" in result.stderr:
        failures.append(f"report.py on odd content: exit {result.returncode}: {result.stderr!r}")
    elif len(written_pages(top)) != 2:
        failures.append(f"report.py: expected 2 pages, wrote {written_pages(top)}")


def animate_cases(source, track, out):
    animate = os.path.join(source, "scripts", "animate.py")
    run_dir = os.path.join(out, "run")
    made = run(track, "--config", os.path.join(source, "experiments/configs/track.yaml"),
               "--set", "steps=2", "--set", "warmup_steps=1", "--set", "plant=model",
               "--set", "controller.modes=[direct]", "--out", run_dir, "--quiet")
    if made.returncode != 0:
        failures.append(f"track: {made.stderr}")
        return
    gif = os.path.join(out, "a.gif")
    expect_refused("--steps x", [PY, animate, run_dir, "--steps", "x", "--out", gif],
                   "--steps: invalid int value")
    expect_refused("--fps 1e-300", [PY, animate, run_dir, "--fps", "1e-300", "--out", gif],
                   "--fps 1e-300: expected a number from 0.01 to 1000")
    os.makedirs(os.path.join(out, "folder.gif"))
    expect_refused("--out a folder", [PY, animate, run_dir, "--out",
                                      os.path.join(out, "folder.gif")], "is a folder")
    table = os.path.join(run_dir, "table2.json")
    shutil.copy(table, table + ".kept")
    for text, needle in (("[1, 2]", "table2.json: expected a JSON object, got list"),
                         ('{"plant": "sim"}', "table2.json: field 'plant' is not an object")):
        with open(table, "w") as f:
            f.write(text)
        expect_refused(f"table2.json {text}", [PY, animate, run_dir, "--out", gif], needle)
    shutil.copy(table + ".kept", table)
    trace = os.path.join(run_dir, "trace_direct.csv")
    with open(trace) as f:
        lines = f.read().splitlines()
    header = lines[0].split(",")
    cells = lines[1].split(",")
    cells[header.index("actual_deg")] = "nan"
    lines[1] = ",".join(cells)
    with open(trace, "w") as f:
        f.write("\n".join(lines) + "\n")
    expect_refused("a NaN in a trace", [PY, animate, run_dir, "--out", gif],
                   "the actual angle is nan")
    if os.path.exists(gif):
        failures.append("animate.py wrote a.gif though it refused")


def main(argv):
    source, track, out = argv[1:4]
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    report_cases(source, out)
    animate_cases(source, track, out)
    for failure in failures:
        print(f"FAIL: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
