#!/usr/bin/env python3
"""Draws a sweep's sweep.csv (build/bin/sweep) as a figure beside it (or where --out says).

- one swept key: every mode's foot L2 (and the floor's) against the key;
- two swept keys on a grid: heatmaps of model_based's foot L2 over direct's and over the best
  time shift's (below 1: the paper's method wins);
- three or more swept keys on a grid, with the time shift among the modes: each mode's (and the
  floor's) foot L2 over the best time shift's at every point, a strip per mode (below 1: the
  mode wins there), the median marked;
- otherwise: each mode's foot L2 against each swept key, one panel per key.

Usage: /usr/bin/python3 scripts/plot_sweep.py results/sweeps/walk_speed/sweep.csv [--out F.png]
Points whose status is not `ok` are left out (and counted in the title).
"""
import argparse
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

from results_reader import declared_columns, read_csv  # noqa: E402


def read_sweep(path):
    header, rows = read_csv(path)
    if "index" not in header or "status" not in header:
        sys.exit(f"plot_sweep: {path} is not a sweep.csv (no index or status column)")
    keys = header[header.index("index") + 1:header.index("status")]
    # A mode's column is "<mode>_foot_l2_cm"; the floor's is declared on its own.
    declared = set(declared_columns(path))
    modes = [c[: -len("_foot_l2_cm")] for c in header
             if c.endswith("_foot_l2_cm") and c not in declared]
    ok = [r for r in rows if r.status == "ok"]
    return keys, modes, ok, len(rows) - len(ok)


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def lines(ax, key, modes, rows):
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


def heatmap(ax, fig, keys, rows, numerator, denominator):
    xs = sorted({number(r[keys[1]]) for r in rows})
    ys = sorted({number(r[keys[0]]) for r in rows})
    grid = [[math.nan] * len(xs) for _ in ys]
    for r in rows:
        value = number(r[f"{numerator}_foot_l2_cm"]) / number(r[f"{denominator}_foot_l2_cm"])
        grid[ys.index(number(r[keys[0]]))][xs.index(number(r[keys[1]]))] = value
    finite = [v for row in grid for v in row if math.isfinite(v) and v > 0]
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


def strips(ax, modes, rows, baseline):
    names = [m for m in modes if m != baseline] + ["floor"]
    labels = []
    low, high = 1.0, 1.0
    for i, mode in enumerate(names):
        ratios = [number(r[f"{mode}_foot_l2_cm"]) / number(r[f"{baseline}_foot_l2_cm"])
                  for r in rows]
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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--out", help="figure file (default: sweep.png beside the csv)")
    args = parser.parse_args()
    keys, modes, rows, failed = read_sweep(args.csv)
    out = args.out or os.path.join(os.path.dirname(os.path.abspath(args.csv)), "sweep.png")
    if not rows:
        sys.exit(f"plot_sweep: no point of {args.csv} is ok: nothing to draw")
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
    fig.suptitle(f"{args.csv}: {len(rows)} points{note}", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"plot_sweep: {out}")


if __name__ == "__main__":
    main()
