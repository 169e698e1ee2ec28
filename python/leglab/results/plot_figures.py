"""Draws the paper's figures 1-8 (and the time-shift search, the ILC learning curve, every
mode's foot path, the adaptive mode's estimates and every mode's foot error per step) from the
CSVs in a results folder.

Usage: python3 -m leglab.results.plot_figures RESULTS_DIR
Reads what identify and track wrote; writes fig<N>_<name>.png beside them.
"""
from __future__ import annotations

import os
from typing import Any, Callable, Sequence

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


from . import figures  # noqa: E402
from .reader import (ArgumentParser, declared_columns, read_json, read_rows,  # noqa: E402
                      select)

__all__ = ["main"]

# matplotlib has no types on Debian 12: a figure is Any.
_Figure = Any
# Whether the run's folder holds a file, by its name.
_Have = Callable[[str], bool]


def square_wave_period(request: Sequence[float]) -> int:
    """The ticks of a square wave's first period: up to where it returns to its first level
    after its first change (all of it if it never does)."""
    changed = next((t for t, r in enumerate(request) if r != request[0]), len(request))
    return next((t for t in range(changed, len(request)) if request[t] == request[0]),
                len(request))


def save(fig: _Figure, out: str, name: str) -> None:
    figures.require(name)
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print("figure:", path)


def foot_paths(out: str, mode: str) -> tuple[list[float], list[float], list[float],
                                               list[float]]:
    first = select(read_rows(os.path.join(out, f"foot_{mode}.csv")), step=0)
    return first.desired_x_cm, first.desired_z_cm, first.actual_x_cm, first.actual_z_cm


def closed(values: list[float]) -> list[float]:
    return values + values[:1]


def foot_figure(out: str, name: str, title: str,
                modes: Sequence[tuple[str, str, str]]) -> None:
    """The desired foot path and the actual one of each (mode, label, style), in x-z."""
    fig, ax = plt.subplots(figsize=(6, 4))
    dx, dz, _, _ = foot_paths(out, modes[0][0])
    ax.plot(closed(dx), closed(dz), "k-", label="desired")
    for mode, label, style in modes:
        _, _, x, z = foot_paths(out, mode)
        ax.plot(closed(x), closed(z), style, label=label)
    ax.set(xlabel="x, forward (cm)", ylabel="z, up (cm)", title=title)
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8)
    save(fig, out, name)


# The paper's and leglab's modes keep their colours from figure to figure; any other mode (one
# a user registers) gets the next of the rest.
MODE_STYLES = {"direct": "r--", "time_shift": "g-.", "model_based": "b-", "optimal": "m-",
               "ilc": "c-", "adaptive": "C1-"}
OTHER_STYLES = ["C5-", "C7-", "C8-", "C9-", "y-", "C4-"]


def mode_style(mode: str) -> str:
    if mode not in MODE_STYLES:
        MODE_STYLES[mode] = OTHER_STYLES[(len(MODE_STYLES) - 6) % len(OTHER_STYLES)]
    return MODE_STYLES[mode]


def mode_color(mode: str) -> str:
    return mode_style(mode).rstrip("-.:")


def modes_present(out: str) -> list[str]:
    """Every mode with a foot_<mode>.csv in `out`, in table2.json's order when it has one."""
    present = sorted(f[len("foot_"):-len(".csv")] for f in os.listdir(out)
                     if f.startswith("foot_") and f.endswith(".csv"))
    try:
        order = [m for m in read_json(os.path.join(out, "table2.json"))["foot_cm"] if m in present]
    except (OSError, KeyError, ValueError):
        order = []
    return order + [m for m in present if m not in order]


def draw_direct(out: str, have: _Have) -> None:
    """Figures 1 and 2: the direct method's foot path and rotator angles."""
    # Figure 1: desired and actual foot path under the direct method (x forward, z up).
    if have("foot_direct.csv"):
        foot_figure(out, "fig1_foot_direct.png", "Fig. 1: foot trajectory",
                    [("direct", "actual (direct)", "r--")])

    # Figure 2: requests (= desired) and actual angles of the rotator under the direct method.
    if have("trace_direct.csv"):
        rotator = select(read_rows(os.path.join(out, "trace_direct.csv")), step=0, joint="rotator")
        req, act = rotator.request_deg, rotator.actual_deg
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(req, "k-", label="requested (= desired)")
        ax.plot(act, "r--", label="actual")
        ax.set(xlabel="tick (8 ms)", ylabel="rotator angle (deg)",
               title="Fig. 2: direct requests vs actual, rotator")
        ax.legend()
        save(fig, out, "fig2_rotator_direct.png")


def draw_step_tests(out: str, have: _Have) -> None:
    """Figures 3 and 4: the step tests with the identified model's prediction."""
    # Figures 3 and 4: the paper's two step tests (40 and 110 deg; a run with other
    # identify.theta_test_deg has no such files) with the identified model's prediction, over
    # the square wave's first period.
    for number, theta in ((3, 40), (4, 110)):
        name = f"step_rotator_{theta}.csv"
        if not have(name):
            continue
        test = select(read_rows(os.path.join(out, name)))
        period = square_wave_period(test.request_deg)
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(test.request_deg[:period], "k-", label="requested")
        ax.plot(test.actual_deg[:period], "r.", ms=4, label="actual")
        ax.plot(test.model_deg[:period], "b-", lw=1, label="model")
        ax.set(xlabel="tick (8 ms)", ylabel="rotator angle (deg)",
               title=f"Fig. {number}: step test, theta_test = {theta} deg")
        ax.legend()
        save(fig, out, f"fig{number}_step_rotator_{theta}.png")


def draw_f(out: str, have: _Have) -> None:
    """Figure 5: the function f of eq. 2."""
    # Figure 5: the function f of eq. 2 with the rotator's identified parameters.
    if have("table1.json"):
        p = read_json(os.path.join(out, "table1.json"))["joints"]["rotator"]
        v, t0 = p.v_max_deg_per_tick, p.theta0_deg
        xs = [-3 * t0, -t0, t0, 3 * t0]
        ys = [-v, -v, v, v]
        fig, ax = plt.subplots(figsize=(5, 4))
        ax.plot(xs, ys, "k-")
        ax.axhline(0, color="0.8", lw=0.5)
        ax.axvline(0, color="0.8", lw=0.5)
        ax.set(xlabel="requested - actual (deg)", ylabel="f (deg per tick)",
               title=f"Fig. 5: f, v_max = {v:.2f}, theta_0 = {t0:.2f}")
        save(fig, out, "fig5_f.png")


def draw_model_based(out: str, have: _Have) -> None:
    """Figures 6, 7 and 8: the model-based method's approximation, requests and foot path."""
    if have("trace_model_based.csv"):
        rotator = select(read_rows(os.path.join(out, "trace_model_based.csv")), step=0,
                         joint="rotator")
        # Figure 6: the piecewise-linear approximation of the rotator's desired angles.
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(rotator.desired_deg, "k-", label="desired")
        ax.plot(rotator.pwl_deg, "g-", label="piecewise linear")
        ax.set(xlabel="tick (8 ms)", ylabel="rotator angle (deg)",
               title="Fig. 6: piecewise-linear approximation")
        ax.legend()
        save(fig, out, "fig6_pwl_rotator.png")
        # Figure 7: desired, approximation, requests and actual under the model-based method.
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(rotator.desired_deg, "k-", label="desired")
        ax.plot(rotator.pwl_deg, "g-", label="piecewise linear")
        ax.plot(rotator.request_deg, "b:", label="requested")
        ax.plot(rotator.actual_deg, "r--", label="actual")
        ax.set(xlabel="tick (8 ms)", ylabel="rotator angle (deg)",
               title="Fig. 7: model-based requests, rotator")
        ax.legend()
        save(fig, out, "fig7_model_based_rotator.png")

    # Figure 8: desired foot path, direct (old) and model-based (new).
    if have("foot_direct.csv") and have("foot_model_based.csv"):
        foot_figure(out, "fig8_foot_old_new.png", "Fig. 8: foot trajectories",
                    [("direct", "old (direct)", "r--"), ("model_based", "new (model-based)", "b-")])


def draw_shift_search(out: str, have: _Have) -> None:
    """Figure 9: the time-shift baseline's search."""
    # The time-shift search behind the best k.
    if have("shift_search.csv"):
        search = select(read_rows(os.path.join(out, "shift_search.csv")))
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(search.k, search.foot_l2_cm, "k.-")
        ax.set(xlabel="time shift k (ticks)", ylabel="foot L2 (cm)",
               title="Time-shift baseline: foot error for every k")
        save(fig, out, "fig9_shift_search.png")


def draw_ilc_learning(out: str, have: _Have) -> None:
    """Figure 10: the ILC learning curve against the floor."""
    # Figure 10: the ILC learning curve (every step, warm-up negative) against the floor.
    if have("ilc_learning.csv") and have("table2.json"):
        rows = read_rows(os.path.join(out, "ilc_learning.csv"))
        table = read_json(os.path.join(out, "table2.json"))
        fig, (joints_ax, foot_ax) = plt.subplots(1, 2, figsize=(10, 4))
        for joint, colour in (("rotator", "C0"), ("abductor", "C1"), ("knee", "C2")):
            learned = select(rows, joint=joint)
            joints_ax.plot(learned.step, learned.l2_deg, "o-", color=colour, ms=3, label=joint)
            floor = table["joints"][joint]["L2(Des,Floor)"]["mean"]
            joints_ax.axhline(floor, color=colour, ls=":", lw=1)
        joints_ax.axvline(-0.5, color="0.6", lw=0.8)
        joints_ax.set(xlabel="step (warm-up < 0)", ylabel="L2 to desired (deg)",
                      title="ILC learning, joints (dotted: floor)")
        joints_ax.legend()
        learned = select(rows, joint="rotator")
        foot_ax.plot(learned.step, learned.foot_l2_cm, "ko-", ms=3, label="ilc")
        foot = table["foot_cm"]
        for mode, style in (("floor", "k:"), ("model_based", "b--"), ("time_shift", "g--")):
            if mode in foot:
                # The floor row is the joints' floors put together: a bound for policies that
                # track each joint on its own, not for ILC's foot objective.
                label = "floor (the joints' floors)" if mode == "floor" else mode
                foot_ax.axhline(foot[mode]["L2"]["mean"], ls=style[1:], color=style[0],
                                lw=1, label=label)
        foot_ax.axvline(-0.5, color="0.6", lw=0.8)
        foot_ax.set(xlabel="step (warm-up < 0)", ylabel="foot L2 (cm)",
                    title="ILC learning, foot")
        foot_ax.legend()
        save(fig, out, "fig10_ilc_learning.png")


def draw_every_mode(out: str) -> None:
    """Figure 11: every mode's foot path."""
    # Figure 11: the foot path of every mode that ran (its foot_<mode>.csv), in table 2's order.
    modes = [(m, m, mode_style(m)) for m in modes_present(out)]
    if len(modes) > 1:
        foot_figure(out, "fig11_foot_every_mode.png", "Foot trajectories, every mode", modes)


def draw_estimates(out: str, have: _Have) -> list[int]:
    """Figure 12: the adaptive mode's estimates; returns the steps where the plant changed."""
    # Figures 12, 13 (adaptive mode): its estimates every step against what identify finds on
    # the plant before and after each change; every mode's foot error per step.
    changes: list[int] = []
    if have("model_estimates.csv") and have("plant_models.csv"):
        path = os.path.join(out, "model_estimates.csv")
        rows = read_rows(path)
        plant = read_rows(os.path.join(out, "plant_models.csv"))
        starts = sorted({int(s) for s in select(plant).from_step})
        changes = starts[1:]
        last = max(select(rows).step)
        fig, axes = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
        # The model's four values, in the declared order after step and joint.
        params = zip(declared_columns(path)[2:6],
                     ("v_max (deg/tick)", "theta_0 (deg)", "l (ticks)", "a (ticks)"))
        for ax, (key, label) in zip(axes.flat, params):
            for joint, colour in (("rotator", "C0"), ("abductor", "C1"), ("knee", "C2")):
                estimates = select(rows, joint=joint)
                ax.plot(estimates.step, estimates[key], "o-", color=colour, ms=2.5, lw=1,
                        label=joint)
                for k, start in enumerate(starts):
                    end = starts[k + 1] if k + 1 < len(starts) else last
                    value = select(plant, joint=joint, from_step=start)[key][0]
                    ax.hlines(value, start, end, color=colour, ls="--", lw=1.2)
            for step in changes:
                ax.axvline(step - 0.5, color="0.5", lw=0.8)
            ax.set(ylabel=label)
        for ax in axes[1]:
            ax.set(xlabel="step (warm-up < 0)")
        axes[0][0].legend(fontsize=8)
        fig.suptitle("adaptive: estimates per step (dashed: identify on the plant as it is)")
        save(fig, out, "fig12_model_estimates.png")
    return changes


def draw_foot_per_step(out: str, have: _Have, changes: Sequence[int]) -> None:
    """Figure 13: every mode's foot error per step, the plant's `changes` marked."""
    if have("per_step.csv") and have("model_estimates.csv"):
        rows = read_rows(os.path.join(out, "per_step.csv"))
        fig, ax = plt.subplots(figsize=(8, 4))
        for mode in dict.fromkeys(select(rows).mode):
            per_step = select(rows, mode=mode)
            ax.plot(per_step.step, per_step.foot_l2_cm, "o-", color=mode_color(mode), ms=2.5,
                    lw=1, label=mode)
        # model_based with a model identified on the changed plant, when reproduce.sh ran it.
        worn = os.path.join(out, "worn_model", "per_step.csv")
        if os.path.exists(worn):
            per_step = select(read_rows(worn), mode="model_based")
            ax.plot(per_step.step, per_step.foot_l2_cm, "--", color="b", lw=1,
                    label="model_based, model of the changed plant")
        for step in changes:
            ax.axvline(step - 0.5, color="0.5", lw=0.8)
        ax.set(xlabel="step (warm-up < 0; grey: plant change)", ylabel="foot L2 (cm)",
               title="Foot error per step, every mode")
        ax.set_yscale("log")
        ax.legend(fontsize=8)
        save(fig, out, "fig13_foot_per_step.png")


def draw_stand(out: str, have: _Have) -> None:
    """Figures 14, 15 and 16: the test stand's force, carriage and foot path."""
    # Figures 14-16 (the single-leg test stand): drawn when the foot CSVs carry the
    # stand's instruments (a run on robots/ers210a_stand; zeros in the air).
    stand_modes = [(m, label, st) for m, label, st in
                   (("direct", "direct", "r--"), ("model_based", "model_based", "b-"))
                   if have(f"foot_{m}.csv")]
    on_stand = False
    for mode, _, _ in stand_modes:
        foot = select(read_rows(os.path.join(out, f"foot_{mode}.csv")))
        on_stand = on_stand or any(f != 0 for f in foot.contact_fz_n)
    if on_stand:
        weight = None
        if have("table2.json"):
            stand = read_json(os.path.join(out, "table2.json")).get("stand")
            weight = stand.carried_weight_n if stand else None
        # Figure 14: the floor's force on the foot over one step (step 0), each mode.
        fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
        for mode, label, style in stand_modes:
            first = select(read_rows(os.path.join(out, f"foot_{mode}.csv")), step=0)
            axes[0].plot(first.tick, first.contact_fz_n, style, label=label)
            axes[1].plot(first.tick, first.contact_fx_n, style, label=f"{label}, x")
            axes[1].plot(first.tick, first.contact_fy_n, style, lw=0.8, alpha=0.5,
                         label=f"{label}, y")
        if weight:
            axes[0].axhline(weight, color="0.4", ls=":", label="carried weight")
        axes[0].set(ylabel="normal Fz (N)",
                    title="Ground reaction force over a step (stand, step 0)")
        axes[1].set(xlabel="tick (8 ms)", ylabel="tangential (N)")
        axes[0].legend(fontsize=8)
        axes[1].legend(fontsize=7, ncol=2)
        save(fig, out, "fig14_stand_ground_force.png")
        # Figure 15: the carriage height over the same step.
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for mode, label, style in stand_modes:
            first = select(read_rows(os.path.join(out, f"foot_{mode}.csv")), step=0)
            ax.plot(first.tick, first.carriage_z_mm, style, label=label)
        ax.set(xlabel="tick (8 ms)", ylabel="carriage height (mm)",
               title="Carriage height above the walking height (stand, step 0)")
        ax.legend(fontsize=8)
        save(fig, out, "fig15_stand_carriage.png")
        # Figure 16: the foot path on the stand against the desired one.
        foot_figure(out, "fig16_stand_foot.png", "Foot trajectory on the stand",
                    [(m, f"actual ({label})", st) for m, label, st in stand_modes])


def main(out: str) -> None:
    """Draws every figure whose inputs are in a run's folder (``python3 -m
    leglab.results.plot_figures RESULTS_DIR``).

    Parameters
    ----------
    out : str
        A folder identify and/or track wrote; the figures (fig*.png) are written into it.

    Raises
    ------
    ValueError
        When a figure has no caption in figures.py (a bug).
    """
    have: _Have = lambda name: os.path.exists(os.path.join(out, name))  # noqa: E731
    draw_direct(out, have)
    draw_step_tests(out, have)
    draw_f(out, have)
    draw_model_based(out, have)
    draw_shift_search(out, have)
    draw_ilc_learning(out, have)
    draw_every_mode(out)
    draw_foot_per_step(out, have, draw_estimates(out, have))
    draw_stand(out, have)


if __name__ == "__main__":
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results_dir", metavar="RESULTS_DIR")
    main(parser.parse_args().results_dir)
