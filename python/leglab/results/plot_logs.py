"""Draws the servo-log figures: one per log_<motor>_<name>.csv that identify wrote in its log
mode (the request, the measured angle and each model's prediction, held out where identify
cross-validated; ticks with the torque off greyed), and the plan figure of a folder plan wrote
(requests.csv: the desired motion, the planned requests and the model's predicted angle).

Usage: python3 -m leglab.results.plot_logs DIR [DIR ...]
Writes log_<motor>_<name>.png and plan.png beside the CSV files. Bad input (a folder that is
missing or holds neither table, a table that is not the declared one or holds a cell that is not
a finite number, a figure's place taken by a folder) prints one line naming the item and exits
2, having written nothing: every table is read and every figure drawn before any is put in
place.
"""
from __future__ import annotations

import csv
import os
import sys
from typing import Any, Callable, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import figures  # noqa: E402
from .. import ladder  # noqa: E402
from .reader import ArgumentParser, Row, one_line, read_finite_columns  # noqa: E402

# matplotlib has no types on Debian 12: a figure and its axes are Any.
_Figure = Any
_Axes = Any
# A drawn figure's hidden file and its place, put in place once every figure is drawn.
_Staged = list[tuple[str, str]]
# A figure's drawing: (table's path, table, figure's path, staged).
_Draw = Callable[[str, Row, str, _Staged], None]

__all__ = ["main"]

# The rungs' prediction columns follow the log's own four (time, request, measured, torque), in
# the ladder's order (servo/ladder.json), then any rung added for that fit.
LOG_COLUMNS = 4
# A rung the ladder does not hold (added for one fit): drawn in these, in turn.
ADDED_STYLES = [("tab:cyan", "-."), ("tab:olive", "-."), ("tab:pink", "-."), ("tab:gray", "-.")]


def rung_style(key: str, added: int) -> tuple[str, str, str]:
    """A `<rung>_deg` column's (color, line style, legend): the ladder's, or the `added`-th of
    ADDED_STYLES and the column's name for a rung the ladder does not hold."""
    found = ladder.rung(key.removesuffix("_deg"))
    if found:
        return found.color, found.linestyle, found.legend
    color, style = ADDED_STYLES[added % len(ADDED_STYLES)]
    return color, style, ladder.label(key.removesuffix("_deg"))


class BadInput(Exception):
    """Bad input: one line naming the item, exit status 2."""


def read_table(path: str) -> Row:
    """A table of numbers (read_finite_columns), its problems as BadInput."""
    try:
        return read_finite_columns(path)
    except OSError as e:
        raise BadInput(f"{path}: cannot be read ({e.strerror or e})") from None
    except (UnicodeDecodeError, ValueError, csv.Error) as e:
        text = str(e)
        raise BadInput(text if text.startswith(str(path)) else f"{path}: {text}") from None


def target(path: str) -> str:
    """`path`, a figure's place, refused when anything but a file is there."""
    if os.path.lexists(path) and not os.path.isfile(path):
        raise BadInput(f"{path}: in the way of the figure (not a file)")
    return path


def save(fig: _Figure, path: str, staged: _Staged) -> None:
    """Draws `fig` into a hidden file beside `path`, put in place once every figure is drawn."""
    figures.require(os.path.basename(path))
    fig.tight_layout()
    partial = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.{os.getpid()}")
    staged.append((partial, path))
    try:
        fig.savefig(partial, dpi=110, format="png")
    except OSError as e:
        raise BadInput(f"{path}: cannot be written ({e.strerror or e})") from None
    finally:
        plt.close(fig)


def grey_torque_off(ax: _Axes, time: list[float], enabled: list[float]) -> None:
    """Shades every stretch of ticks with the torque off (labelled once)."""
    start: float | None = None
    label: str | None = "torque off"
    for t, on in zip(time + [time[-1]], enabled + [1.0]):
        if on == 0.0 and start is None:
            start = t
        elif on != 0.0 and start is not None:
            ax.axvspan(start, t, color="0.85", lw=0, label=label)
            label = None
            start = None


def log_figure(path: str, c: Row, figure: str, staged: _Staged) -> None:
    fig, ax = plt.subplots(figsize=(10, 4))
    t = c.time_s
    grey_torque_off(ax, t, c.torque_enabled)
    ax.plot(t, c.request_deg, color="0.3", lw=1.0, label="request")
    ax.plot(t, c.measured_deg, color="k", lw=2.0, label="measured")
    added = 0
    for key in list(c)[LOG_COLUMNS:]:
        color, style, legend = rung_style(key, added)
        added += ladder.rung(key.removesuffix("_deg")) is None
        # Not drawn where the torque is off: nothing is predicted there.
        y = [v if on else float("nan") for v, on in zip(c[key], c.torque_enabled)]
        ax.plot(t, y, color=color, ls=style, lw=1.2, label=legend)
    name = os.path.basename(path)[len("log_"):-len(".csv")]
    ax.set_title(f"{name}: open-loop predictions (grey: torque off, not scored)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angle (deg)")
    ax.legend(fontsize=8, ncol=3, loc="best")
    save(fig, figure, staged)


def plan_figure(path: str, c: Row, figure: str, staged: _Staged) -> None:
    fig, ax = plt.subplots(figsize=(10, 4))
    t = c.time_s
    ax.plot(t, c.desired_deg, color="k", lw=2.0, label="desired")
    ax.plot(t, c.request_deg, color="tab:blue", lw=1.0, label="planned request")
    ax.plot(t, c.predicted_deg, color="tab:green", lw=1.2, label="predicted angle")
    beyond = [x for x, b in zip(t, c.beyond_servo) if b != 0.0]
    if beyond:
        ax.plot(beyond, [min(c.desired_deg)] * len(beyond), "|", color="tab:red",
                label="beyond the servo")
    ax.set_title("Planned requests and the model's predicted angle")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angle (deg)")
    ax.legend(fontsize=8, loc="best")
    save(fig, figure, staged)


def figures_of(folder: str) -> list[tuple[_Draw, str, Row, str]]:
    """[(draw, table's path, table, figure's path)] for every table `folder` holds, each read
    and checked; BadInput when it is not a folder or holds no table to draw."""
    if not os.path.isdir(folder):
        raise BadInput(f"{folder}: no such folder" if not os.path.lexists(folder) else
                       f"{folder}: not a folder")
    try:
        names = sorted(os.listdir(folder))
    except OSError as e:
        raise BadInput(f"{folder}: cannot be read ({e.strerror})") from None
    found: list[tuple[_Draw, str, str]] = [
        (log_figure, name, name[:-len(".csv")] + ".png") for name in names
        if name.startswith("log_") and name.endswith(".csv")]
    if "requests.csv" in names:
        found.append((plan_figure, "requests.csv", "plan.png"))
    if not found:
        raise BadInput(f"{folder}: no log_<motor>_<name>.csv or requests.csv to draw")
    return [(draw, os.path.join(folder, table), read_table(os.path.join(folder, table)),
             target(os.path.join(folder, figure))) for draw, table, figure in found]


def main(folders: Sequence[str]) -> int:
    """Reads and checks every table, draws every figure, then puts them all in place
    (``python3 -m leglab.results.plot_logs DIR [DIR ...]``).

    Parameters
    ----------
    folders : sequence of str
        Folders identify (on servo logs) or plan wrote.

    Returns
    -------
    int
        The exit status: 0, or 2 on bad input (one line on stderr, no figure written).
    """
    staged: _Staged = []  # (drawn file, its place)
    try:
        jobs = [job for folder in folders for job in figures_of(folder)]
        for draw, path, table, figure in jobs:
            if table:  # a table without rows draws nothing
                draw(path, table, figure, staged)
        for partial, figure in staged:
            os.replace(partial, figure)
            print("figure:", figure)
    except BadInput as e:
        print(f"plot_logs: {one_line(e)}", file=sys.stderr)
        return 2
    finally:
        for partial, _ in staged:
            if os.path.exists(partial):
                os.remove(partial)
    return 0


if __name__ == "__main__":
    parser = ArgumentParser(prog="plot_logs", description=__doc__.splitlines()[0])
    parser.add_argument("folders", nargs="+", metavar="DIR",
                        help="folders identify (logs) or plan wrote")
    sys.exit(main(parser.parse_args().folders))
