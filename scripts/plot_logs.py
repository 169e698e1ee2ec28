#!/usr/bin/python3
"""Draws the servo-log figures: one per log_<motor>_<name>.csv that identify wrote in its log
mode (the request, the measured angle and each model's prediction, held out where identify
cross-validated; ticks with the torque off greyed), and the plan figure of a folder plan wrote
(requests.csv: the desired motion, the planned requests and the model's predicted angle).

Usage: /usr/bin/python3 scripts/plot_logs.py DIR [DIR ...]
Writes log_<motor>_<name>.png and plan.png beside the CSV files.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import figures  # noqa: E402
from results_reader import read_columns  # noqa: E402

# The rungs' prediction columns follow the log's own four (time, request, measured, torque), in
# the ladder's order: direct, best shift, the paper's model, the extended model.
LOG_COLUMNS = 4
RUNG_STYLES = [("0.6", ":"), ("tab:purple", "--"), ("tab:orange", "-"), ("tab:green", "-")]
RUNG_LABELS = {"direct": "direct (angle = request)", "best_shift": "best shift (hindsight oracle)",
               "paper": "paper's model", "extended": "extended model"}


def save(fig, path):
    figures.require(os.path.basename(path))
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print("figure:", path)


def grey_torque_off(ax, time, enabled):
    """Shades every stretch of ticks with the torque off (labelled once)."""
    start = None
    label = "torque off"
    for t, on in zip(time + [time[-1]], enabled + [1.0]):
        if on == 0.0 and start is None:
            start = t
        elif on != 0.0 and start is not None:
            ax.axvspan(start, t, color="0.85", lw=0, label=label)
            label = None
            start = None


def log_figure(path):
    c = read_columns(path)
    if not c:
        return
    fig, ax = plt.subplots(figsize=(10, 4))
    t = c.time_s
    grey_torque_off(ax, t, c.torque_enabled)
    ax.plot(t, c.request_deg, color="0.3", lw=1.0, label="request")
    ax.plot(t, c.measured_deg, color="k", lw=2.0, label="measured")
    for key, (color, style) in zip(list(c)[LOG_COLUMNS:], RUNG_STYLES):
        # Not drawn where the torque is off: nothing is predicted there.
        y = [v if on else float("nan") for v, on in zip(c[key], c.torque_enabled)]
        ax.plot(t, y, color=color, ls=style, lw=1.2, label=RUNG_LABELS.get(key.removesuffix("_deg"), key))
    name = os.path.basename(path)[len("log_"):-len(".csv")]
    ax.set_title(f"{name}: open-loop predictions (grey: torque off, not scored)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("angle (deg)")
    ax.legend(fontsize=8, ncol=3, loc="best")
    save(fig, path[:-len(".csv")] + ".png")


def plan_figure(folder):
    c = read_columns(os.path.join(folder, "requests.csv"))
    if not c:
        return
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
    save(fig, os.path.join(folder, "plan.png"))


def main(folders):
    for folder in folders:
        for name in sorted(os.listdir(folder)):
            if name.startswith("log_") and name.endswith(".csv"):
                log_figure(os.path.join(folder, name))
        if os.path.exists(os.path.join(folder, "requests.csv")):
            plan_figure(folder)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
