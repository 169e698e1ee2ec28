"""Writes a results page, RUN_DIR/index.html, for a folder the programs wrote (identify, track,
fit_walk, sweep, plan, identify on servo logs), and one index.html in every sub-run folder
beneath it (hind/, stand/, sweeps/<name>/, servo_logs/ ...), each linked from the pages above.

A page leads with the findings: every Markdown table the programs wrote (and a sweep's
sweep.csv) as HTML tables, on a page with sub-runs the real servos' held-out errors from the
shallowest log fit below, every figure (Fig. 8 first) with a caption saying what to look at,
the animation leg.gif when there is one; then the sub-runs, what the run's JSON files record of
its configuration, and links to the CSV and JSON files.
The pages are self-contained: inline CSS, no script, no font or anything else from a network;
figures and data files are linked by relative paths, so the folder can be moved or served.

Usage: python3 -m leglab.results.report RUN_DIR
Bad input (no such folder, or a folder holding nothing a program wrote): one line on stderr,
exit status 2, nothing written. Plain python3 (no numpy or matplotlib needed).
"""
from __future__ import annotations

import csv
import html
import json
import os
import re
import sys
import urllib.parse
from typing import Any, Collection, Iterable, Mapping, NoReturn, Sequence

from . import figures
from . import log_fit_results
from .reader import Row, read_csv, read_json, split_row

__all__ = ["main"]

# Files only the programs write: a folder holding one of them (or a folder beneath it that
# does) is a run. Everything else a page shows is found by extension.
RUN_MARKERS = ("table1.json", "table2.json", "walk_fit.json", "log_fit.json", "plan.json",
               "sweep.csv", "requests.csv")
RUN_MARKER_PATTERNS = (re.compile(r"^log_.+\.csv$"), re.compile(r"^sweep\.shard-.+\.csv$"))

# Tables in the order a reader meets them; other .md files follow by name.
TABLE_ORDER = ("table1.md", "table2.md", "walk_fit.md", "log_fit.md")

# Figures shown first, in this order (the paper's Fig. 8 leads); the others follow: those with a
# caption, then by name.
FIGURE_ORDER = ("fig8_foot_old_new.png",)

RUN_DESCRIPTIONS = {
    "hind": "The left hind leg: its own Table 1 and Table 2.",
    "stand": "The front leg on the single-leg test stand: Table 1 with the foot free of the "
             "floor, Table 2 walking on the floor.",
    "stand/air70": "The stand's step tests repeated with the leg in the air.",
    "stand/loaded": "The loaded step test on the stand.",
    "track_paper_regime": "Table 2 on the walk fitted to the paper's direct-method row (the "
                          "paper's regime), every mode.",
    "walk_fit": "The walk fitted to the paper's direct-method numbers (fit_walk).",
    "adapt_cold_start": "Learning the model while walking (adaptive), from a wrong model.",
    "adapt_wear": "Learning the model while walking through a change of the plant at step 20.",
    "adapt_wear/worn_model": "model_based with the model identified on the changed plant: "
                             "adapt_wear's yardstick.",
    "servo_logs": "Real servos: the model ladder on the shipped logs of two hobby servos, each "
                  "trajectory held out in turn.",
    "servo_logs/by_kp": "Real servos: the XL330 with each gain setting held out in turn.",
    "servo_logs/plan": "Requests planned through the fitted extended model for an XL330 log's "
                       "motion (plan).",
    "servo_logs/online": "The online planner against the batch plan by preview length: the "
                         "XL330's kp 400 logs as desired motions (plan --online).",
    "sweeps": "The sweeps: track over a grid of config values, one folder each.",
    "variants": "The runs the results page quotes beyond the shipped configs, one folder each "
                "(scripts/variants.py; --list prints each command).",
    "sweeps/walk_speed": "Sweep: the walk's step time from 40 to 120 ticks, every mode.",
    "sweeps/model_mismatch": "Sweep: the plant's servo delay and top speed around a fixed "
                             "model: how much model error the paper's method stands.",
    "sweeps/stand_load": "Sweep: the load on the test stand's carriage, where the paper's "
                         "model stops holding.",
    "sweeps/servo_firmware": "Sweep: servo firmware unlike the shipped one (delay, top speed, "
                             "PD speed law), every mode.",
}

# A sweep.csv longer than this is shown in part on the page (the file is linked).
SWEEP_TABLE_ROWS = 100

STYLE = """
body { font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Helvetica, Arial, sans-serif;
       max-width: 1200px; margin: 1.5em auto; padding: 0 1em; color: #1b1b1b; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { border-bottom: 1px solid #ccc; padding-bottom: 0.2em; margin-top: 1.6em; }
h3, h4 { margin-bottom: 0.3em; }
nav.crumbs { font-size: 0.9em; color: #555; }
table { border-collapse: collapse; margin: 0.6em 0 1em; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
tr:nth-child(even) td { background: #fafafa; }
.scroll { overflow-x: auto; }
code { background: #f2f2f2; padding: 0 0.2em; border-radius: 3px; font-size: 0.92em; }
pre { background: #f6f6f6; padding: 0.6em; overflow: auto; max-height: 30em; font-size: 0.85em; }
.note { color: #555; font-size: 0.92em; }
.figures { display: grid; grid-template-columns: repeat(auto-fill, minmax(520px, 1fr));
           gap: 1.2em; }
figure { margin: 0; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #333; }
figcaption code { font-size: 0.95em; }
ul.files { columns: 3; font-size: 0.9em; }
section.md { margin-bottom: 1.5em; }
"""


def fail(message: object) -> NoReturn:
    """Bad input: one line on stderr (control and undecodable characters escaped), status 2."""
    line = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(message))
    print(f"report.py: {line}", file=sys.stderr)
    sys.exit(2)


def href(path: str) -> str:
    """A relative link to path (a path below the page's folder, '/'-separated), percent-encoded
    from its bytes: a name that is not UTF-8 still links to its file."""
    return urllib.parse.quote(os.fsencode(path))


def natural_key(name: str) -> list[int | str]:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]


def is_run_folder(folder: str) -> bool:
    """True if a program wrote into folder itself."""
    names = os.listdir(folder)
    return any(n in RUN_MARKERS or any(p.match(n) for p in RUN_MARKER_PATTERNS) for n in names)


def find_runs(top: str) -> dict[str, list[str]]:
    """Every folder at or below top (relative paths, '' for top) that is a run or holds one,
    mapped to its sub-folders of the same kind."""
    tree: dict[str, list[str]] = {}
    # A folder is visited once, however links lead to it: a link to an ancestor (a loop) or a
    # second link to one folder adds nothing.
    seen: set[str] = set()

    def visit(rel: str) -> bool:
        folder = os.path.join(top, rel)
        seen.add(os.path.realpath(folder))
        children: list[str] = []
        for name in sorted(os.listdir(folder), key=natural_key):
            path = os.path.join(folder, name)
            if (name.startswith(".") or not os.path.isdir(path)
                    or os.path.realpath(path) in seen):
                continue
            child = f"{rel}/{name}" if rel else name
            if visit(child):
                children.append(child)
        if children or is_run_folder(folder):
            tree[rel] = children
            return True
        return False

    visit("")
    return tree


# ---- Markdown (the subset the programs write) -------------------------------------------------

def inline(text: str) -> str:
    """Escapes text and renders `code`, **bold** and *emphasis*."""
    parts = re.split(r"(`[^`]*`)", text)
    out = []
    for part in parts:
        if len(part) >= 2 and part.startswith("`") and part.endswith("`"):
            out.append(f"<code>{html.escape(part[1:-1])}</code>")
            continue
        part = html.escape(part, quote=False)
        part = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", part)
        part = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", part)
        out.append(part)
    return "".join(out)


def is_separator(line: str) -> bool:
    cells = split_row(line)
    return bool(cells) and all(re.fullmatch(r":?-{2,}:?", c) for c in cells)


def table_html(header: Sequence[str], rows: Sequence[list[str]]) -> str:
    out = ['<div class="scroll"><table>', "<thead><tr>"]
    out += [f"<th>{inline(c)}</th>" for c in header]
    out.append("</tr></thead><tbody>")
    for row in rows:
        row = row + [""] * (len(header) - len(row))
        out.append("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in row[:len(header)]) + "</tr>")
    out.append("</tbody></table></div>")
    return "".join(out)


def markdown_to_html(text: str, heading_shift: int = 2) -> str:
    """Headings, paragraphs, lists and pipe tables: what identify, track and fit_walk write.
    Headings are shifted down (# becomes <h3>) to sit under the page's own."""
    lines = text.splitlines()
    out: list[str] = []
    paragraph: list[str] = []
    items: list[str] = []

    def flush() -> None:
        if paragraph:
            out.append(f"<p>{inline(' '.join(paragraph))}</p>")
            paragraph.clear()
        if items:
            out.append("<ul>" + "".join(f"<li>{inline(i)}</li>" for i in items) + "</ul>")
            items.clear()

    i = 0
    while i < len(lines):
        line = lines[i].rstrip()
        heading = re.match(r"^(#{1,6})\s+(.*)$", line)
        if heading:
            flush()
            level = min(6, len(heading.group(1)) + heading_shift)
            out.append(f"<h{level}>{inline(heading.group(2))}</h{level}>")
        elif line.lstrip().startswith("|") and i + 1 < len(lines) and is_separator(lines[i + 1]):
            flush()
            header = split_row(line)
            i += 2
            rows: list[list[str]] = []
            while i < len(lines) and lines[i].lstrip().startswith("|"):
                rows.append(split_row(lines[i]))
                i += 1
            out.append(table_html(header, rows))
            continue
        elif re.match(r"^\s*[-*]\s+", line):
            if paragraph:
                flush()
            items.append(re.sub(r"^\s*[-*]\s+", "", line))
        elif not line.strip():
            flush()
        elif items and line.startswith("  "):
            items[-1] += " " + line.strip()
        else:
            if items:
                flush()
            paragraph.append(line.strip())
        i += 1
    flush()
    return "\n".join(out)


# ---- What the run records of its configuration -----------------------------------------------

def flatten(value: Any, prefix: str = "") -> list[tuple[str, Any]]:
    """(dotted key, scalar) pairs of a JSON value; lists of scalars kept whole."""
    if isinstance(value, dict):
        pairs: list[tuple[str, Any]] = []
        for key, sub in value.items():
            pairs += flatten(sub, f"{prefix}.{key}" if prefix else str(key))
        return pairs
    if isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        pairs = []
        for k, sub in enumerate(value):
            pairs += flatten(sub, f"{prefix}[{k}]")
        return pairs
    return [(prefix, value)]


def scalar_text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, dict)):
        return json.dumps(value)
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def key_value_table(pairs: Sequence[tuple[str, Any]]) -> str:
    rows = [[f"`{k}`", scalar_text(v).replace("|", "\\|")] for k, v in pairs]
    return table_html(["key", "value"], rows)


def matrix_table(rows: Mapping[str, Mapping[str, Any]]) -> str:
    """A dict of dicts (joint -> key -> value) as one row per joint, one column per key."""
    columns = list(dict.fromkeys(k for row in rows.values() for k in row))
    cells = [[name] + [scalar_text(row.get(k, "")) for k in columns] for name, row in rows.items()]
    return table_html([""] + [f"`{c}`" for c in columns], cells)


def config_parts(name: str, data: Any) -> list[tuple[str, Any]]:
    """The parts of a program's JSON file that describe the run's set-up rather than its
    results: (what they are, dotted key/value pairs or a dict of per-joint dicts)."""
    if not isinstance(data, dict):
        return []

    def pick(*keys: str) -> dict[str, Any]:
        return {k: data[k] for k in keys if k in data}

    if name == "table1.json":
        return [("identify: the plant the step tests ran on", flatten(pick("plant"))),
                ("identify: the paper's Table 1 it is compared with", flatten(pick("paper")))]
    if name == "table2.json":
        parts: list[tuple[str, Any]] = [("track: the measured steps", flatten(pick("steps")))]
        for key, what in (("model", "the controllers' model per joint"),
                          ("walk_model", "the model fitted to the walk (modes with model: walk)")):
            if isinstance(data.get(key), dict):
                parts.append((f"track: {what}", data[key]))
        return parts
    if name == "walk_fit.json":
        return [("fit_walk: its config, overrides and the fitted walk",
                 flatten(pick("program", "config", "overrides", "fitted_on", "fitted")))]
    if name == "log_fit.json":
        parts = [("identify on servo logs: its settings",
                  flatten({k: v for k, v in data.items() if k not in ("logs", "folds", "models")}))]
        models = data.get("models")
        for rung, motors in (models.items() if isinstance(models, dict) else ()):
            if isinstance(motors, dict) and all(isinstance(m, dict) for m in motors.values()):
                parts.append((f"identify on servo logs: the {rung} model fitted per servo type "
                              "(on all its training logs; the held-out scores come from models "
                              "fitted without the scored log)", motors))
        return parts
    if name == "plan.json":
        results = ("predicted_mae_deg", "beyond_servo_ticks")
        return [("plan: its settings and the servo it plans for",
                 [(k, v) for k, v in flatten({k: v for k, v in data.items() if k not in results})
                  if not isinstance(v, list)])]
    return []


def sweep_keys(rows: Sequence[Row], header: Sequence[str]) -> list[tuple[str, str]]:
    """A sweep's swept keys (the columns between index and status) and their values."""
    if "status" not in header:
        return []
    keys = header[1:header.index("status")] if header[:1] == ["index"] else \
        header[:header.index("status")]
    pairs: list[tuple[str, str]] = []
    for key in keys:
        values = list(dict.fromkeys(r.get(key) or "" for r in rows))
        pairs.append((key, ", ".join(values)))
    return pairs


def read_sweep(folder: str) -> tuple[list[str], list[Row]] | str:
    """The folder's sweep.csv as (header, rows), or the reason it cannot be read (a str): a file
    whose columns are not the declared ones is shown as not read, never a traceback."""
    path = os.path.join(folder, "sweep.csv")
    try:
        return read_csv(path)
    except (OSError, UnicodeDecodeError, ValueError, csv.Error) as error:
        return (str(error) or type(error).__name__).replace(path, "sweep.csv")


def not_read(name: str, why: str) -> str:
    """A note: the file `name` is shown as not read, and why."""
    return (f'<p class="note"><a href="{href(name)}">{html.escape(name)}</a>: not read '
            f"({html.escape(why)}).</p>")


def merged_config_parts(folder: str, names: Iterable[str]) -> list[str]:
    """The keys each program ran with, as it wrote them (<program>_config.yaml: the --config
    file, the files it extends, the robot file and every --set, merged)."""
    out = []
    for name in sorted((n for n in names if n.endswith("_config.yaml")), key=natural_key):
        try:
            with open(os.path.join(folder, name)) as f:
                text = f.read()
        except OSError as error:
            out.append(not_read(name, str(error)))
            continue
        program = name[:-len("_config.yaml")]
        out.append(f'<h4>The keys {html.escape(program)} ran with (<a href="{href(name)}">'
                   f"{html.escape(name)}</a>)</h4>")
        out.append(f"<pre>{html.escape(text)}</pre>")
    return out


def config_section(folder: str, names: Collection[str]) -> str:
    merged = merged_config_parts(folder, names)
    note = ("Each program writes the keys it ran with, merged (the <code>--config</code> file, "
            "the files it <code>extends:</code>, the robot's <code>robot.yaml</code> and every "
            "<code>--set</code>), as <code>&lt;program&gt;_config.yaml</code>; below them, what "
            "the run's JSON files record: the plant, the settings and the models the "
            "controllers used." if merged else
            "This folder holds no <code>&lt;program&gt;_config.yaml</code> (the merged keys a "
            "program ran with; <code>sweep</code> and <code>plan</code> write none). Shown here "
            "is what the run's JSON files record: the plant, the settings and the models the "
            "controllers used.")
    out = ["<h2 id=\"config\">Configuration</h2>",
           f'<p class="note">{note} <code>--list-keys</code> on a program and '
           "docs/configuration.md give every key and its default.</p>"] + merged
    shown = bool(merged)
    for name in sorted((n for n in names if n.endswith(".json")), key=natural_key):
        try:
            data = read_json(os.path.join(folder, name))
            parts = config_parts(name, data)
        except (OSError, ValueError, RecursionError) as error:
            # Not JSON, or JSON nested too deeply to walk: shown as not read, never a traceback.
            out.append(not_read(name, str(error) or type(error).__name__))
            continue
        for title, pairs in parts:
            if pairs:
                out.append(f'<h4>{html.escape(title)} (<a href="{href(name)}">'
                           f"{html.escape(name)}</a>)</h4>")
                out.append(matrix_table(pairs) if isinstance(pairs, dict)
                           else key_value_table(pairs))
                shown = True
    sweep = read_sweep(folder) if "sweep.csv" in names else None
    if isinstance(sweep, tuple):
        header, rows = sweep
        pairs = sweep_keys(rows, header)
        if pairs:
            out.append('<h4>sweep: the swept keys and their values (<a href="sweep.csv">'
                       "sweep.csv</a>; the base config is named in the sweep's YAML file, "
                       "which the folder does not hold)</h4>")
            out.append(key_value_table(pairs))
            shown = True
    if not shown:
        out.append('<p class="note">No file in this folder records a configuration.</p>')
    return "\n".join(out)


# ---- Pages ------------------------------------------------------------------------------------

def describe(rel: str, folder: str) -> str:
    if rel in RUN_DESCRIPTIONS:
        return RUN_DESCRIPTIONS[rel]
    names = set(os.listdir(folder))
    wrote = [program for program, marker in
             (("identify (Table 1)", "table1.json"), ("track (Table 2)", "table2.json"),
              ("fit_walk", "walk_fit.json"), ("identify on servo logs", "log_fit.json"),
              ("plan", "plan.json"), ("sweep", "sweep.csv")) if marker in names]
    return "A run of " + ", ".join(wrote) + "." if wrote else "Folders of runs."


def caption(name: str) -> str:
    return (figures.caption(name)
            or "A figure of this run (no caption is known for this file name).")


def holds(folder: str) -> str:
    """What a folder holds, counted: '(2 tables, 11 figures, 19 data files)'."""
    names = [n for n in os.listdir(folder) if os.path.isfile(os.path.join(folder, n))]
    counts = [(sum(n.endswith(".md") for n in names) + ("sweep.csv" in names), "table"),
              (sum(n.endswith(".png") for n in names), "figure"),
              (sum(n.endswith((".csv", ".json")) for n in names), "data file")]
    text = ", ".join(f"{k} {what}{'s' if k != 1 else ''}" for k, what in counts if k)
    return f"({text})" if text else ""


def runs_list(tree: Mapping[str, list[str]], top: str, rel: str, base: str) -> str:
    """A nested list of the sub-runs below rel, linked relative to the page of base."""
    children = tree.get(rel, [])
    if not children:
        return ""
    out = ["<ul>"]
    for child in children:
        link = os.path.relpath(child, base) if base else child
        out.append(f'<li><a href="{href(link + "/index.html")}">{html.escape(child)}/</a>: '
                   f"{inline(describe(child, os.path.join(top, child)))} "
                   f'<span class="note">{holds(os.path.join(top, child))}</span>'
                   f"{runs_list(tree, top, child, base)}</li>")
    out.append("</ul>")
    return "".join(out)


def size_text(path: str) -> str:
    size: float = os.path.getsize(path)
    for unit in ("B", "kB", "MB"):
        if size < 1000 or unit == "MB":
            return f"{size:.0f} {unit}" if unit == "B" else f"{size:.1f} {unit}"
        size /= 1000
    return ""


def crumbs(top: str, rel: str) -> str:
    """Links up the tree: top / sweeps / walk_speed."""
    parts = rel.split("/")
    links = []
    for k in range(len(parts)):
        label = os.path.basename(os.path.abspath(top)) if k == 0 else parts[k - 1]
        links.append(f'<a href="{"../" * (len(parts) - k)}index.html">{html.escape(label)}</a>')
    links.append(html.escape(parts[-1]))
    return f'<nav class="crumbs">{" / ".join(links)}</nav>'


def tables_section(folder: str, tables: Sequence[str], sweep: bool) -> str:
    """Every Markdown file rendered, then the sweep's table (its first SWEEP_TABLE_ROWS rows,
    long fractions shortened)."""
    out = ['<h2 id="tables">Tables</h2>']
    for name in tables:
        with open(os.path.join(folder, name), encoding="utf-8", errors="replace") as f:
            text = f.read()
        out.append(f'<section class="md"><p class="note">From <a href="{href(name)}">'
                   f"{html.escape(name)}</a>:</p>{markdown_to_html(text)}</section>")
    read = read_sweep(folder) if sweep else None
    if isinstance(read, str):
        out.append(not_read("sweep.csv", read))
    elif read:
        header, rows = read
        shown = rows[:SWEEP_TABLE_ROWS]
        note = (f" (the first {len(shown)} of its {len(rows)} points)"
                if len(rows) > len(shown) else f" ({len(rows)} points)")
        long_number = re.compile(r"-?\d+\.\d{7,}(e-?\d+)?")
        cells = [[scalar_text(float(r.get(h) or "")) if long_number.fullmatch(r.get(h) or "")
                  else (r.get(h) or "") for h in header] for r in shown]
        out.append(f'<section class="md"><h3>The sweep</h3><p class="note">From <a href='
                   f'"sweep.csv">sweep.csv</a>{note}; errors in deg (joints) and cm '
                   f"(foot).</p>{table_html(header, cells)}</section>")
    return "\n".join(out)


def servo_summary(tree: Mapping[str, list[str]], top: str, rel: str) -> str:
    """The real servos' headline for a page with sub-runs: the shallowest sub-run below rel
    whose log_fit.json holds held-out logs, each motor's mean held-out error by method, linked
    to that run's page; "" if none (or its JSON is not a log fit's)."""
    below = sorted((r for r in tree if r != rel and (not rel or r.startswith(rel + "/"))),
                   key=lambda r: (r.count("/"), natural_key(r)))
    for run in below:
        path = os.path.join(top, run, "log_fit.json")
        if not os.path.isfile(path):
            continue
        try:
            held_out = log_fit_results.logs_of(read_json(path), "validate")
            methods = log_fit_results.methods_of(held_out)
            means, counts = log_fit_results.mean_errors(held_out, [key for key, _ in methods])
        except (ValueError, KeyError, TypeError, AttributeError):
            continue
        if not means:
            continue
        rows = [[str(motor), str(counts[motor])] + [f"{row[key]:.2f}" for key, _ in methods]
                for motor, row in sorted(means.items())]
        link = os.path.relpath(run, rel) if rel else run
        header = ["servo", "held-out logs"] + [f"{name} (deg)" for _, name in methods]
        return (f'<section class="md"><h3>Real servos</h3><p class="note">Mean open-loop '
                f"prediction error on logs each model never saw, from "
                f'<a href="{href(link + "/index.html")}">{html.escape(run)}/</a>.</p>'
                f"{table_html(header, rows)}</section>")
    return ""


def page(tree: Mapping[str, list[str]], top: str, rel: str) -> str:
    folder = os.path.join(top, rel)
    names = sorted((n for n in os.listdir(folder) if os.path.isfile(os.path.join(folder, n))),
                   key=natural_key)
    title = os.path.basename(os.path.abspath(top)) + (f"/{rel}" if rel else "")
    body = [f"<h1>leglab results: {html.escape(title)}</h1>"]
    if rel:
        body.append(crumbs(top, rel))
    body.append(f"<p>{inline(describe(rel, folder))}</p>")

    tables = sorted((n for n in names if n.endswith(".md")),
                    key=lambda n: (TABLE_ORDER.index(n) if n in TABLE_ORDER else
                                   len(TABLE_ORDER), natural_key(n)))
    pictures = [n for n in names if n.endswith(".png")]
    pictures.sort(key=lambda n: (FIGURE_ORDER.index(n) if n in FIGURE_ORDER else len(FIGURE_ORDER),
                                 figures.caption(n) is None, natural_key(n)))
    data = [n for n in names if n.endswith((".csv", ".json"))]
    servos = servo_summary(tree, top, rel) if tree.get(rel) and "log_fit.json" not in names else ""
    # The findings first (tables, figures, the animation, the real servos), then where they
    # come from (sub-runs, configuration, data files).
    sections: list[tuple[str, str]] = []
    if tables or "sweep.csv" in names or servos:
        sections.append(("tables", "Tables"))
    if pictures:
        sections.append(("figures", "Figures"))
    if "leg.gif" in names:
        sections.append(("animation", "Animation"))
    if tree.get(rel):
        sections.append(("runs", "Sub-runs"))
    sections.append(("config", "Configuration"))
    if data:
        sections.append(("data", "Data files"))
    body.append("<p>" + " · ".join(f'<a href="#{i}">{t}</a>' for i, t in sections) + "</p>")

    if tables or "sweep.csv" in names or servos:
        body.append(tables_section(folder, tables, "sweep.csv" in names) + servos)
    if pictures:
        body.append('<h2 id="figures">Figures</h2><div class="figures">')
        for name in pictures:
            body.append(f'<figure><a href="{href(name)}"><img src="{href(name)}" alt="'
                        f'{html.escape(name)}"></a><figcaption><code>{html.escape(name)}'
                        f"</code>: {html.escape(caption(name))}</figcaption></figure>")
        body.append("</div>")
    if "leg.gif" in names:
        body.append('<h2 id="animation">Animation</h2><figure><img src="leg.gif" alt="leg.gif">'
                    "<figcaption><code>leg.gif</code>: the leg's animation, as "
                    "leglab.results.animate drew it from this run.</figcaption></figure>")
    if tree.get(rel):
        body.append('<h2 id="runs">Sub-runs</h2>')
        body.append(runs_list(tree, top, rel, rel))
    body.append(config_section(folder, names))
    if data:
        body.append('<h2 id="data">Data files</h2><ul class="files">')
        for name in data:
            body.append(f'<li><a href="{href(name)}">{html.escape(name)}</a> '
                        f'<span class="note">{size_text(os.path.join(folder, name))}</span></li>')
        body.append("</ul>")
    body.append('<p class="note">Written by leglab.results.report.</p>')
    return ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>leglab results: {html.escape(title)}</title>\n<style>{STYLE}</style>\n"
            "</head>\n<body>\n" + "\n".join(body) + "\n</body>\n</html>\n")


def main(argv: Sequence[str]) -> None:
    """The command: ``python3 -m leglab.results.report RUN_DIR``.

    Writes index.html into the folder and every sub-run folder below it, all or none.

    Parameters
    ----------
    argv : sequence of str
        sys.argv: the program's name, then RUN_DIR.

    Raises
    ------
    SystemExit
        Status 2 on bad input (one line on stderr, no page written).
    """
    if len(argv) != 2:
        fail("usage: report.py RUN_DIR")
    top = argv[1]
    if not os.path.isdir(top):
        fail(f"{top}: no such folder")
    try:
        tree = find_runs(top)
    except OSError as error:
        fail(f"cannot read {error.filename}: {error.strerror}")
    if not tree:
        fail(f"{top}: nothing a leglab program wrote (no table1.json, table2.json, "
             "walk_fit.json, log_fit.json, plan.json or sweep.csv here or below)")
    # Every page is made, then staged beside its place, before any is put in place: a folder
    # that cannot take its page leaves no page written anywhere.
    try:
        pages = {rel: page(tree, top, rel) for rel in tree}
    except OSError as error:
        fail(f"cannot read {error.filename}: {error.strerror}")
    staged: list[tuple[str, str]] = []
    try:
        for rel, text in pages.items():
            target = os.path.join(top, rel, "index.html")
            if os.path.isdir(target) and not os.path.islink(target):
                raise OSError(f"{target} is a folder")
            temporary = os.path.join(top, rel, f".index.html.report-{os.getpid()}")
            staged.append((temporary, target))
            with open(temporary, "w", encoding="utf-8", errors="surrogateescape") as f:
                f.write(text)
    except OSError as error:
        for temporary, _ in staged:
            if os.path.exists(temporary):
                os.remove(temporary)
        fail(f"cannot write the pages, none written: {error}")
    for temporary, target in staged:
        os.replace(temporary, target)
    print(f"report.py: {len(pages)} page(s), {os.path.join(top, 'index.html')}")


if __name__ == "__main__":
    main(sys.argv)
