"""Draws a sweep's sweep.csv (build/bin/sweep) as a figure beside it (or where --out says).

- one swept key: every mode's foot L2 (and the floor's) against the key;
- two swept keys on a grid: heatmaps of model_based's foot L2 over direct's and over the best
  time shift's (below 1: the paper's method wins);
- three or more swept keys on a grid, with the time shift among the modes: each mode's (and the
  floor's) foot L2 over the best time shift's at every point, a strip per mode (below 1: the
  mode wins there), the median marked;
- otherwise: each mode's foot L2 against each swept key, one panel per key.

Usage: python3 -m leglab.results.plot_sweep results/sweeps/walk_speed/sweep.csv [--out F.png]
Points whose status is not `ok` are left out (and counted in the title).
Bad input (a file that is not a sweep.csv: its columns, a row's cells, a cell of an ok point that
is not a finite number where sweep writes one; an --out that cannot be written) prints one line
naming the file, row and column or the flag and exits 2, having written nothing.
"""
from __future__ import annotations

import csv
import math
import os
import sys
from typing import Any, Mapping, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

from .reader import (ArgumentParser, Row, check_row_lengths, declared_columns,  # noqa: E402
                      finite_number, one_line, read_csv)

__all__ = ["main"]

# matplotlib has no types on Debian 12: a figure and its axes are Any.
_Figure = Any
_Axes = Any


class BadInput(Exception):
    """Bad input: one line naming the item, exit status 2."""


def owners(header: Sequence[str], modes: list[str],
           text_columns: Sequence[str]) -> dict[str, str | None]:
    """Each result column (after status, but the declared text ones) mapped to whose it is: a
    base mode, the floor or the model (the longest prefix that fits), or None for a column no
    sweep writes."""
    prefixes = sorted(modes + ["floor", "model"], key=len, reverse=True)
    return {c: next((p for p in prefixes if c.startswith(p + "_")), None)
            for c in header[header.index("status") + 1:] if c not in text_columns}


def check_point(where: str, row: Row, keys: Sequence[str], owner_of: Mapping[str, str | None],
                modes: Sequence[str]) -> None:
    """An ok point as sweep writes it: its keys and results finite numbers, save a mode the
    point did not run, whose results are all empty. ValueError naming `where` (the file and
    row) and the column otherwise."""
    for key in keys:
        finite_number(row[key], f"{where}, column {key}")
    not_run = {m for m in modes if not any(row[c] for c, o in owner_of.items() if o == m)}
    for c, owner in owner_of.items():
        if owner not in not_run:
            finite_number(row[c], f"{where}, column {c}")


def read_sweep(path: str) -> tuple[list[str], list[str], list[Row], int]:
    """A sweep.csv: (swept keys, base modes, the ok points, how many are not ok), every cell
    checked as the sweep's merge checks it; BadInput naming the file (row and column) when it is
    not one."""
    if os.path.isdir(path):
        raise BadInput(f"{path}: a folder, not a sweep.csv")
    try:
        header, rows = read_csv(path)
        declared = declared_columns(path)
        if header[:1] != ["index"]:
            raise ValueError(f"{path}: expected 'index' as the first column")
        keys = header[1:header.index("status")]
        if not keys:
            raise ValueError(f"{path}: no swept key (no column between index and status)")
        check_row_lengths(path, header, rows)
        # A mode's column is "<mode>_foot_l2_cm"; the floor's is declared on its own.
        modes = [c[: -len("_foot_l2_cm")] for c in header
                 if c.endswith("_foot_l2_cm") and c not in declared]
        owner_of = owners(header, modes, [c for c in declared if "<" not in c])
        strays = [c for c, owner in owner_of.items() if owner is None]
        if strays:
            raise ValueError(f"{path}: column '{strays[0]}' is no mode's, the floor's or the "
                             "model's")
        for number, row in enumerate(rows, 1):
            finite_number(row["index"], f"{path}: row {number}, column index")
            if row.status == "ok":
                check_point(f"{path}: row {number}", row, keys, owner_of, modes)
            elif not row.status or any(row[c] for c in owner_of):
                raise ValueError(f"{path}: row {number}: expected status ok, or why the point "
                                 "failed and no results")
    except OSError as e:
        raise BadInput(f"{path}: cannot be read ({e.strerror or e})") from None
    except (UnicodeDecodeError, ValueError, csv.Error) as e:
        text = str(e)
        raise BadInput(text if text.startswith(str(path)) else f"{path}: {text}") from None
    ok = [r for r in rows if r.status == "ok"]
    return keys, modes, ok, len(rows) - len(ok)


def output(path: str | None, csv_path: str) -> str:
    """The figure's path (default sweep.png beside the csv), refused where it cannot be: a
    folder in its place, no folder for it, a format matplotlib does not write."""
    out = path or os.path.join(os.path.dirname(os.path.abspath(csv_path)), "sweep.png")
    folder = os.path.dirname(os.path.abspath(out))
    suffix = os.path.splitext(out)[1][1:].lower()
    if os.path.isdir(out):
        raise BadInput(f"--out {out}: a folder, not a file")
    if not os.path.isdir(folder):
        raise BadInput(f"--out {out}: no folder {folder}")
    if suffix and suffix not in FigureCanvasAgg.get_supported_filetypes():
        raise BadInput(f"--out {out}: no figure format .{suffix}")
    return out


def number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


def ratio(numerator: str, denominator: str) -> float:
    """numerator / denominator, NaN where it is no finite number (an empty cell, a zero
    denominator, an overflow)."""
    a, b = number(numerator), number(denominator)
    value = a / b if b != 0 else math.nan
    return value if math.isfinite(value) else math.nan


def lines(ax: _Axes, key: str, modes: list[str], rows: Sequence[Row]) -> None:
    rows = sorted(rows, key=lambda r: number(r[key]))
    x = [number(r[key]) for r in rows]
    for mode in modes + ["floor"]:
        y = [number(r[f"{mode}_foot_l2_cm"]) for r in rows]
        style = dict(color="black", linestyle="--") if mode == "floor" else dict(marker="o")
        ax.plot(x, y, label=mode, **style)
    ax.set_xlabel(key)
    ax.set_ylabel("foot L2 (cm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)


def heatmap(ax: _Axes, fig: _Figure, keys: Sequence[str], rows: Sequence[Row], numerator: str,
            denominator: str) -> None:
    xs = sorted({number(r[keys[1]]) for r in rows})
    ys = sorted({number(r[keys[0]]) for r in rows})
    grid = [[math.nan] * len(xs) for _ in ys]
    for r in rows:
        value = ratio(r[f"{numerator}_foot_l2_cm"], r[f"{denominator}_foot_l2_cm"])
        grid[ys.index(number(r[keys[0]]))][xs.index(number(r[keys[1]]))] = value
    finite = [v for row in grid for v in row
              if math.isfinite(v) and v > 0 and math.isfinite(1 / v)]
    # A ratio and its inverse equally far from white: a log scale symmetric about 1.
    spread = max([1.05] + [max(v, 1 / v) for v in finite])
    image = ax.imshow(grid, origin="lower", aspect="auto", cmap="RdBu_r",
                      norm=LogNorm(vmin=1 / spread, vmax=spread))
    ax.set_xticks(range(len(xs)), [f"{v:g}" for v in xs], rotation=45, fontsize=7)
    ax.set_yticks(range(len(ys)), [f"{v:g}" for v in ys], fontsize=7)
    ax.set_xlabel(keys[1])
    ax.set_ylabel(keys[0])
    for i, row in enumerate(grid):
        for j, v in enumerate(row):
            if math.isfinite(v):
                ax.text(j, i, f"{v:.2f}", ha="center", va="center", fontsize=6)
    ax.set_title(f"foot L2: {numerator} / {denominator}", fontsize=9)
    bar = fig.colorbar(image, ax=ax, fraction=0.046)
    ticks = [t for t in (0.2, 0.25, 1 / 3, 0.5, 2 / 3, 1, 1.5, 2, 3, 4, 5) if 1 / spread <= t <= spread]
    bar.set_ticks(ticks, labels=[f"{t:.2g}" for t in ticks])
    bar.minorticks_off()


def strips(ax: _Axes, modes: Sequence[str], rows: Sequence[Row], baseline: str) -> None:
    names = [m for m in modes if m != baseline] + ["floor"]
    labels = []
    low, high = 1.0, 1.0
    for i, mode in enumerate(names):
        ratios = [ratio(r[f"{mode}_foot_l2_cm"], r[f"{baseline}_foot_l2_cm"]) for r in rows]
        ratios = sorted(v for v in ratios if math.isfinite(v) and v > 0)
        if not ratios:
            labels.append(mode)
            continue
        low, high = min(low, ratios[0]), max(high, ratios[-1])
        # A fixed spread across the strip (no random jitter: the same csv, the same figure).
        x = [i + 0.3 * ((k * 0.618034) % 1.0 - 0.5) for k in range(len(ratios))]
        ax.scatter(x, ratios, s=9, alpha=0.6, **(dict(color="black") if mode == "floor" else {}))
        n = len(ratios)
        median = ratios[n // 2] if n % 2 else 0.5 * (ratios[n // 2 - 1] + ratios[n // 2])
        ax.plot([i - 0.25, i + 0.25], [median, median], color="red", linewidth=2)
        wins = sum(v < 1 for v in ratios)
        labels.append(f"{mode}\nmedian {median:.2f}\nbelow 1: {wins}/{n}")
    ax.axhline(1.0, color="gray", linestyle="--", linewidth=1)
    ax.set_yscale("log")
    ax.set_ylim(low / 1.2, high * 1.2)
    ax.set_xticks(range(len(names)), labels, fontsize=8)
    ax.set_ylabel(f"foot L2 / {baseline}'s (log)")
    ax.grid(alpha=0.3, axis="y")


def main() -> int:
    """The command: ``python3 -m leglab.results.plot_sweep SWEEP_CSV [--out F.png]``.

    Returns
    -------
    int
        The exit status: 0, or 2 on bad input (one line on stderr, nothing written).

    Raises
    ------
    SystemExit
        Status 2 on a usage error.
    """
    parser = ArgumentParser(prog="plot_sweep", description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--out", help="figure file (default: sweep.png beside the csv)")
    args = parser.parse_args()
    try:
        keys, modes, rows, failed = read_sweep(args.csv)
        out = output(args.out, args.csv)
        if not rows:
            raise BadInput(f"{args.csv}: no point is ok: nothing to draw")
        save(draw(args.csv, keys, modes, rows, failed), out)
    except BadInput as e:
        print(f"plot_sweep: {one_line(e)}", file=sys.stderr)
        return 2
    print(f"plot_sweep: {out}")
    return 0


def draw(name: str, keys: Sequence[str], modes: list[str], rows: Sequence[Row],
         failed: int) -> _Figure:
    """The figure of the ok points `rows` (see the module's doc for which)."""
    note = f" ({failed} points not ok, left out)" if failed else ""
    if len(keys) == 2 and "model_based" in modes and len(
            {(r[keys[0]], r[keys[1]]) for r in rows}) == len(rows):
        baselines = [m for m in ("direct", "time_shift") if m in modes]
        fig, axes = plt.subplots(1, len(baselines), figsize=(6.5 * len(baselines), 5),
                                 squeeze=False)
        for ax, baseline in zip(axes[0], baselines):
            heatmap(ax, fig, keys, rows, "model_based", baseline)
    elif len(keys) >= 3 and "time_shift" in modes:
        fig, ax = plt.subplots(figsize=(1.8 * len(modes) + 3, 5))
        strips(ax, modes, rows, "time_shift")
    else:
        fig, axes = plt.subplots(1, len(keys), figsize=(7 * len(keys), 4.5), squeeze=False)
        for ax, key in zip(axes[0], keys):
            lines(ax, key, modes, rows)
    fig.suptitle(f"{name}: {len(rows)} points{note}", fontsize=10)
    fig.tight_layout()
    return fig


def save(fig: _Figure, out: str) -> None:
    """Writes the figure beside `out` and renames it into place: never half a file."""
    folder, base = os.path.split(os.path.abspath(out))
    partial = os.path.join(folder, f".{base}.{os.getpid()}")
    suffix = os.path.splitext(out)[1][1:].lower() or "png"
    try:
        fig.savefig(partial, dpi=110, format=suffix)
        os.replace(partial, out)
    except OSError as e:
        raise BadInput(f"--out {out}: cannot be written ({e.strerror or e})") from None
    except ValueError as e:  # matplotlib's: e.g. a figure too large for its image size
        raise BadInput(f"--out {out}: cannot be drawn ({e})") from None
    finally:
        plt.close(fig)
        if os.path.exists(partial):
            os.remove(partial)


if __name__ == "__main__":
    sys.exit(main())
