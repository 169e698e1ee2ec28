#!/usr/bin/python3
"""The measured tables of README.md and docs/results/*.md, filled from a run's files or checked
against them, so that no number in them is copied by hand.

Usage: PYTHONPATH=build/python /usr/bin/python3 scripts/docs_numbers.py RESULTS [--write]
                                        [--only ID ...] [--docs DIR] [--build DIR]

RESULTS is a folder as scripts/reproduce.sh writes it (results/). In the docs a generated table
follows the marker naming its block (the table's lines, those starting with '|', are the block):

    <!-- numbers: table1 -->
    | ... |

and blocks() below says what each block shows and which of RESULTS' files it reads. Check (the
default): every block is rendered from RESULTS and compared with the docs cell by cell; a cell
whose file RESULTS lacks (the learned models' columns after a run without leglab.servo.learned)
is not compared, a block none of whose files RESULTS has is skipped (named on stderr). Any
difference: each one named on stderr, exit status 1. --write: every block RESULTS has all the
files of is replaced in the docs (the others are left as they are, and named). --only: just these blocks,
each of which must be checked in full (its files all there). The paper's values come from the
leglab package's compiled module (found through PYTHONPATH: --build's python/, which the message
names when it is missing), which has them from model/include/leglab/model/paper.h.

Bad input (no RESULTS folder, a file of it that is not what a program writes, a marker naming
no block, an --only block whose files are missing): one line on stderr, exit status 2, nothing
written.
"""
import os
import pathlib
import re
import sys

try:
    from leglab.results import log_fit_results
    from leglab.results.reader import ArgumentParser, split_row
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"docs_numbers: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

import numbers_beyond  # noqa: E402  (the scripts' folder, after leglab is found)
from numbers_run import (JOINTS, UNKNOWN, Missing, Run, UserError, cell, fixed,  # noqa: E402
                         joint_norm, paper_value, with_paper)

SOURCE_DIR = pathlib.Path(__file__).resolve().parent.parent
DOCS = ("README.md", "docs/results/paper.md", "docs/results/beyond.md", "docs/results/stand.md",
        "docs/results/servos.md")
BEGIN = re.compile(r"^<!-- numbers: ([a-z0-9-]+) -->$")

# BAM's own models on the XL330 logs (Rhoban/bam, its README's comparison of models m1, m4
# and m6 over these 12 logs and four more, fitted on all of them): published, not a run's.
BAM_PUBLISHED = {"xl330": "4.0-4.7 (not held out)"}


# --- the blocks -------------------------------------------------------------------------------

def table1_block(run, rms_row, lag_label):
    def rows():
        t = run.json("table1.json")
        p = t["paper"]
        j = [t["joints"][name] for name in JOINTS]
        out = [["v_max (deg/tick)", paper_value(p.v_max_deg_per_tick)] +
               [fixed(x.v_max_deg_per_tick) for x in j],
               ["theta_0 (deg)", paper_value(p.theta0_deg)] + [fixed(x.theta0_deg) for x in j],
               [lag_label, paper_value(p.lag_ticks)] + [str(x.lag_ticks) for x in j],
               ["a (ticks)", paper_value(p.accel_ticks)] + [str(x.accel_ticks) for x in j]]
        if rms_row:
            out.append(["fit RMS residual (deg)", ""] + [fixed(x.fit_rms_deg, 3) for x in j])
        return out
    return lambda: ["", "paper", *JOINTS], rows


def table2_joints_block(run, leglab):
    keys = ("L2(Des,Dir)", "Linf(Des,Dir)", "L2(Des,MB)", "Linf(Des,MB)", "L2(Pwl,MB)",
            "Linf(Pwl,MB)")

    def rows():
        t = run.json("table2.json")
        return [[key] + [with_paper(t["joints"][joint][key]["mean"], leglab.PAPER_TABLE2[key][i])
                         for i, joint in enumerate(JOINTS)] for key in keys]
    return lambda: ["", *JOINTS], rows


FOOT_NAMES = {"direct": "direct", "time_shift": "best time shift (k = {k})",
              "model_based": "model-based"}


def foot_block(run, leglab):
    def rows():
        foot = run.json("table2.json")["foot_cm"]
        out = []
        for mode, name in FOOT_NAMES.items():
            ours, paper = foot[mode], leglab.PAPER_FOOT_CM[mode]
            out.append([name.format(k=ours.get("k")), fixed(ours["L2"]["mean"]),
                        fixed(ours["Linf"]["mean"]), paper_value(paper["L2"]["mean"]),
                        paper_value(paper["Linf"]["mean"])])
        return out
    return lambda: ["method", "L2", "L-infinity", "paper L2", "paper L-infinity"], rows


def table2_summary_block(run, leglab):
    def rows():
        t = run.json("table2.json")
        foot = t["foot_cm"]
        out = []
        for key, mode in (("L2(Des,Dir)", "direct"), ("L2(Des,MB)", "model_based")):
            paper_foot = leglab.PAPER_FOOT_CM[mode]
            out.append([f"{key} [paper]"] +
                       [with_paper(t["joints"][j][key]["mean"], leglab.PAPER_TABLE2[key][i])
                        for i, j in enumerate(JOINTS)] +
                       [with_paper(foot[mode][n]["mean"], paper_foot[n]["mean"])
                        for n in ("L2", "Linf")])
        out.append(["L2(Pwl,MB) [paper]"] +
                   [with_paper(t["joints"][j]["L2(Pwl,MB)"]["mean"],
                               leglab.PAPER_TABLE2["L2(Pwl,MB)"][i])
                    for i, j in enumerate(JOINTS)] + ["", ""])
        shift, paper_shift = foot["time_shift"], leglab.PAPER_FOOT_CM["time_shift"]
        out.append([f"best time shift, k = {shift['k']} [paper]"] +
                   [joint_norm(t, "L2(Des,TS)", j) for j in JOINTS] +
                   [with_paper(shift[n]["mean"], paper_shift[n]["mean"]) for n in ("L2", "Linf")])
        return out
    return lambda: ["", *JOINTS, "foot L2", "foot Linf"], rows


def held_out(run, rel, keys, role="validate"):
    """log_fit_results.mean_errors of RESULTS/rel's logs with `role`."""
    return log_fit_results.mean_errors(log_fit_results.logs_of(run.json(rel), role), keys)


def kp_text(kps):
    return ", ".join(f"{kp:g}" for kp in kps)


def real_servos_block(run):
    """README's headline: each servo's held-out mean by method, the lowest in bold."""
    methods = [key for key, _ in log_fit_results.METHODS]
    learned = [key for key, _ in log_fit_results.LEARNED]

    def rows():
        means, counts = held_out(run, "servo_logs/log_fit.json", methods)
        logs = log_fit_results.logs_of(run.json("servo_logs/log_fit.json"), "validate")
        out = []
        for motor in sorted(means):
            numbers = [means[motor][key] for key in methods]
            nets = cell(lambda m=motor: held_out(run, "servo_logs/learned_fit.json",
                                                      learned)[0][m])
            best = min(numbers + (list(nets.values()) if nets else []))

            def shown(value):
                text = fixed(value)
                return f"**{text}**" if fixed(value) == fixed(best) else text
            kps = sorted({float(log["kp"]) for log in logs if log["motor"] == motor})
            label = f"{motor.upper()} ({counts[motor]} logs"
            label += f", kp {kp_text([kps[0]])}-{kp_text([kps[-1]])})" if len(kps) > 1 else ")"
            out.append([label] + [shown(x) for x in numbers] +
                       [", ".join(shown(nets[key]) for key in learned) if nets else UNKNOWN] +
                       [BAM_PUBLISHED.get(motor, "")])
        return out
    return lambda: ["servo", "direct", "best shift (hindsight)", "paper's model", "extended model",
             "learned (MLP, LSTM)", "BAM's physics models"], rows


def servo_ladder_block(run):
    """Every held-out log by motor and trajectory (a cell per gain), and each motor's mean."""
    methods = [key for key, _ in log_fit_results.METHODS]

    def rows():
        fit = run.json("servo_logs/log_fit.json")
        logs = log_fit_results.logs_of(fit, "validate")
        means, _ = log_fit_results.mean_errors(logs, methods)
        out = []
        for motor in sorted(means):
            mine = sorted((log for log in logs if log["motor"] == motor),
                          key=lambda log: (log["trajectory"], float(log["kp"])))
            for trajectory in sorted({log["trajectory"] for log in mine}):
                same = [log for log in mine if log["trajectory"] == trajectory]
                out.append([motor.upper(),
                            f"{trajectory} ({kp_text(float(log['kp']) for log in same)})"] +
                           [", ".join(fixed(log["mae_deg"][key]) for log in same)
                            for key in methods])
            out.append([f"**{motor.upper()}**", "**mean**"] +
                       [f"**{fixed(means[motor][key])}**" for key in methods])
        return out
    return lambda: ["servo", "trajectory (kp)", "direct", "best shift (hindsight)", "paper",
             "extended"], rows


def servo_plans_block(run):
    """The planned requests' predicted errors on each log's motion, the models fitted on every
    log (the logs a plan was made for), by motor and trajectory, a cell per gain."""
    def rows():
        logs = [log for log in run.json("servo_logs/log_fit.json")["logs"] if "plan" in log]
        out = []
        for motor in sorted({log["motor"] for log in logs}):
            mine = sorted((log for log in logs if log["motor"] == motor),
                          key=lambda log: (log["trajectory"], float(log["kp"])))
            for trajectory in sorted({log["trajectory"] for log in mine}):
                plans = [log["plan"] for log in mine if log["trajectory"] == trajectory]
                kps = [float(log["kp"]) for log in mine if log["trajectory"] == trajectory]
                out.append([motor.upper(), f"{trajectory} ({kp_text(kps)})"] +
                           [", ".join(fixed(mae(plan)) for plan in plans) for mae in
                            (lambda p: p.direct_mae_deg, lambda p: p.model_based_mae_deg,
                             lambda p: p.optimal_mae_deg)] +
                           [", ".join(str(plan.beyond_servo_ticks) for plan in plans)])
        return out
    return lambda: ["servo", "log (kp)", "direct", "model_based", "optimal",
                    "beyond servo (ticks)"], rows


def servo_by_kp_block(run):
    """The extended model's error on each log of the gain-setting folds, by the gain held out."""
    def rows():
        logs = log_fit_results.logs_of(run.json("servo_logs/by_kp/log_fit.json"), "validate")
        trajectories = sorted({log["trajectory"] for log in logs})
        out = []
        for kp in sorted({float(log["kp"]) for log in logs}):
            by_trajectory = {log["trajectory"]: log for log in logs if float(log["kp"]) == kp}
            out.append([kp_text([kp])] + [fixed(by_trajectory[t]["mae_deg"]["extended"])
                                          if t in by_trajectory else "" for t in trajectories])
        return out

    def header():
        logs = log_fit_results.logs_of(run.json("servo_logs/by_kp/log_fit.json"), "validate")
        return ["kp held out", *sorted({log["trajectory"] for log in logs})]
    return header, rows


def servo_learned_block(run):
    """identify's methods and the networks by servo and fold kind, held out and in sample."""
    methods = [key for key, _ in log_fit_results.METHODS]
    learned = [key for key, _ in log_fit_results.LEARNED]
    folds = (("servo_logs", "trajectory", "validate"), ("servo_logs/by_kp", "kp", "validate"),
             ("servo_logs", "in sample", "train"))

    def rows():
        out = []
        motors = sorted(held_out(run, "servo_logs/log_fit.json", methods)[0])
        for motor in motors:
            for folder, kind, role in folds:
                means = held_out(run, f"{folder}/log_fit.json", methods, role)[0]
                if motor not in means:
                    continue
                nets = cell(lambda f=folder, r=role, m=motor: held_out(
                    run, f"{f}/learned_fit.json", learned, r)[0][m])
                out.append([f"{motor.upper()}, {kind}"] +
                           [fixed(means[motor][key]) for key in methods] +
                           [fixed(nets[key]) if nets else UNKNOWN for key in learned])
        return out
    return lambda: ["servo, held out by"] + [name for _, name in log_fit_results.METHODS +
                                              log_fit_results.LEARNED], rows


def paper_regime_block(run, leglab):
    """Every mode on the walk fitted to the paper's direct row, beside the paper."""
    def rows():
        t = run.json("track_paper_regime/table2.json")
        foot = t["foot_cm"]

        def foot_cells(mode, paper):
            if paper is None:
                return [fixed(foot[mode][n]["mean"]) for n in ("L2", "Linf")]
            return [with_paper(foot[mode][n]["mean"], leglab.PAPER_FOOT_CM[mode][n]["mean"])
                    for n in ("L2", "Linf")]
        out = []
        for key, mode in (("L2(Des,Dir)", "direct"), ("Linf(Des,Dir)", None),
                          ("L2(Des,MB)", "model_based"), ("Linf(Des,MB)", None),
                          ("L2(Pwl,MB)", None), ("Linf(Pwl,MB)", None)):
            out.append([key] + [with_paper(t["joints"][j][key]["mean"],
                                           leglab.PAPER_TABLE2[key][i])
                                for i, j in enumerate(JOINTS)] +
                       (foot_cells(mode, True) if mode else ["", ""]))
        for label, key, mode, paper in (
                (f"best time shift (k = {foot['time_shift']['k']}), L2", "L2(Des,TS)",
                 "time_shift", True),
                ("floor, L2", "L2(Des,Floor)", "floor", None),
                ("optimal, L2", "L2(Des,Opt)", "optimal", None),
                ("ilc, L2", "L2(Des,ILC)", "ilc", None)):
            out.append([label] + [joint_norm(t, key, j) for j in JOINTS] +
                       foot_cells(mode, paper))
        return out
    return lambda: ["", *JOINTS, "foot L2", "foot Linf"], rows


def hind_block(run):
    """The hind leg's walk: each mode's L2 per joint and at the foot."""
    rows_of = (("floor", "L2(Des,Floor)", "floor"), ("L2(Des,Dir)", "L2(Des,Dir)", "direct"),
               ("best time shift (k = {k})", "L2(Des,TS)", "time_shift"),
               ("L2(Des,MB)", "L2(Des,MB)", "model_based"), ("L2(Pwl,MB)", "L2(Pwl,MB)", None),
               ("optimal", "L2(Des,Opt)", "optimal"), ("ilc", "L2(Des,ILC)", "ilc"))

    def rows():
        t = run.json("hind/table2.json")
        foot = t["foot_cm"]
        return [[label.format(k=foot["time_shift"]["k"])] +
                [joint_norm(t, key, j) for j in JOINTS] +
                [fixed(foot[mode]["L2"]["mean"]) if mode else ""]
                for label, key, mode in rows_of]
    return lambda: ["", *JOINTS, "foot L2"], rows


def engines_block(run):
    """Each mode's foot L2 on ODE and DART, front and hind leg."""
    runs = ("table2.json", "dart/table2.json", "hind/table2.json", "hind/dart/table2.json")
    modes = (("floor", "floor"), ("direct", "direct"), ("time_shift", "time shift"),
             ("model_based", "model-based"), ("optimal", "optimal"), ("ilc", "ilc"))

    def rows():
        feet = [run.json(rel)["foot_cm"] for rel in runs]
        return [[name] + [fixed(foot[mode]["L2"]["mean"], 3) for foot in feet]
                for mode, name in modes]
    return lambda: ["foot L2, cm", "front ODE", "front DART", "hind ODE", "hind DART"], rows


def stand_block(run):
    """The walk on the test stand: the foot's error and what the stance does, by mode."""
    def rows():
        t = run.json("stand/table2.json")
        stand, foot = t["stand"], t["foot_cm"]
        out = [["floor", fixed(foot["floor"]["L2"]["mean"], 3), "", "", "", "", ""]]
        for mode, s in stand["modes"].items():
            label = f"{mode} (k = {foot[mode]['k']})" if "k" in foot[mode] else mode
            out.append([label, fixed(foot[mode]["L2"]["mean"], 3),
                        fixed(s.stance_fz_n.mean / stand.carried_weight_n, 3),
                        fixed(s["peak_fz_n"], 1), f"{s['loaded_ticks']:.0f}",
                        f"{fixed(s['slip_mm']['mean'])} ({fixed(s['max_slip_mm'])})",
                        f"{fixed(s['sled_travel_x_mm']['mean'], 1)}, "
                        f"{fixed(s['sled_travel_y_mm']['mean'], 1)}"])
        return out
    return lambda: ["", "foot L2", "stance Fz / weight", "peak Fz (N)", "stance ticks",
                    "slip per stance (max)", "sled travel x, y (mm)"], rows


def walk_speed_block(run):
    """The walk_speed sweep: each mode's foot L2 (cm) by step time, the best policy in bold."""
    modes = ("direct", "time_shift", "model_based", "optimal", "ilc")

    def rows():
        out = []
        for row in run.rows("sweeps/walk_speed/sweep.csv"):
            foot = {mode: float(row[f"{mode}_foot_l2_cm"]) for mode in modes}
            best = min(foot, key=foot.get)

            def shown(mode):
                text = fixed(foot[mode], 3)
                if mode == "time_shift":
                    text += f" ({row['time_shift_k']})"
                return f"**{text}**" if mode == best else text
            out.append([row["track.t_step_ticks"], fixed(row.floor_foot_l2_cm, 3)] +
                       [shown(mode) for mode in modes])
        return out
    return lambda: ["t_step", "floor", "direct", "time shift (k)", "model_based", "optimal",
                    "ilc"], rows


def regimes_block(run):
    """The walk_speed sweep's direct, time-shift and model-based foot L2 (cm) and the ratio of
    the last two, by step time (the paper's 88 named)."""
    def rows():
        out = []
        for row in run.rows("sweeps/walk_speed/sweep.csv"):
            shift = float(row["time_shift_foot_l2_cm"])
            model = float(row["model_based_foot_l2_cm"])
            t_step = row["track.t_step_ticks"]
            out.append([f"{t_step} (the paper's)" if t_step == "88" else t_step,
                        fixed(row["direct_foot_l2_cm"], 3),
                        f"{fixed(shift, 3)} ({row['time_shift_k']})", fixed(model, 3),
                        fixed(model / shift)])
        return out
    return lambda: ["t_step (ticks)", "direct", "best time shift (k)", "model-based",
                    "model-based / time shift"], rows


def blocks(run, leglab):
    """Block id -> (header, rows): functions of RESULTS (header a list of cells, or a function
    giving it), rows raising Missing for a file RESULTS lacks."""
    return {
        "table1": table1_block(run, rms_row=False, lag_label="l (ticks of 8 ms)"),
        "table1-rms": table1_block(run, rms_row=True, lag_label="l (ticks)"),
        "table2-joints": table2_joints_block(run, leglab),
        "foot": foot_block(run, leglab),
        "table2-summary": table2_summary_block(run, leglab),
        "paper-regime": paper_regime_block(run, leglab),
        "hind": hind_block(run),
        "engines": engines_block(run),
        "stand-table2": stand_block(run),
        "regimes": regimes_block(run),
        "walk-speed": walk_speed_block(run),
        "real-servos": real_servos_block(run),
        "servo-ladder": servo_ladder_block(run),
        "servo-by-kp": servo_by_kp_block(run),
        "servo-plans": servo_plans_block(run),
        "servo-learned": servo_learned_block(run),
        **numbers_beyond.blocks(run),
    }


# --- rendering, checking and writing ----------------------------------------------------------

def row_text(cells):
    """A Markdown table row as the docs write it: `| a | b |`, an empty cell `| |`."""
    return "|" + "|".join(f" {c} " if c else " " for c in cells) + "|"


def render(block):
    """The block's table as rows of cells, the separator row as None; or raises Missing."""
    header_fn, rows_fn = block
    header = header_fn()
    rows = rows_fn()
    return [header, None, *rows]


def cells_of(line):
    """The cells of a docs table row (stripped), or None for a line that is not one."""
    return split_row(line) if line.startswith("|") and line.endswith("|") else None


def differences(rendered, lines):
    """How the docs' lines differ from the rendered rows: [(line offset, description)]."""
    if len(rendered) != len(lines):
        return [(0, f"{len(lines)} lines where the run gives {len(rendered)}")]
    out = []
    separator = "|" + "---|" * len(rendered[0])
    for offset, (row, line) in enumerate(zip(rendered, lines)):
        if row is None:
            if line != separator:
                out.append((offset, f"{line!r} where the run gives {separator!r}"))
            continue
        cells = cells_of(line)
        if cells is None or len(cells) != len(row):
            out.append((offset, f"{line!r} where the run gives {row_text(row)!r}"))
            continue
        for column, (want, have) in enumerate(zip(row, cells), 1):
            if want is not UNKNOWN and want != have:
                out.append((offset, f"column {column}: {have!r} where the run gives {want!r}"))
    return out


def text_of(rendered):
    lines = []
    for row in rendered:
        lines.append("|" + "---|" * len(rendered[0]) if row is None else row_text(row))
    return lines


def find_blocks(text, path, known):
    """[(id, first line index, end index)] of the blocks in `text`: each the table of lines
    starting with '|' right after its marker (the table's end ends the block)."""
    found, lines = [], text.split("\n")
    for i, line in enumerate(lines):
        match = BEGIN.match(line)
        if not match:
            continue
        if match.group(1) not in known:
            raise UserError(f"{path}:{i + 1}: no block named '{match.group(1)}' "
                            f"(scripts/docs_numbers.py's blocks())")
        end = i + 1
        while end < len(lines) and lines[end].startswith("|"):
            end += 1
        found.append((match.group(1), i + 1, end))
    return found


def load_leglab(build):
    """The leglab package with its compiled module (the paper's values), found on PYTHONPATH."""
    import leglab  # pylint: disable=import-outside-toplevel
    try:
        leglab.PAPER_MODEL  # pylint: disable=pointless-statement
    except ImportError:
        raise UserError(f"the leglab package's compiled module is not on PYTHONPATH: set "
                        f"PYTHONPATH={build}/python (scripts/test.sh builds it)") from None
    return leglab


def run_check(args):
    """0: the docs hold the run's numbers (or were written); 1: they differ."""
    if not os.path.isdir(args.results):
        raise UserError(f"{args.results}: no such folder")
    run = Run(args.results)
    registry = blocks(run, load_leglab(args.build))
    only = args.only or list(registry)
    for name in only:
        if name not in registry:
            raise UserError(f"--only: no block named '{name}' (have: {', '.join(registry)})")
    docs = {}
    for rel in DOCS:
        path = os.path.join(args.docs, rel)
        try:
            with open(path, encoding="utf-8") as f:
                docs[rel] = f.read()
        except (OSError, UnicodeDecodeError) as e:
            raise UserError(f"{path}: not readable: {e}") from None
    placed = {rel: find_blocks(text, rel, registry) for rel, text in docs.items()}
    unplaced = set(registry) - {name for found in placed.values() for name, _, _ in found}
    if unplaced:
        raise UserError(f"block '{sorted(unplaced)[0]}' is in none of {', '.join(DOCS)}")

    rendered, incomplete = {}, {}
    for name in only:
        run.missing.clear()
        try:
            rendered[name] = render(registry[name])
        except Missing:
            if args.only:
                raise UserError(f"block '{name}' needs {args.results}/"
                                f"{sorted(run.missing)[0]}") from None
            print(f"docs_numbers: skipped '{name}' (no {sorted(run.missing)[0]})",
                  file=sys.stderr)
            continue
        if run.missing:
            if args.only:
                raise UserError(f"block '{name}' needs {args.results}/{sorted(run.missing)[0]}")
            incomplete[name] = sorted(run.missing)

    for name, missing in incomplete.items():
        print(f"docs_numbers: '{name}' {'left as it is' if args.write else 'checked'} "
              f"without {', '.join(missing)}", file=sys.stderr)
    if args.write:
        write_blocks(args.docs, docs, placed,
                     {name: rows for name, rows in rendered.items() if name not in incomplete})
        return 0
    drift = [f"{rel}:{first + offset + 1}: '{name}': {what}"
             for rel in DOCS for name, first, end in placed[rel] if name in rendered
             for offset, what in differences(rendered[name], docs[rel].split("\n")[first:end])]
    for line in drift:
        print(line, file=sys.stderr)
    if drift:
        print(f"docs_numbers: the docs differ from {args.results} ({len(drift)} difference{'s' if len(drift) > 1 else ''}); "
              f"/usr/bin/python3 scripts/docs_numbers.py {args.results} --write updates them",
              file=sys.stderr)
        return 1
    print(f"docs_numbers: {len(rendered)} blocks hold {args.results}'s numbers", file=sys.stderr)
    return 0


def write_blocks(root, docs, placed, rendered):
    """Replaces the `rendered` blocks in the docs under `root`; each changed file is written
    whole to a temporary file and renamed over the old one."""
    for rel, text in docs.items():
        lines = text.split("\n")
        for name, first, end in reversed(placed[rel]):
            if name in rendered:
                lines[first:end] = text_of(rendered[name])
        new_text = "\n".join(lines)
        if new_text != text:
            path = os.path.join(root, rel)
            with open(path + ".tmp", "w", encoding="utf-8") as f:
                f.write(new_text)
            os.replace(path + ".tmp", path)
            print(f"docs_numbers: wrote {rel}", file=sys.stderr)


def main(argv):
    parser = ArgumentParser(
        prog="docs_numbers.py", description="Fill or check the docs' measured tables from a run.")
    parser.add_argument("results", help="a folder as scripts/reproduce.sh writes it")
    parser.add_argument("--write", action="store_true",
                        help="replace the blocks in the docs instead of checking them")
    parser.add_argument("--only", nargs="+", metavar="ID",
                        help="just these blocks, each with all its files")
    parser.add_argument("--docs", default=str(SOURCE_DIR),
                        help="the folder holding README.md and docs/ (default: this repository)")
    parser.add_argument("--build", default=str(SOURCE_DIR / "build"),
                        help="the build folder whose python/ holds the leglab package (to be "
                             "on PYTHONPATH)")
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:
        return 2 if e.code else 0
    try:
        return run_check(args)
    except UserError as e:
        print(f"docs_numbers: error: {e}", file=sys.stderr)
        return 2
    except (KeyError, TypeError, ValueError, IndexError, AttributeError) as e:
        print(f"docs_numbers: error: {args.results}: not what the programs write "
              f"({type(e).__name__}: {e})", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
