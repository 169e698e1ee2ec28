#!/usr/bin/python3
"""The scripts under hostile input, one explicit case each: one line on stderr naming the item,
exit status 2, no traceback, and nothing written (report.py writes every page or none; the
others every output or none). report.py shows a sweep.csv whose columns are not the declared
ones as not read; a usage error of every script's command line is one line, exit 2.

Usage: scripts_bad_input_test.py SOURCE_DIR TRACK OUT_DIR   (TRACK: BUILD/bin/track)
Exit 0: passed; 1: failed (every failure printed).
"""
import contextlib
import io
import json
import math
import os
import shutil
import subprocess
import sys

import script_inputs
from script_inputs import snapshot

failures = []


def run(*command, cwd=None, env=None):
    return subprocess.run(command, capture_output=True, text=True, timeout=120, cwd=cwd, env=env)


def expect_refused(what, command, needle, untouched=None, cwd=None, env=None):
    """`command` exits 2 with one line holding `needle`, and leaves the folder `untouched` as it
    was."""
    before = snapshot(untouched) if untouched else None
    result = run(*command, cwd=cwd, env=env)
    lines = result.stderr.strip().splitlines()
    if result.returncode != 2 or len(lines) != 1 or needle not in result.stderr or \
            "Traceback" in result.stderr:
        failures.append(f"{what}: expected exit 2 and one line with {needle!r}, got "
                        f"{result.returncode}: {result.stderr!r}")
    if untouched and snapshot(untouched) != before:
        failures.append(f"{what}: files in {untouched} created or changed though it refused")
    return result


def written_pages(top):
    return [os.path.join(d, f) for d, _, files in os.walk(top) for f in files
            if f == "index.html" or f.startswith(".index.html")]


def report_cases(source, out):
    report = script_inputs.command(source, "leglab.results.report")
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
    expect_refused("report.py, index.html a folder", [*report, top], "index.html is a folder")
    if written_pages(top):
        failures.append(f"report.py wrote {written_pages(top)} though it refused")
    os.rmdir(os.path.join(sub, "index.html"))
    result = run(*report, top)
    if result.returncode != 0 or "Traceback" in result.stderr:
        failures.append(f"report.py on odd content: exit {result.returncode}: {result.stderr!r}")
    elif len(written_pages(top)) != 2:
        failures.append(f"report.py: expected 2 pages, wrote {written_pages(top)}")


def animate_cases(source, track, out):
    animate = script_inputs.command(source, "leglab.results.animate")
    run_dir = os.path.join(out, "run")
    made = run(track, "--config", os.path.join(source, "experiments/configs/track.yaml"),
               "--set", "steps=2", "--set", "warmup_steps=1", "--set", "plant=model",
               "--set", "controller.modes=[direct]", "--out", run_dir, "--quiet")
    if made.returncode != 0:
        failures.append(f"track: {made.stderr}")
        return
    gif = os.path.join(out, "a.gif")
    expect_refused("--steps x", [*animate, run_dir, "--steps", "x", "--out", gif],
                   "--steps: invalid int value")
    expect_refused("--fps 1e-300", [*animate, run_dir, "--fps", "1e-300", "--out", gif],
                   "--fps 1e-300: expected a number from 0.01 to 1000")
    os.makedirs(os.path.join(out, "folder.gif"))
    expect_refused("--out a folder", [*animate, run_dir, "--out",
                                      os.path.join(out, "folder.gif")], "is a folder")
    table = os.path.join(run_dir, "table2.json")
    shutil.copy(table, table + ".kept")
    for text, needle in (("[1, 2]", "table2.json: expected a JSON object, got list"),
                         ('{"plant": "sim"}', "table2.json: field 'plant' is not an object")):
        with open(table, "w") as f:
            f.write(text)
        expect_refused(f"table2.json {text}", [*animate, run_dir, "--out", gif], needle)
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
    expect_refused("a NaN in a trace", [*animate, run_dir, "--out", gif],
                   "the actual angle is nan")
    if os.path.exists(gif):
        failures.append("animate.py wrote a.gif though it refused")


def report_sweep_case(source, out):
    """A sweep.csv whose columns are not the declared ones is shown as not read; the page is
    written."""
    top = os.path.join(out, "report_sweep")
    os.makedirs(top)
    script_inputs.write_csv(os.path.join(top, "sweep.csv"), ["a", "b"], [[1, 2]])
    result = run(*script_inputs.command(source, "leglab.results.report"), top)
    page = os.path.join(top, "index.html")
    text = open(page, encoding="utf-8").read() if os.path.exists(page) else ""
    if result.returncode != 0 or "sweep.csv</a>: not read (" not in text:
        failures.append(f"report.py on a sweep.csv of other columns: exit {result.returncode}, "
                        f"{result.stderr!r}, page shows it as not read: {'not read' in text}")


def plot_logs_cases(source, out):
    script = script_inputs.command(source, "leglab.results.plot_logs")
    top = os.path.join(out, "plot_logs")
    good, bad = os.path.join(top, "good"), os.path.join(top, "bad")
    os.makedirs(good)
    header, rows = script_inputs.log_table(source)
    log = os.path.join(good, script_inputs.LOG_CSV)
    script_inputs.write_csv(log, header, rows)
    expect_refused("plot_logs.py, a missing folder", [*script, os.path.join(top, "missing")],
                   "missing: no such folder", top)
    expect_refused("plot_logs.py, a file for a folder", [*script, log], "not a folder", top)
    os.makedirs(bad)
    with open(os.path.join(bad, "log_fit.json"), "w") as f:
        f.write("[[1, 2], {\"logs\": NaN}]")  # a log fit of the wrong shape, nothing to draw
    expect_refused("plot_logs.py, a folder of no log", [*script, bad],
                   "no log_<motor>_<name>.csv or requests.csv", top)
    bad_log = os.path.join(bad, script_inputs.LOG_CSV)
    for what, cells, needle in (("a NaN", "nan", "row 3, column measured_deg: 'nan' is not a "
                                 "finite number"),
                                ("a text cell", "abc", "'abc' is not a number"),
                                ("an empty cell", "", "row 3, column measured_deg: empty")):
        changed = [list(r) for r in rows]
        changed[2][2] = cells
        script_inputs.write_csv(bad_log, header, changed)
        # The good folder first: its figure is not written either.
        expect_refused(f"plot_logs.py, {what} in a log", [*script, good, bad], needle, top)
    script_inputs.write_csv(bad_log, header[:2] + header[3:], [r[:2] + r[3:] for r in rows])
    expect_refused("plot_logs.py, a column missing", [*script, bad],
                   "declared columns missing", top)
    open(bad_log, "w").close()
    expect_refused("plot_logs.py, an empty log", [*script, bad], "declared columns missing",
                   top)
    os.remove(bad_log)
    figure = log[:-len(".csv")] + ".png"
    if os.path.isfile(figure):  # written though refused: a failure found above
        os.remove(figure)
    os.makedirs(figure)
    expect_refused("plot_logs.py, a folder in the figure's place", [*script, good],
                   "in the way of the figure", top)
    expect_refused("plot_logs.py, no argument", [*script], "plot_logs: error:", top)
    os.rmdir(figure)
    expect_drawn("plot_logs.py on a good log", [*script, good], figure)


def expect_drawn(what, command, figure):
    """The check beside the refusals: good input is drawn, exit 0."""
    result = run(*command)
    if result.returncode != 0 or not os.path.isfile(figure):
        failures.append(f"{what}: exit {result.returncode}, {result.stderr!r}")


def plot_sweep_cases(source, out):
    script = script_inputs.command(source, "leglab.results.plot_sweep")
    top = os.path.join(out, "plot_sweep")
    os.makedirs(top)
    header, rows = script_inputs.sweep_table()
    path = os.path.join(top, "sweep.csv")
    column = header.index("direct_foot_l2_cm")
    for cell, needle in (("abc", "row 2, column direct_foot_l2_cm: 'abc' is not a number"),
                         ("nan", "row 2, column direct_foot_l2_cm: 'nan' is not a finite"),
                         ("-inf", "row 2, column direct_foot_l2_cm: '-inf' is not a finite"),
                         ("", "row 2, column direct_foot_l2_cm: empty")):
        changed = [list(r) for r in rows]
        changed[1][column] = cell
        script_inputs.write_csv(path, header, changed)
        expect_refused(f"plot_sweep.py, a cell {cell!r}", [*script, path],
                       f"{path}: {needle}", top)
    status = header.index("status")
    script_inputs.write_csv(path, header[:status] + header[status + 1:],
                            [r[:status] + r[status + 1:] for r in rows])
    expect_refused("plot_sweep.py, a column missing", [*script, path],
                   "declared columns missing or out of order: status", top)
    script_inputs.write_csv(path, header + ["extra"], [r + [1] for r in rows])
    expect_refused("plot_sweep.py, a column extra", [*script, path], "column 'extra'", top)
    script_inputs.write_csv(path, header, [rows[0][:-2]] + rows[1:])
    expect_refused("plot_sweep.py, a row short", [*script, path], "row 1: 8 cells", top)
    open(path, "w").close()
    expect_refused("plot_sweep.py, an empty file", [*script, path], "declared columns", top)
    os.remove(path)
    os.makedirs(path)
    expect_refused("plot_sweep.py, a folder", [*script, path], "a folder, not a sweep.csv",
                   top)
    os.rmdir(path)
    script_inputs.write_csv(path, header, rows)
    expect_refused("plot_sweep.py, --out under a file", [*script, path, "--out",
                                                          os.path.join(path, "f.png")],
                   "no folder", top)
    expect_refused("plot_sweep.py, a bad flag", [*script, path, "--bins", "3"],
                   "plot_sweep: error: unrecognized arguments: --bins 3", top)
    expect_drawn("plot_sweep.py on a good sweep", [*script, path],
                 os.path.join(top, "sweep.png"))


def online_preview_cases(source, build, out):
    """online_preview_table.py: run from the source tree (its logs are data/servo_logs/), its
    temporary folders in TMPDIR, which it leaves as it found it."""
    script = script_inputs.command(source, "scripts/online_preview_table.py")
    top = os.path.join(out, "online_preview")
    tmp = os.path.join(top, "tmp")
    os.makedirs(tmp)
    env = dict(os.environ, TMPDIR=tmp)
    model = os.path.join(top, "log_fit.json")
    fit = script_inputs.log_fit()
    fit["models"]["extended"]["xl330"]["gain_per_deg_kp"] = -1.0  # plan refuses it
    with open(model, "w") as f:
        json.dump(fit, f)
    result_out = os.path.join(top, "out")

    def refused(what, extra, needle):
        command = [*script, "--model", model, "--out", result_out, "--build", build, *extra]
        result = expect_refused(f"online_preview_table.py, {what}", command, needle, top,
                                source, env)
        if "--desired" in result.stderr:
            failures.append(f"online_preview_table.py, {what}: echoes plan's command line")

    refused("plan refuses the model", [],
            "lift_and_drop_kp400_2026-01-15_10h29m21.json, optimal online, preview default: "
            "plan: error:")
    fit["models"]["extended"]["xl330"]["gain_per_deg_kp"] = 4.3e-05
    with open(model, "w") as f:
        json.dump(fit, f)
    refused("--motor the model lacks", ["--motor", "sts3250"], "--motor sts3250: not in")
    refused("--kp of no log", ["--kp", "5"], "--kp 5: no xl330 log at kp 5")
    refused("--build without bin/plan", ["--build", tmp], "no program bin/plan")
    open(os.path.join(top, "a_file"), "w").close()
    refused("--out a file", ["--out", os.path.join(top, "a_file")], "is not a folder")
    for what, text, needle in (("a list", "[1, 2]", "expected a JSON object, got list"),
                               ("a NaN", '{"models": {"extended": {"xl330": {"lag_ticks": NaN}}}}',
                                "models.extended.xl330.lag_ticks is not a finite number")):
        with open(model, "w") as f:
            f.write(text)
        refused(f"--model {what}", [], needle)
    os.remove(model)
    refused("--model missing", [], "no such file")
    os.makedirs(model)
    refused("--model a folder", [], "not a file")


def learned_fit_cases(source, build, out):
    if not script_inputs.compiled_package():
        print("leglab.servo.learned: skipped, this build has no leglab Python package")
        return
    script = script_inputs.command(source, "leglab.servo.learned")
    top = os.path.join(out, "learned_fit")
    run_dir = os.path.join(top, "run")
    script_inputs.write_log_run(source, run_dir)
    result_out = os.path.join(top, "out")
    command = [*script, run_dir, "--out", result_out, "--size", "small", "--jobs", "1",
               "--build", build]
    fit_path = os.path.join(run_dir, "log_fit.json")
    for what, change, needle in (
            ("logs a number", lambda fit: fit.update(logs=5), "field 'logs'"),
            ("a NaN error", lambda fit: fit["logs"][0]["mae_deg"].update(paper=math.nan),
             "logs[0].mae_deg.paper is not a finite number"),
            ("kp a text", lambda fit: fit["logs"][0].update(kp="x"), "logs[0].kp: expected")):
        fit = script_inputs.log_fit()
        change(fit)
        with open(fit_path, "w") as f:
            json.dump(fit, f)
        expect_refused(f"leglab.servo.learned, {what}", command, needle, top)
    script_inputs.write_log_run(source, run_dir)
    header, rows = script_inputs.log_table(source)
    rows[4][2] = "nan"
    script_inputs.write_csv(os.path.join(run_dir, script_inputs.LOG_CSV), header, rows)
    expect_refused("leglab.servo.learned, a NaN cell", command,
                   "row 5, column measured_deg: 'nan' is not a finite number", top)
    script_inputs.write_log_run(source, run_dir)
    learned_fit_bug_case(source, build, run_dir, result_out)


def learned_fit_bug_case(source, build, run_dir, result_out):
    """A non-finite result of training (here a stand-in for it) is a bug: exit 1, one line,
    nothing written; finite results are written."""
    # It runs with the compiled package (learned_fit_cases skips a build without it).
    from leglab.servo import learned as learned_fit  # PYTHONPATH: the build's package
    if not hasattr(learned_fit, "cli"):
        failures.append("leglab.servo.learned: no cli(), main's exit status")
        return

    def trained(mae):
        form = {"history_ticks": 2, "width": 8, "parameters": 10, "validation_mae_deg": None,
                "grid": []}
        return lambda job: {"motor": job[0][0], "held_out": job[0][1],
                            "forms": {"mlp": form, "lstm": form},
                            "mae_deg": {f: {"mlp": mae, "lstm": 1.0} for f in job[0][3]},
                            "curves": {}, "training_ticks": 20, "trained_on": []}

    argv = [run_dir, "--out", result_out, "--size", "small", "--jobs", "1", "--build", build]
    for mae, status in ((0.5, 0), (math.nan, 1)):
        learned_fit.run_job = trained(mae)
        before = snapshot(result_out)
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            got = learned_fit.cli(argv)
        lines = stderr.getvalue().strip().splitlines()
        if got != status or (status and (len(lines) != 1 or snapshot(result_out) != before)):
            failures.append(f"leglab.servo.learned, results of MAE {mae}: exit {got}, expected "
                            f"{status}: {stderr.getvalue()!r}")
    if not os.path.isfile(os.path.join(result_out, "learned_fit.json")):
        failures.append("leglab.servo.learned did not write finite results")


def compare_engines_cases(source, out):
    script = script_inputs.command(source, "leglab.results.compare_engines")
    top = os.path.join(out, "compare_engines")
    ode, dart = os.path.join(top, "ode"), os.path.join(top, "dart")
    script_inputs.table_run(ode)
    script_inputs.table_run(dart, foot_l2=math.nan)
    expect_refused("compare_engines.py, a NaN in table2.json", [*script, ode, dart],
                   "table2.json': foot_cm.direct.L2.mean is not a finite number", top)
    script_inputs.table_run(dart, step_angles=(0.0, float("inf"), 2.0, 3.0))
    expect_refused("compare_engines.py, an infinity in a step test", [*script, ode, dart],
                   "row 2: 'inf' is not a finite number", top)


def usage_cases(source):
    """A flag no script knows: one line, exit 2, whatever the script."""
    for name in ("leglab.results.animate", "leglab.results.report",
                 "leglab.results.plot_figures", "leglab.results.plot_logs",
                 "leglab.results.plot_sweep", "leglab.results.compare_engines",
                 "leglab.servo.learned", "scripts/online_preview_table.py", "scripts/variants.py",
                 "scripts/bus_loop.py", "scripts/docs_numbers.py",
                 "scripts/examine_paper_numbers.py", "tools/tidy_keys.py", "tools/check_links.py",
                 "tools/check_outputs.py", "tools/check_output_names.py", "tools/check_ranges.py"):
        if name == "leglab.servo.learned" and not script_inputs.compiled_package():
            continue
        expect_refused(f"{name} --no-such-flag",
                       [*script_inputs.command(source, name), "--no-such-flag"], "", None)


def main(argv):
    source, track, out = argv[1:4]
    build = os.path.dirname(os.path.dirname(os.path.abspath(track)))
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    report_cases(source, out)
    report_sweep_case(source, out)
    animate_cases(source, track, out)
    plot_logs_cases(source, out)
    plot_sweep_cases(source, out)
    online_preview_cases(source, build, out)
    learned_fit_cases(source, build, out)
    compare_engines_cases(source, out)
    usage_cases(source)
    for failure in failures:
        print(f"FAIL: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
