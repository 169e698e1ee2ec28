"""Writes engines.md: two runs of the same experiment on the two physics engines (identify and
track with `--set sim.engine=dart` beside the same runs on ODE) side by side, with DART's
difference from ODE: Table 1, each step test's angles tick by tick, and Table 2 (the foot
table and every joint row).

Usage: python3 -m leglab.results.compare_engines ODE_RUN DART_RUN [--out DIR]
  ODE_RUN, DART_RUN  folders identify and/or track wrote (table1.json, step_*.csv,
                     table2.json); what both hold is compared
  --out DIR          where engines.md goes (default: DART_RUN)
Bad input (a folder that is missing or holds neither table, a file that does not parse, a
number that is not finite): one line on stderr, exit status 2, nothing written. Plain python3
(no numpy needed).
"""
from __future__ import annotations

import csv
import os
import sys
from typing import Any, Callable, Sequence

from . import reader

__all__ = ["BadInput", "compare", "main"]

JOINTS = ("rotator", "abductor", "knee")


class BadInput(Exception):
    """Bad input: one line naming the item (a folder, a file, a field); the command exits 2."""


def read_json(path: str) -> Any:
    try:
        data = reader.read_json(path)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as e:
        raise BadInput(f"'{path}' cannot be read as JSON: {e}") from None
    if not isinstance(data, dict):
        raise BadInput(f"'{path}' is not a JSON object")
    field = reader.non_finite_field(data)
    if field is not None:
        raise BadInput(f"'{path}': {field} is not a finite number")
    return data


def number(value: Any, path: str, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise BadInput(f"'{path}': {field} is not a number")
    return float(value)


def whole(value: Any, path: str, field: str) -> int:
    """A whole number of ticks as identify writes it (shown as it is)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise BadInput(f"'{path}': {field} is not a whole number of ticks")
    return value


def read_steps(path: str) -> list[float]:
    """A step test's actual angle per tick (the step_<joint>_<height>.csv identify writes)."""
    try:
        header, rows = reader.read_csv(path)
        reader.check_row_lengths(path, header, rows)
        return [reader.finite_number(row.actual_deg, f"row {number}")
                for number, row in enumerate(rows, 1)]
    except (OSError, UnicodeDecodeError, AttributeError, TypeError, ValueError, csv.Error) as e:
        raise BadInput(f"'{path}' is not a step test's CSV (tick,...,actual_deg): {e}") from None


def fmt(value: float, digits: int = 3) -> str:
    return f"{value:.{digits}f}"


def signed(value: float) -> str:
    """A difference with its sign, 4 decimals; one that rounds to zero is +0.0000."""
    text = f"{value:+.4f}"
    return "+0.0000" if text == "-0.0000" else text


def table1_section(ode_path: str, dart_path: str) -> list[str]:
    ode, dart = read_json(ode_path), read_json(dart_path)
    lines = ["## Table 1 (identify)", "",
             "| Joint | v_max ODE | v_max DART | theta_0 ODE | theta_0 DART | l ODE, DART "
             "| a ODE, DART | fit RMS ODE | fit RMS DART |",
             "|---|---|---|---|---|---|---|---|---|"]
    for joint in JOINTS:
        try:
            o, d = ode["joints"][joint], dart["joints"][joint]
            cells = [fmt(number(o.v_max_deg_per_tick, ode_path, "v_max"), 4),
                     fmt(number(d.v_max_deg_per_tick, dart_path, "v_max"), 4),
                     fmt(number(o.theta0_deg, ode_path, "theta_0")),
                     fmt(number(d.theta0_deg, dart_path, "theta_0")),
                     f"{whole(o.lag_ticks, ode_path, 'l')}, "
                     f"{whole(d.lag_ticks, dart_path, 'l')}",
                     f"{whole(o.accel_ticks, ode_path, 'a')}, "
                     f"{whole(d.accel_ticks, dart_path, 'a')}",
                     fmt(number(o.fit_rms_deg, ode_path, "the fit's RMS")),
                     fmt(number(d.fit_rms_deg, dart_path, "the fit's RMS"))]
        except (KeyError, AttributeError, TypeError) as e:
            raise BadInput(f"'{ode_path}' or '{dart_path}': no Table 1 entry {e} "
                           f"for joint {joint}") from None
        lines.append(f"| {joint} | " + " | ".join(cells) + " |")
    return lines + ["", "v_max in deg a tick (8 ms), theta_0 in deg, l and a in ticks.", ""]


def steps_section(ode_run: str, dart_run: str) -> list[str]:
    names = sorted(n for n in os.listdir(ode_run)
                   if n.startswith("step_") and n.endswith(".csv")
                   and os.path.isfile(os.path.join(dart_run, n)))
    if not names:
        return []
    lines = ["## Step tests", "",
             "Each step test's measured angle (the same sensor noise on both: same seed), "
             "DART's difference from ODE's over its ticks.", "",
             "| Step test | ticks | largest difference (deg) | mean absolute difference (deg) |",
             "|---|---|---|---|"]
    for name in names:
        ode = read_steps(os.path.join(ode_run, name))
        dart = read_steps(os.path.join(dart_run, name))
        if len(ode) != len(dart) or not ode:
            raise BadInput(f"'{name}': {len(ode)} ticks on ODE, {len(dart)} on DART")
        diffs = [abs(d - o) for o, d in zip(ode, dart)]
        lines.append(f"| {name[len('step_'):-len('.csv')]} | {len(ode)} | {fmt(max(diffs), 4)} "
                     f"| {fmt(sum(diffs) / len(diffs), 5)} |")
    return lines + [""]


def table2_section(ode_path: str, dart_path: str) -> list[str]:
    ode, dart = read_json(ode_path), read_json(dart_path)
    lines = ["## Table 2 (track): the foot, cm", "",
             "| Mode | L2 ODE | L2 DART | DART - ODE | Linf ODE | Linf DART | DART - ODE |",
             "|---|---|---|---|---|---|---|"]
    try:
        for mode, o in ode["foot_cm"].items():
            d = dart["foot_cm"][mode]
            cells = []
            for norm in ("L2", "Linf"):
                a = number(o[norm]["mean"], ode_path, f"foot_cm.{mode}.{norm}")
                b = number(d[norm]["mean"], dart_path, f"foot_cm.{mode}.{norm}")
                cells += [fmt(a), fmt(b), signed(b - a)]
            lines.append(f"| {mode} | " + " | ".join(cells) + " |")
        lines += ["", "## Table 2 (track): the joints, deg", "",
                  "| Row | " + " | ".join(f"{j} ODE | {j} DART" for j in JOINTS) + " |",
                  "|---|" + "---|---|" * len(JOINTS)]
        for row in ode["joints"][JOINTS[0]]:
            cells = []
            for joint in JOINTS:
                on_ode = ode["joints"][joint].get(row)
                on_dart = dart["joints"][joint].get(row)
                cells += [fmt(number(on_ode["mean"], ode_path, row)) if on_ode else "",
                          fmt(number(on_dart["mean"], dart_path, row)) if on_dart else ""]
            lines.append(f"| {row} | " + " | ".join(cells) + " |")
    except (KeyError, TypeError, AttributeError) as e:
        raise BadInput(f"'{ode_path}' and '{dart_path}' do not hold the same Table 2 "
                       f"(missing {e})") from None
    return lines + [""]


def compare(ode_run: str, dart_run: str) -> str:
    """engines.md's text: the same experiment on ODE and on DART, side by side.

    Parameters
    ----------
    ode_run, dart_run : str
        Folders identify and/or track wrote, the second with ``--set sim.engine=dart``.

    Returns
    -------
    str
        The Markdown: Table 1 and the step tests (both folders have table1.json), Table 2
        (both have table2.json), DART's differences beside each.

    Raises
    ------
    BadInput
        One line naming the item: a folder missing, no table in common, a file unreadable or
        not what the programs write, a number that is not finite.
    """
    for run in (ode_run, dart_run):
        if not os.path.isdir(run):
            raise BadInput(f"'{run}' is not a folder")
    lines = ["# The same experiment on ODE and on DART", "",
             f"ODE: `{ode_run}`; DART: `{dart_run}` (the same config with "
             "`--set sim.engine=dart`). Written by leglab.results.compare_engines.", ""]
    found = False
    sections: tuple[tuple[str, Callable[[str, str], list[str]]], ...] = (
        ("table1.json", table1_section), ("table2.json", table2_section))
    for table, section in sections:
        ode_path, dart_path = os.path.join(ode_run, table), os.path.join(dart_run, table)
        if os.path.isfile(ode_path) and os.path.isfile(dart_path):
            lines += section(ode_path, dart_path)
            if table == "table1.json":
                lines += steps_section(ode_run, dart_run)
            found = True
    if not found:
        raise BadInput(f"'{ode_run}' and '{dart_run}' hold no table1.json or table2.json in "
                       "common")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> None:
    """The command: ``python3 -m leglab.results.compare_engines ODE_RUN DART_RUN [--out DIR]``.

    Writes engines.md into --out (default DART_RUN), whole or not at all.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default sys.argv[1:]).

    Raises
    ------
    SystemExit
        Status 2 on bad input or a usage error, after one line on stderr.
    """
    parser = reader.ArgumentParser(prog="compare_engines.py",
                                           description=__doc__.split("\n")[0])
    parser.add_argument("ode_run")
    parser.add_argument("dart_run")
    parser.add_argument("--out")
    args = parser.parse_args(argv)
    try:
        text = compare(args.ode_run, args.dart_run)
        out = args.out or args.dart_run
        if not os.path.isdir(out):
            raise BadInput(f"--out '{out}' is not a folder")
        target = os.path.join(out, "engines.md")
        staging = f"{target}.compare-{os.getpid()}"
        try:
            with open(staging, "w", encoding="utf-8") as f:
                f.write(text + "\n")
            os.replace(staging, target)
        except OSError as e:
            if os.path.exists(staging):
                os.remove(staging)
            raise BadInput(f"--out '{out}': cannot write engines.md: {e.strerror}") from None
    except BadInput as e:
        print(f"compare_engines.py: error: {e}", file=sys.stderr)
        sys.exit(2)
    print(f"compare_engines.py: wrote {target}")


if __name__ == "__main__":
    main()
