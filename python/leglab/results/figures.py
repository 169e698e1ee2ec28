"""Every figure the plotting modules draw, by file name, with its caption saying what to look at:
registered once, here. report.py shows the captions; plot_figures.py and plot_logs.py refuse to
write a figure that has none (a bug: exit 1). plot_sweep.py's figure is sweep.png unless its
--out names another.
"""
from __future__ import annotations

__all__ = ["CAPTIONS", "LOG_CAPTION", "caption", "require"]

CAPTIONS = {
    "fig1_foot_direct.png":
        "Fig. 1: the desired foot path and the foot under direct requests (x forward, z up): "
        "the actual loop lags the desired one and cuts its corners.",
    "fig2_rotator_direct.png":
        "Fig. 2: the rotator's requests (= desired) and its actual angle under direct requests "
        "over one step: look at the lag and the flattened peaks.",
    "fig3_step_rotator_40.png":
        "Fig. 3: the rotator's 40 deg step test with the identified model's prediction: the "
        "model (blue) should lie on the measured points (red).",
    "fig4_step_rotator_110.png":
        "Fig. 4: the rotator's 110 deg step test with the identified model's prediction: the "
        "long ramp is the top speed v_max; the model (blue) should lie on the points (red).",
    "fig5_f.png":
        "Fig. 5: f of eq. 2 with the rotator's identified parameters: speed grows with the gap "
        "between request and angle up to theta_0, and is capped at v_max beyond it.",
    "fig6_pwl_rotator.png":
        "Fig. 6: the rotator's desired angle and its piecewise-linear approximation: the green "
        "line should follow the black one closely.",
    "fig7_model_based_rotator.png":
        "Fig. 7: model-based requests (dotted) run ahead of the desired angle; the actual angle "
        "(red) should follow the piecewise-linear target (green).",
    "fig8_foot_old_new.png":
        "Fig. 8: the foot under direct (old) and model-based (new) requests: the new path "
        "should hug the desired loop far more closely than the old one.",
    "fig9_shift_search.png":
        "The time-shift baseline: the foot's L2 error for every shift k; the minimum is the k "
        "that Table 2's time_shift row uses.",
    "fig10_ilc_learning.png":
        "ILC learning: joint and foot error per step (warm-up steps negative) against the "
        "floor (dotted): the error should fall during warm-up and stay flat after.",
    "fig11_foot_every_mode.png":
        "The foot path of every mode that ran, against the desired loop: which modes leave it, "
        "and where.",
    "fig12_model_estimates.png":
        "The adaptive mode's estimates of v_max, theta_0, l and a per step against what "
        "identify finds on the plant (dashed): they should settle on the dashed lines, also "
        "after a plant change (grey).",
    "fig13_foot_per_step.png":
        "Every mode's foot error per step (log scale; grey: a plant change): how far each "
        "mode falls at a change and how fast the adaptive one recovers.",
    "fig14_stand_ground_force.png":
        "On the stand, the floor's force on the foot over step 0: in stance the normal force "
        "should carry the carried weight (dotted); the tangential forces show slip.",
    "fig15_stand_carriage.png":
        "On the stand, the carriage's height over step 0: how far the body rises and sinks "
        "as the leg walks under each mode.",
    "fig16_stand_foot.png":
        "On the stand, the foot path against the desired one: the floor flattens the bottom "
        "of the loop.",
    "sweep.png":
        "The sweep: each mode's foot error across the swept values (or, for two or more keys, "
        "ratios: below 1, the mode beats the baseline there).",
    "plan.png":
        "Planned requests for a real servo: the predicted angle (green) should lie on the "
        "desired motion (black); red ticks mark where the motion is beyond the servo.",
}
LOG_CAPTION = ("A servo log: the request, the measured angle (black) and each model's "
               "open-loop prediction (held out where identify cross-validated; grey: torque "
               "off, not scored): the nearer a line to the black one, the better the model.")

# What each sub-run folder of reproduce.sh's results/ holds (by its path below the top).


def caption(name: str) -> str | None:
    """A figure's caption.

    Parameters
    ----------
    name : str
        The figure's file name (``fig1_foot_direct.png``, ``log_<motor>_<name>.png``).

    Returns
    -------
    str or None
        The caption saying what to look at, or None when the figure has none.
    """
    if name in CAPTIONS:
        return CAPTIONS[name]
    if name.startswith("log_") and name.endswith(".png"):
        return LOG_CAPTION
    return None


def require(name: str) -> None:
    """Checks that a figure has a caption, before it is drawn.

    Parameters
    ----------
    name : str
        The figure's file name.

    Raises
    ------
    ValueError
        When it has none (a bug of the module drawing it: add the caption to CAPTIONS).
    """
    if caption(name) is None:
        raise ValueError(f"figure {name} has no caption in leglab/results/figures.py: add one "
                         "there")
