#!/usr/bin/python3
"""The scripts' contract on input of every wrong shape, property-based (hypothesis): plot_logs.py,
plot_sweep.py, online_preview_table.py, leglab.servo.learned (its checks alone: every input given it
here is refused before any training), compare_engines.py and report.py get files written by
hand (script_inputs) and then broken: JSON of another type or nested deep, objects with a field
missing, extra, of another type, NaN or infinite; CSV tables with a column missing or extra, a
cell that is text, NaN, infinite or empty, a row short or long; empty files, a huge single line,
bytes that are not UTF-8; a folder in a file's place, a missing folder, an output path that is a
file or lies under one. Each keeps the contract (script_inputs.contract_problems): exit 0 or 2
(2 where the input is surely bad), on 2 one line on stderr and nothing in its folder created or
changed, on 0 no NaN or infinity in a JSON, Markdown or CSV file it wrote. The examples are the
same every run (derandomized); online_preview_table.py runs plan once at most per example.

Usage: scripts_properties_test.py SOURCE_DIR PLAN OUT_DIR   (PLAN: BUILD/bin/plan)
Exit 0: passed; 1: failed (each failure and its example printed).
"""
import copy
import csv
import io
import json
import math
import os
import shutil
import sys
import tempfile
import time

try:
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    from hypothesis.configuration import set_hypothesis_home_dir
except ImportError:
    print("skipped: python3-hypothesis is not installed")
    sys.exit(77)

import script_inputs
from script_inputs import contract_problems, snapshot, written_non_finite

# Text with no letter of "nan" or "inf": a name drawn here never reads as a non-finite number.
TEXT = st.text(alphabet="bcdeghjklmopqrstuvwxyz_", max_size=6)
NAME = TEXT.filter(bool)
LEAF = st.none() | st.booleans() | st.integers() | st.floats() | TEXT
JSON = st.recursive(LEAF, lambda inner: st.lists(inner, max_size=3) |
                    st.dictionaries(TEXT, inner, max_size=3), max_leaves=6)
NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf, 10 ** 400])
BAD_CELL = st.sampled_from(["nan", "NaN", "inf", "-inf", "1e999", "", " ", "abc", "1,5", "0x1p3"])
HUGE = st.integers(200_000, 900_000)  # characters of a single line: under 1 MB

JSON_KINDS = ("other", "deep", "drop", "extra", "retype", "non-finite", "huge", "empty",
              "not utf-8", "folder", "missing")
CSV_KINDS = ("cell", "drop column", "extra column", "short row", "long row", "header only",
             "empty", "huge", "not utf-8", "folder", "missing")
# CSV kinds that make any table of numbers bad, wherever they fall.
BAD_TABLE = {"cell", "extra column", "short row", "long row", "empty", "huge", "not utf-8",
             "folder"}

SOURCE = PLAN = OUT = None
failures = []


# --- JSON and CSV, broken -----------------------------------------------------------------------

def paths(value, prefix=()):
    """Every path into a JSON value (keys and list indices), the root's () first."""
    found = [prefix]
    if isinstance(value, dict):
        for key, item in value.items():
            found += paths(item, prefix + (key,))
    elif isinstance(value, list):
        for index, item in enumerate(value):
            found += paths(item, prefix + (index,))
    return found


def at(value, path):
    for key in path:
        value = value[key]
    return value


def replaced(doc, path, new):
    """A copy of `doc` with the value at `path` replaced by `new` (deleted when new is DROP)."""
    if not path:
        return new
    doc = copy.deepcopy(doc)
    parent = at(doc, path[:-1])
    if new is DROP:
        del parent[path[-1]]
    else:
        parent[path[-1]] = new
    return doc


DROP = object()


def kind_of(value):
    if isinstance(value, bool) or value is None:
        return repr(value)
    return "number" if isinstance(value, (int, float)) else type(value).__name__


def json_file(data, base, kind, where=None):
    """`base` (a JSON value) broken as `kind` says: ("text", str), ("bytes", b), ("folder",) or
    ("missing",). `where` (paths) limits where a field is dropped or retyped."""
    inner = where or [p for p in paths(base) if p]
    if kind == "other":
        return "text", json.dumps(data.draw(JSON))
    if kind == "deep":
        depth = data.draw(st.integers(1000, 100_000))
        return "text", "[" * depth + "]" * depth
    if kind == "drop":
        return "text", json.dumps(replaced(base, data.draw(st.sampled_from(inner)), DROP))
    if kind == "extra":
        return "text", json.dumps(dict(base, **{"extra_" + data.draw(TEXT): data.draw(JSON)}))
    if kind == "retype":
        path = data.draw(st.sampled_from(inner))
        old = kind_of(at(base, path))
        return "text", json.dumps(replaced(base, path,
                                           data.draw(JSON.filter(lambda v: kind_of(v) != old))))
    if kind == "non-finite":
        numbers = [p for p in paths(base) if kind_of(at(base, p)) == "number"]
        path = data.draw(st.sampled_from(numbers))
        return "text", json.dumps(replaced(base, path, data.draw(NON_FINITE)))
    if kind == "huge":
        return "text", json.dumps(dict(base, extra_huge="b" * data.draw(HUGE)))
    return plain_file(kind, b'{"\xff\xfe": 1}')


def csv_file(data, header, rows, kind, cells=None):
    """A CSV table (`header`, `rows`) broken as `kind` says, as json_file's; `cells` ((row,
    column) pairs) limits where a cell is broken."""
    rows = [list(map(str, r)) for r in rows]
    cells = cells or [(i, j) for i in range(len(rows)) for j in range(len(header))]
    table = [list(header)] + rows
    if kind in ("cell", "huge", "not utf-8"):
        i, j = data.draw(st.sampled_from(cells))
        table[i + 1][j] = {"cell": lambda: data.draw(BAD_CELL),
                           "huge": lambda: "b" * data.draw(HUGE),
                           "not utf-8": lambda: "\udcff\udcfe"}[kind]()
    elif kind == "drop column":
        j = data.draw(st.integers(0, len(header) - 1))
        table = [r[:j] + r[j + 1:] for r in table]
    elif kind == "extra column":
        table = [table[0] + ["extra_" + data.draw(TEXT)]] + [r + ["1"] for r in table[1:]]
    elif kind in ("short row", "long row"):
        i = data.draw(st.integers(1, len(rows)))
        cut = data.draw(st.integers(1, len(header) - 1))
        table[i] = table[i][:-cut] if kind == "short row" else table[i] + ["1"] * cut
    elif kind == "header only":
        table = table[:1]
    else:
        return plain_file(kind, b"")
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows(table)
    return "bytes", text.getvalue().encode("utf-8", errors="surrogateescape")


def plain_file(kind, not_utf8):
    return {"empty": ("text", ""), "not utf-8": ("bytes", not_utf8), "folder": ("folder",),
            "missing": ("missing",)}[kind]


def place(path, made):
    """Puts `made` (json_file's, csv_file's) at `path`, replacing what is there."""
    if os.path.isdir(path):
        shutil.rmtree(path)
    elif os.path.lexists(path):
        os.remove(path)
    if made[0] == "folder":
        os.makedirs(path)
    elif made[0] != "missing":
        with open(path, "w" if made[0] == "text" else "wb") as f:
            f.write(made[1])


def write_json(path, value):
    with open(path, "w", encoding="utf-8") as f:
        json.dump(value, f)


# --- Each script: a case from a kind, (arguments, the exit statuses allowed, environment) ---

def plot_logs_case(data, scratch, kind):
    folder = os.path.join(scratch, "run")
    os.makedirs(folder)
    log = os.path.join(folder, script_inputs.LOG_CSV)
    script_inputs.write_csv(log, *script_inputs.log_table(SOURCE))
    script_inputs.write_csv(os.path.join(folder, "requests.csv"),
                            *script_inputs.plan_table(SOURCE))
    if kind == "missing folder":
        return [os.path.join(scratch, "none")], {2}, None
    if kind == "file for folder":
        return [log], {2}, None
    if kind == "figure's place":
        os.makedirs(os.path.join(folder, "plan.png"))
        return [folder], {2}, None
    header, rows = script_inputs.log_table(SOURCE)
    place(log, csv_file(data, header, rows, kind))
    return [folder], {2} if kind in BAD_TABLE | {"drop column"} else {0, 2}, None


def plot_sweep_case(data, scratch, kind):
    path = os.path.join(scratch, "sweep.csv")
    header, rows = script_inputs.sweep_table()
    script_inputs.write_csv(path, header, rows)
    outs = {"--out a folder": scratch, "--out under a file": os.path.join(path, "f.png"),
            "--out of no format": os.path.join(scratch, "f.xyz")}
    if kind in outs:
        return [path, "--out", outs[kind]], {2}, None
    text = {header.index("status"), header.index("model_source")}
    numbers = [(i, j) for i in range(3) for j in range(len(header)) if j not in text]
    place(path, csv_file(data, header, rows, kind, numbers))
    return [path], {2} if kind in BAD_TABLE | {"header only"} else {0, 2}, None


def report_case(data, scratch, kind):
    folder = os.path.join(scratch, "run")
    script_inputs.table_run(folder)
    write_json(os.path.join(folder, "log_fit.json"), script_inputs.log_fit())
    script_inputs.write_csv(os.path.join(folder, "sweep.csv"), *script_inputs.sweep_table())
    if kind == "missing folder":
        return [os.path.join(scratch, "none")], {2}, None
    if kind == "index.html a folder":
        os.makedirs(os.path.join(folder, "index.html"))
        return [folder], {2}, None
    file, kind = kind
    if file == "sweep.csv":
        place(os.path.join(folder, file), csv_file(data, *script_inputs.sweep_table(), kind))
    else:
        file = data.draw(st.sampled_from(["table2.json", "log_fit.json"]))
        with open(os.path.join(folder, file), encoding="utf-8") as f:
            place(os.path.join(folder, file), json_file(data, json.load(f), kind))
    return [folder], {0}, None  # a file it cannot read is shown as not read


def compare_engines_case(data, scratch, kind):
    ode, dart = os.path.join(scratch, "ode"), os.path.join(scratch, "dart")
    script_inputs.table_run(ode)
    script_inputs.table_run(dart, v_max=2.5125, foot_l2=1.5)
    if kind == "--out a file":
        return [ode, dart, "--out", os.path.join(dart, "table1.json")], {2}, None
    if kind == "engines.md a folder":
        os.makedirs(os.path.join(dart, "engines.md"))
        return [ode, dart], {2}, None
    file, kind = kind
    if file == "json":
        file = data.draw(st.sampled_from(["table1.json", "table2.json"]))
    path = os.path.join(data.draw(st.sampled_from([ode, dart])), file)
    if file.endswith(".csv"):
        header = ["tick", "request_deg", "actual_deg", "model_deg"]
        rows = [[t, 40, a, 0] for t, a in enumerate((0.0, 1.0, 2.0, 3.0))]
        place(path, csv_file(data, header, rows, kind, [(i, 2) for i in range(4)]))
        return [ode, dart], {2} if kind in BAD_TABLE else {0, 2}, None
    with open(path, encoding="utf-8") as f:
        place(path, json_file(data, json.load(f), kind))
    return [ode, dart], {2} if kind in ("non-finite", "not utf-8", "deep") else {0, 2}, None


def learned_fit_case(data, scratch, kind):
    run = os.path.join(scratch, "run")
    script_inputs.write_log_run(SOURCE, run)
    out = os.path.join(scratch, "out")
    flags = ["--size", "small", "--jobs", "1", "--build", os.path.dirname(os.path.dirname(PLAN))]
    if kind == "missing folder":
        return [os.path.join(scratch, "none"), "--out", out] + flags, {2}, None
    if kind in ("--out a file", "--out under a file"):
        target = os.path.join(run, "log_fit.json")
        out = target if kind == "--out a file" else os.path.join(target, "out")
        return [run, "--out", out] + flags, {2}, None
    file, kind = kind
    if file == "log_fit.json":
        # The fields leglab.servo.learned reads: one missing or of another type is refused.
        row = ("logs", 0)
        read = [("models",), ("models", "extended"), ("models", "extended", "xl330"),
                ("models", "extended", "xl330", "tick_s"), ("cross_validate",), ("folds",),
                ("logs",), row] + [row + (k,) for k in (
                    "file", "role", "held_out_by", "motor", "trajectory", "kp", "ticks_scored",
                    "mae_deg")] + [row + ("mae_deg", r) for r in (
                        "direct", "best_shift", "paper", "extended")]
        place(os.path.join(run, file), json_file(data, script_inputs.log_fit(), kind, read))
    else:
        header, rows = script_inputs.log_table(SOURCE)
        place(os.path.join(run, file), csv_file(data, header, rows, kind))
    return [run, "--out", out] + flags, {2}, None


def online_preview_case(data, scratch, kind):
    model, out = os.path.join(scratch, "log_fit.json"), os.path.join(scratch, "out")
    fit = script_inputs.log_fit()
    write_json(model, fit)
    tmp = os.path.join(scratch, "tmp")
    os.makedirs(tmp)
    env = dict(os.environ, TMPDIR=tmp)  # its run folders go here, and go away
    build = os.path.dirname(os.path.dirname(PLAN))
    flags = {"--motor": lambda: ["--motor", data.draw(NAME.filter(lambda m: m != "xl330"))],
             "--kp": lambda: ["--kp", data.draw(NAME | st.integers(0, 99_999).filter(
                 lambda k: k not in (100, 400, 800)).map(str))],
             "--build": lambda: ["--build", tmp],
             "--out a file": lambda: ["--out", model],
             "--out under a file": lambda: ["--out", os.path.join(model, "out")]}
    if kind in flags:
        return ["--model", model, "--out", out, "--build", build, *flags[kind]()], {2}, env
    motor = ("models", "extended", "xl330")
    # Fields plan reads and refuses missing or of another type: its first run fails.
    where = [motor[:1], motor[:2], motor] + [motor + (k,) for k, v in at(fit, motor).items()
                                             if kind_of(v) == "number"]
    place(model, json_file(data, fit, kind, where))
    return ["--model", model, "--out", out, "--build", build], {2}, env


SCRIPTS = {
    # The two that draw start slowly (matplotlib): fewer kinds, the others' cover the rest.
    "leglab.results.plot_logs": (plot_logs_case, 1,
                                 ["cell", "drop column", "short row", "not utf-8",
                                  "missing folder", "file for folder", "figure's place"]),
    "leglab.results.plot_sweep": (plot_sweep_case, 1,
                                  ["cell", "long row", "header only", "huge", "drop column",
                                   "--out a folder", "--out under a file", "--out of no format"]),
    # A JSON kind breaks one of the JSON files, drawn.
    "leglab.results.report": (report_case, 1,
                              [("json", k) for k in JSON_KINDS] +
                              [("sweep.csv", k) for k in CSV_KINDS] +
                              ["missing folder", "index.html a folder"]),
    "leglab.results.compare_engines": (compare_engines_case, 1,
                                       [("json", k) for k in JSON_KINDS] +
                                       [("step_knee_40.csv", k) for k in CSV_KINDS] +
                                       ["--out a file", "engines.md a folder"]),
    "leglab.servo.learned": (learned_fit_case, 1,
                             [("log_fit.json", k) for k in JSON_KINDS] +
                             [(script_inputs.LOG_CSV, k) for k in CSV_KINDS] +
                             ["missing folder", "--out a file", "--out under a file"]),
    "scripts/online_preview_table.py": (online_preview_case, 1,
                                        list(JSON_KINDS) + ["--motor", "--kp", "--build",
                                                            "--out a file", "--out under a file"]),
}


def check(script, case, kind, examples):
    """Runs `examples` examples of `case` for `kind`, each in a fresh folder; a broken contract
    is recorded with its example."""
    @settings(max_examples=examples, deadline=None, derandomize=True, database=None,
              suppress_health_check=list(HealthCheck))
    @given(st.data())
    def keeps_the_contract(data):
        scratch = tempfile.mkdtemp(prefix="case_", dir=OUT)
        try:
            argv, allowed, env = case(data, scratch, kind)
            before = snapshot(scratch)
            result = script_inputs.run([*script_inputs.command(SOURCE, script), *argv],
                                       cwd=SOURCE, env=env, timeout=60)
            after = snapshot(scratch)
            problems = contract_problems(result, before, after, tuple(sorted(allowed)))
            if result.returncode == 0:
                problems += [f"{f} holds a NaN or an infinity"
                             for f in written_non_finite(scratch, before, after)]
            assert not problems, f"{'; '.join(problems)}; stderr: {result.stderr[-400:]!r}"
        finally:
            shutil.rmtree(scratch, ignore_errors=True)

    try:
        keeps_the_contract()
    except Exception as e:  # hypothesis has printed the falsifying example
        failures.append(f"{script}, {kind}: {e}")


def main(argv):
    global SOURCE, PLAN, OUT
    SOURCE, PLAN, OUT = (os.path.abspath(a) for a in argv[1:4])
    shutil.rmtree(OUT, ignore_errors=True)
    os.makedirs(OUT)
    set_hypothesis_home_dir(os.path.join(os.path.dirname(OUT), ".hypothesis"))  # its caches
    for script, (case, examples, kinds) in SCRIPTS.items():
        if script == "leglab.servo.learned" and not script_inputs.compiled_package():
            print(f"{script}: skipped, this build has no leglab Python package")
            continue
        start = time.monotonic()
        for kind in kinds:
            check(script, case, kind, examples)
        print(f"{script}: {len(kinds) * examples} examples, {time.monotonic() - start:.1f} s")
    for failure in failures:
        print(f"FAIL: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
