"""The blocks of docs/results/*.md beyond Tables 1 and 2 and the real servos' headline: the paper's
walk fitted and examined, C_m, the floor and the modes that go for it, optimal's model and
objective, the untuned walks, move suppression, the sweeps, adaptive and its probes, the
stand's Table 1 and the online servo planner. Each reads a file reproduce.sh writes, most the
runs of scripts/variants.py (RESULTS/variants/<name>/); docs_numbers.blocks() registers them.

A block is (header, rows): functions of a numbers_run.Run, rows raising Missing for a file the
folder lacks. Bold marks, where a table has them, follow the rule its caption in docs/results/*.md
states.
"""
import math
import statistics

import examine_paper_numbers
import variants
from numbers_run import JOINTS, fixed, joint_norm


def table2(run, variant=None):
    """table2.json of the shipped run (RESULTS/) or of a variant."""
    return run.json("table2.json" if variant is None else f"variants/{variant}/table2.json")


def foot(t, mode, norm="L2"):
    return t["foot_cm"][mode][norm]["mean"]


def bold(text, when):
    return f"**{text}**" if when else text


def walk_fit_block(run):
    """The paper's walk's unknowns as fit_walk fitted them, with their ranges."""
    # (key, decimals of the fitted value, the range's reason in short; walk_fit.json gives it
    # whole)
    keys = (("ground_below_shoulder_mm", 2, "the cited 7.7 cm body height taken literally .. "
             "just short of the straight leg's 133.9 mm"),
            ("body_pitch_deg", 2, "level .. the cited front and rear heights (77, 112 mm) at "
             "shoulders 119 mm apart"),
            ("skew", 3, "the cited skew multiplier 0.035, unit and sign not given"),
            ("ground_fraction", 3, "the cited 0.5 (a trot) .. a flight of 18 ticks, three "
             "times the knee's top speed"))

    def rows():
        w = run.json("walk_fit/walk_fit.json")
        fitted, ranges = w["fitted"], w["ranges"]
        offsets = ranges["desired.locus.{forward_mm,outward_mm}"]["choices"]
        forward = fitted["desired.locus.forward_mm"]
        outward = fitted["desired.locus.outward_mm"]
        out = [["which cited offset is forward", f"{forward:g} forward, {outward:g} outward",
                " or ".join(" / ".join(f"{x:g}" for x in c) for c in offsets),
                "the source's x and y (2.8, 4.9 cm) are not named"]]
        for key, digits, why in keys:
            r = ranges[f"desired.locus.{key}"]
            out.append([f"`{key}`", fixed(fitted[f"desired.locus.{key}"], digits),
                        f"{r['min']:g} .. {r['max']:g}", why])
        return out
    return lambda: ["unknown (`desired.locus.*`)", "fitted", "range", "why"], rows


def examined_block(run):
    """The paper's direct row against the shipped and the fitted walk's: how much foot error a
    radian of joint error gives."""
    paper_deg = math.sqrt(31.0**2 + 29.0**2 + 20.1**2)
    paper_cm = 3.23

    def rows():
        out = [["the paper's direct row", fixed(paper_deg, 1), fixed(paper_cm),
                fixed(10 * paper_cm / math.radians(paper_deg), 1), ""]]
        for label, rel in (("shipped walk, direct", ""),
                           ("fitted walk, direct", "track_paper_regime/")):
            e = examine_paper_numbers.direct_errors(f"{run.folder}/{rel}",
                                                    run.rows(rel + "trace_direct.csv"),
                                                    run.rows(rel + "foot_direct.csv"))
            out.append([label, fixed(e["combined_deg"], 1), fixed(e["foot_cm"]),
                        fixed(e["mm_per_rad"], 1),
                        fixed(math.degrees(10 * paper_cm / e["mm_per_rad"]), 1)])
        return out
    return lambda: ["", "combined joint RMS (deg)", "foot L2 (cm)",
                    "foot per joint error (mm/rad)", "3.23 cm would need (deg)"], rows


def cm_block(run):
    """model_based's L2(Pwl,MB) and foot L2 with C_m solved exactly and in closed form."""
    def rows():
        return [[label] + [joint_norm(t, "L2(Pwl,MB)", j) for j in JOINTS] +
                [fixed(foot(t, "model_based"))]
                for label, t in (("exact (default)", table2(run)),
                                 ("closed (eqs. 10-12)", table2(run, "cm_closed")))]
    return lambda: ["C_m", "L2(Pwl,MB) rotator", "abductor", "knee", "foot L2"], rows


def floor_block(run):
    """Each mode's joint L2 and foot L2 and L-infinity on the shipped walk, with the floor, the
    walk model for model_based and ILC's joint objective."""
    rows_of = (("floor", None, "L2(Des,Floor)", "floor", False),
               ("direct", None, "L2(Des,Dir)", "direct", False),
               ("best time shift (k = {k})", None, "L2(Des,TS)", "time_shift", False),
               ("model_based", None, "L2(Des,MB)", "model_based", False),
               ("model_based, `--set controller.model=walk`", "t_step_88_model_based_walk",
                "L2(Des,MB)", "model_based", False),
               ("**optimal** (shipped)", None, "L2(Des,Opt)", "optimal", True),
               ("**ilc** (shipped: `objective: foot`)", None, "L2(Des,ILC)", "ilc", True),
               ("ilc, `--set ilc.objective=joint`", "ilc_joint", "L2(Des,ILC)", "ilc", False))

    def rows():
        out = []
        for label, variant, key, mode, shipped in rows_of:
            t = table2(run, variant)
            k = t["foot_cm"]["time_shift"]["k"] if mode == "time_shift" else None
            out.append([label.format(k=k)] + [joint_norm(t, key, j) for j in JOINTS] +
                       [bold(fixed(foot(t, mode, n)), shipped) for n in ("L2", "Linf")])
        return out
    return lambda: ["", *JOINTS, "foot L2", "foot Linf"], rows


def at_t_step(run, t_step, variant=None):
    """table2.json of track.yaml at `t_step` ticks (the shipped run at 88), or of a variant."""
    if variant is not None:
        return table2(run, f"t_step_{t_step}_{variant}")
    return table2(run, None if t_step == 88 else f"t_step_{t_step}")


def optimal_foot_block(run):
    """Foot L2 (cm) by step time: the time shift, model_based with either model, and optimal
    under each model and objective."""
    def rows():
        out = []
        for t_step in variants.T_STEPS:
            shipped = at_t_step(run, t_step)
            cells = [foot(shipped, "time_shift"), foot(shipped, "model_based"),
                     foot(at_t_step(run, t_step, "model_based_walk"), "model_based")]
            cells += [foot(at_t_step(run, t_step, name), "optimal")
                      for name, _ in variants.OPTIMAL_VARIANTS]
            out.append([str(t_step)] + [fixed(c, 3) for c in cells] +
                       [bold(fixed(foot(shipped, "optimal"), 3), True)])
        return out
    return lambda: ["t_step", "best time shift", "model_based", "model_based, walk model",
                    "optimal, joint, step tests", "optimal, foot, step tests",
                    "optimal, joint, walk model", "**optimal, foot, walk model (shipped)**"], rows


def optimal_joints_block(run):
    """Joint L2 (deg) by step time, model_based and optimal as shipped."""
    def rows():
        out = []
        for t_step in variants.T_STEPS:
            t = at_t_step(run, t_step)
            out.append([str(t_step)] + [" / ".join(fixed(t["joints"][j][key]["mean"], 3)
                                                   for j in JOINTS)
                                        for key in ("L2(Des,MB)", "L2(Des,Opt)")])
        return out
    return lambda: ["t_step", "model_based", "optimal (shipped)"], rows


WAVE_NAMES = {"harmonics": "two harmonics"}


def untuned_block(run):
    """Foot L2 (cm) on the untuned walks, every mode and ILC's joint objective; the best in
    bold."""
    modes = ("direct", "time_shift", "model_based", "optimal", "ilc")

    def rows():
        out = []
        for wave, t_step in variants.UNTUNED:
            name = variants.walk_name(wave, t_step)
            t = table2(run, f"walk_{name}")
            cells = [foot(t, m) for m in modes] + [foot(table2(run, f"walk_{name}_ilc_joint"),
                                                        "ilc")]
            out.append([f"{wave}, T = {t_step}", fixed(foot(t, "floor"), 3)] +
                       [bold(fixed(c, 3), c == min(cells)) for c in cells])
        return out
    return lambda: ["walk", "floor", "direct", "best time shift", "model_based", "optimal",
                    "ilc", "ilc, joint"], rows


def held_out_block(run):
    """Foot L2 (cm) on the held-out walks."""
    modes = ("floor", "time_shift", "model_based", "optimal", "ilc")

    def rows():
        out = []
        for wave, t_step in variants.HELD_OUT:
            t = table2(run, f"walk_{variants.walk_name(wave, t_step)}")
            out.append([f"{WAVE_NAMES.get(wave, wave)}, {t_step}"] +
                       [fixed(foot(t, m), 3) for m in modes])
        return out
    return lambda: ["walk", "floor", "best time shift", "model_based", "optimal", "ilc"], rows


def trace_stats(run, variant):
    """Over the measured steps of optimal's trace, per joint: the requests' sum of squared
    second differences (cyclic within a step) per step, deg^2; the model's RMS from desired and
    the plant's from the model, deg."""
    rows = run.rows(f"variants/{variant}/trace_optimal.csv")
    out = {}
    for joint in JOINTS:
        steps = {}
        for r in rows:
            if r.joint == joint:
                steps.setdefault(r.step, []).append(r)
        squares = []
        for step in steps.values():
            q = [float(r.request_deg) for r in step]
            squares.append(sum((q[(i + 1) % len(q)] - 2 * q[i] + q[i - 1])**2
                               for i in range(len(q))))
        every = [r for step in steps.values() for r in step]

        def rms(difference):
            return math.sqrt(statistics.fmean(difference(r)**2 for r in every))
        out[joint] = (statistics.fmean(squares),
                      rms(lambda r: float(r.model_deg) - float(r.desired_deg)),
                      rms(lambda r: float(r.actual_deg) - float(r.model_deg)))
    return out


def smoothing_block(run):
    """Optimal on the slow triangle with and without move suppression."""
    variants_of = ("walk_triangle_88", "walk_triangle_88_no_smoothing")

    def rows():
        shipped = table2(run, variants_of[0])
        best = min(foot(table2(run, v), "optimal") for v in variants_of)
        stats = [trace_stats(run, v) for v in variants_of]

        def joints(s, i, style):
            return " / ".join(style(s[j][i]) for j in JOINTS)

        def squares(x):  # one decimal below 100 deg^2, whole deg^2 above
            return f"{x:.1f}" if x < 100 else f"{x:.0f}"
        return [[f"foot L2 (cm; best time shift {fixed(foot(shipped, 'time_shift'), 3)})"] +
                [bold(fixed(foot(table2(run, v), "optimal"), 3),
                      foot(table2(run, v), "optimal") == best) for v in variants_of],
                ["requests' sum of squared second differences per step (deg^2), rotator / "
                 "abductor / knee"] + [joints(s, 0, squares) for s in stats],
                ["model's prediction against desired (deg RMS)"] +
                [joints(s, 1, fixed) for s in stats],
                ["plant against the model's prediction (deg RMS)"] +
                [joints(s, 2, fixed) for s in stats]]
    return lambda: ["optimal on the slow triangle", "shipped (`request_smoothing: 0.3`)",
                    "`request_smoothing=0`"], rows


def ratio_text(x):
    return f"{x:.2f}" if x < 10 else f"{x:.1f}"


def firmware_block(run):
    """The servo_firmware sweep: each mode's foot L2 over the time shift's and over
    model-based's at every servo, and how often each mode is best."""
    modes = (("direct", "direct"), ("time_shift", "best time shift"),
             ("model_based", "model_based"), ("optimal", "optimal"), ("ilc", "ilc"),
             ("floor", "floor"))
    policies = [m for m, _ in modes if m != "floor"]

    def rows():
        points = [{m: float(r[f"{m}_foot_l2_cm"]) for m, _ in modes}
                  for r in run.rows("sweeps/servo_firmware/sweep.csv")]
        best = [min(policies, key=p.get) for p in points]
        out = []
        for mode, label in modes:
            row = [label]
            for yardstick in ("time_shift", "model_based"):
                if mode == yardstick:
                    row += ["1", "1", "-"]
                    continue
                ratios = [p[mode] / p[yardstick] for p in points]
                row += [ratio_text(statistics.median(ratios)), ratio_text(max(ratios)),
                        str(sum(r < 1 for r in ratios))]
            row.append(str(best.count(mode)) if mode in policies else "")
            out.append(row)
        return out
    return lambda: ["mode", "median / time shift", "worst / time shift", "beats the time shift",
                    "median / model-based", "worst / model-based", "beats model-based",
                    "best of the five"], rows


def stand_load_block(run):
    """The stand_load sweep on the sled and on a rigid rail: foot and rotator L2 by load."""
    rows_of = (("sled (shipped): model_based foot L2", "sweeps/stand_load", "model_based_foot_l2_cm", 3),
               ("sled: model_based rotator L2", "sweeps/stand_load", "model_based_rotator_l2_deg", 2),
               ("rigid rail: model_based foot L2", "variants/stand_load_rigid",
                "model_based_foot_l2_cm", 3),
               ("rigid rail: model_based rotator L2", "variants/stand_load_rigid",
                "model_based_rotator_l2_deg", 2),
               ("rigid rail: direct foot L2", "variants/stand_load_rigid", "direct_foot_l2_cm", 3))

    def header():
        return ["load (kg)"] + [r["stand.load_kg"]
                                for r in run.rows("sweeps/stand_load/sweep.csv")]

    def rows():
        return [[label] + [fixed(r[column], digits) for r in run.rows(f"{folder}/sweep.csv")]
                for label, folder, column, digits in rows_of]
    return header, rows


def mean_foot(run, folder, mode, first, last):
    """The mean of per_step.csv's foot_l2_cm for `mode` over steps first..last."""
    values = [float(r.foot_l2_cm) for r in run.rows(f"{folder}/per_step.csv")
              if r.mode == mode and first <= int(r.step) <= last]
    return statistics.fmean(values)


# The adaptive runs' measured windows: (folder, first step, last step, the folder whose
# model_based holds the right model). Cold start: steps 10-19; wear: before and after the
# change at step 20.
COLD = ("adapt_cold_start", 10, 19, "adapt_cold_start")
BEFORE = ("adapt_wear", 0, 19, "adapt_wear")
AFTER = ("adapt_wear", 30, 39, "adapt_wear/worn_model")


def near_right_model(run, value, window):
    """The adaptive tables' bold rule: within 10 % of model_based with the right model."""
    folder, first, last, right = window
    return value <= 1.1 * mean_foot(run, right, "model_based", first, last)


def adaptive_block(run):
    """Foot L2 (cm) of adaptive and its yardsticks over the cold start's and the wear's
    windows."""
    def rows():
        config = run.yaml("adapt_cold_start/track_config.yaml")
        start = config["adaptive"]["initial_model"]
        out = []
        for label, window, columns in (
                (f"cold start, steps {COLD[1]}-{COLD[2]} (from v_max "
                 f"{start['v_max_deg_per_tick']:g}, theta_0 {start['theta0_deg']:g}, l "
                 f"{start['lag_ticks']}, a {start['accel_ticks']}"
                 f"{', no warm-up' if config['warmup_steps'] == 0 else ''})", COLD, ()),
                (f"wear, steps {BEFORE[1]}-{BEFORE[2]}, before the change", BEFORE,
                 ("time_shift", "direct")),
                (f"wear, steps {AFTER[1]}-{AFTER[2]}, after the change", AFTER,
                 ("time_shift", "direct"))):
            folder, first, last, _ = window
            adaptive = mean_foot(run, folder, "adaptive", first, last)
            worn = (fixed(mean_foot(run, AFTER[3], "model_based", first, last), 3)
                    if window is AFTER else "")
            cells = [bold(fixed(adaptive, 3), near_right_model(run, adaptive, window)),
                     fixed(mean_foot(run, folder, "model_based", first, last), 3), worn]
            cells += [fixed(mean_foot(run, folder, m, first, last), 3) for m in columns]
            out.append([label] + cells + [""] * (5 - len(cells)))
        return out
    return lambda: ["foot L2 (cm), mean over the steps", "adaptive",
                    "model_based, identified model", "model_based, changed plant's model",
                    "time shift", "direct"], rows


def plant_at(rows, step):
    """plant_models.csv's rows of the plant in force at `step` (the last change at or before
    it), by joint."""
    start = max(int(r.from_step) for r in rows if int(r.from_step) <= step)
    return {r.joint: r for r in rows if int(r.from_step) == start}


def estimates_text(run, folder, step):
    """adaptive's model after `step` against identify's on the plant then, per joint:
    "l/a dv_max dtheta_0", joints joined by "; "."""
    def signed(x):
        text = f"{x:+.2f}"
        return text[1:] if text in ("+0.00", "-0.00") else text
    plant = plant_at(run.rows(f"{folder}/plant_models.csv"), step)
    estimates = {r.joint: r for r in run.rows(f"{folder}/model_estimates.csv")
                 if int(r.step) == step}
    return "; ".join(
        f"{e.lag_ticks}/{e.accel_ticks} "
        f"{signed(float(e.v_max_deg_per_tick) - float(plant[j].v_max_deg_per_tick))} "
        f"{signed(float(e.theta0_deg) - float(plant[j].theta0_deg))}"
        for j, e in ((j, estimates[j]) for j in JOINTS))


def probes_block(run):
    """adaptive's estimates and foot L2 with each probe, from a wrong model and through the
    wear."""
    def rows():
        out = []
        for name, deg, ticks in (("", 0, 0),) + variants.PROBES:
            label = ("none (shipped)" if not name else
                     f"pulse {deg} deg" if ticks == 0 else f"excursion {deg} deg, {ticks} ticks")
            row = [label]
            for window, step in ((COLD, 10), (AFTER, 30)):
                folder = window[0] if not name else f"variants/{window[0]}_{name}"
                value = mean_foot(run, folder, "adaptive", window[1], window[2])
                row += [estimates_text(run, folder, step),
                        bold(fixed(value, 3), near_right_model(run, value, window))]
            out.append(row)
        return out
    return lambda: ["probe", "cold, step 10: l/a, dv_max, dtheta_0 (rotator; abductor; knee)",
                    "cold foot, steps 10-19", "wear, step 30: the same",
                    "wear foot, steps 30-39"], rows


def stand_table1_block(run):
    """Table 1 identified on the stand with the foot free and in the air, knee held at 70."""
    def rows():
        out = []
        for label, rel in (("air: v_max / theta_0 / l / a, fit RMS", "stand/air70/table1.json"),
                           ("stand: the same", "stand/table1.json")):
            joints = run.json(rel)["joints"]
            out.append([label] + [
                f"{fixed(m.v_max_deg_per_tick)} / {fixed(m.theta0_deg)} / {m.lag_ticks} / "
                f"{m.accel_ticks}, {fixed(m.fit_rms_deg, 3)}" for m in (joints[j] for j in JOINTS)])
        return out
    return lambda: ["", *JOINTS], rows


def online_block(run):
    """The servo planner's predicted error (deg) by plan and preview, on the XL330's logs: the
    mean absolute error and, in brackets, the root mean square (the optimal plans' objective)."""
    rel = "servo_logs/online/preview.json"
    rms_rel = "servo_logs/online/preview_rms.json"

    def header():
        return ["plan (xl330, kp 400), MAE (RMS)", *next(iter(run.json(rel).values()))]

    def rows():
        rms = run.json(rms_rel)
        return [[plan] + [f"{fixed(v)} ({fixed(rms[plan][log])})" for log, v in by_log.items()]
                for plan, by_log in run.json(rel).items()]
    return header, rows


BUS_RUNS = (("direct", "direct"), ("best_lead", "best lead (hindsight)"),
            ("paper_model_based_online", "paper's model, online"),
            ("model_based", "model_based"), ("model_based_online", "model_based, online"),
            ("optimal", "optimal"), ("optimal_online", "optimal, online"))
BUS_BENCHES = (("dynamixel", "XL330-M288, kp 400, 0.49 kg at 0.10 m"),
               ("feetech", "STS3215, kp 32, 0.50 kg at 0.12 m"))


def bus_block(run):
    """The emulated servos' measured error (deg) on the pick-and-place run, by method
    (scripts/bus_loop.py's run.json files)."""
    def rows():
        out = []
        for protocol, bench in BUS_BENCHES:
            summaries = [run.json(f"bus/{protocol}/{folder}/run.json") for folder, _ in BUS_RUNS]
            cells = [fixed(s.mae_deg) for s in summaries]
            cells[1] += f" (lead {summaries[1].lead_ticks})"
            out.append([f"{bench} ({protocol})", *cells])
        return out
    return lambda: ["servo (emulated)", *(label for _, label in BUS_RUNS)], rows


def blocks(run):
    """This module's blocks by id."""
    return {
        "walk-fit": walk_fit_block(run),
        "paper-examined": examined_block(run),
        "cm": cm_block(run),
        "floor-modes": floor_block(run),
        "optimal-foot": optimal_foot_block(run),
        "optimal-joints": optimal_joints_block(run),
        "untuned": untuned_block(run),
        "held-out": held_out_block(run),
        "smoothing": smoothing_block(run),
        "servo-firmware": firmware_block(run),
        "stand-load": stand_load_block(run),
        "adaptive": adaptive_block(run),
        "probes": probes_block(run),
        "stand-table1": stand_table1_block(run),
        "online": online_block(run),
        "bus-loop": bus_block(run),
    }
