#!/usr/bin/python3
"""The paper's own numbers, examined on the ERS-210A's geometry (docs/results/paper.md, section
"The paper's own numbers, examined").

Usage: scripts/examine_paper_numbers.py RUN_DIR [RUN_DIR ...]   (folders `track` wrote)

For each run: the forward kinematics written out here from ers210a.md's CMPack vectors and the
URDF's axis signs (independent of leglab's C++), checked against the desired foot path of
foot_direct.csv; per tick the lever of each joint (mm of foot motion per rad, the Jacobian's
column norms) and the smallest singular value; and the foot error per unit of joint error
(foot L2 over the joint errors' combined RMS) of the direct run, against the paper's
(3.23 cm for 31.0 / 29.0 / 20.1 deg); and on every tick how many IK solutions lie inside the
joint limits (Newton from a grid of starts: whether the IK's branch is a choice at all).
"""
import itertools
import math
import sys

import numpy as np

try:
    from leglab.results.reader import ArgumentParser, read_rows
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"examine_paper_numbers.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

SHOULDER = np.array([59.5, 59.2, 0.0])
UPPER = np.array([12.8, 0.5, -64.0])
LOWER = np.array([-18.88, 0.0, -66.0])


def rot(axis, angle):
    c, s = math.cos(angle), math.sin(angle)
    x, y, z = axis
    return np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                     [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                     [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])


def fk(q_rad):
    # URDF: rotator about -y, abductor about +x, knee about +y.
    r1 = rot((0, -1, 0), q_rad[0])
    r2 = rot((1, 0, 0), q_rad[1])
    r3 = rot((0, 1, 0), q_rad[2])
    return SHOULDER + r1 @ r2 @ (UPPER + r3 @ LOWER)


def jacobian(q_rad, h=1e-6):
    cols = []
    for j in range(3):
        dq = np.zeros(3)
        dq[j] = h
        cols.append((fk(q_rad + dq) - fk(q_rad - dq)) / (2 * h))
    return np.array(cols).T


LIMITS_DEG = np.array([[-117, 117], [-11, 89], [-27, 147]])


def ik_solutions(target, inside_limits):
    """Every joint solution for `target` (mm), by Newton from a fixed grid of starts."""
    found = []
    for start in itertools.product(np.radians([-150, -90, -30, 30, 90, 150]),
                                   np.radians([-60, 0, 45, 85, 130]),
                                   np.radians([-60, -20, 40, 100, 140])):
        q = np.array(start, dtype=float)
        for _ in range(60):
            miss = fk(q) - target
            if np.linalg.norm(miss) < 1e-10:
                break
            q = q - np.linalg.lstsq(jacobian(q), miss, rcond=None)[0]
        if np.linalg.norm(fk(q) - target) > 1e-6:
            continue
        q = (q + math.pi) % (2 * math.pi) - math.pi
        if inside_limits and not all(
                math.radians(lo) - 1e-9 <= q[j] <= math.radians(hi) + 1e-9
                for j, (lo, hi) in enumerate(LIMITS_DEG)):
            continue
        if not any(np.linalg.norm(q - f) < 1e-4 for f in found):
            found.append(q)
    return found


def desired_cm(row):
    """A foot_<mode>.csv row's desired foot position (x, y, z), cm."""
    return [float(row.desired_x_cm), float(row.desired_y_cm), float(row.desired_z_cm)]


def actual_cm(row):
    """A foot_<mode>.csv row's actual foot position (x, y, z), cm."""
    return [float(row.actual_x_cm), float(row.actual_y_cm), float(row.actual_z_cm)]


def direct_errors(run, trace=None, foot=None):
    """The direct run's errors over every measured tick of `run` (a folder track wrote):
    joint_rms_deg (per joint), combined_deg (their root sum of squares), foot_cm (the foot's
    RMS distance) and mm_per_rad (foot error per radian of combined joint error)."""
    trace = read_rows(f"{run}/trace_direct.csv") if trace is None else trace
    foot = read_rows(f"{run}/foot_direct.csv") if foot is None else foot
    err = {}
    for r in trace:
        err.setdefault(r.joint, []).append(float(r.actual_deg) - float(r.desired_deg))
    joint_rms = [math.sqrt(np.mean(np.square(err[j]))) for j in ("rotator", "abductor", "knee")]
    foot_err = [math.dist(desired_cm(r), actual_cm(r)) for r in foot]
    foot_rms_cm = math.sqrt(np.mean(np.square(foot_err)))
    combined_deg = math.sqrt(sum(v * v for v in joint_rms))
    return {"joint_rms_deg": joint_rms, "combined_deg": combined_deg, "foot_cm": foot_rms_cm,
            "mm_per_rad": 10 * foot_rms_cm / math.radians(combined_deg)}


def examine(run):
    trace = read_rows(f"{run}/trace_direct.csv")
    foot = read_rows(f"{run}/foot_direct.csv")
    period = 1 + max(int(r.tick) for r in foot if r.step == "0")
    desired = np.zeros((period, 3))
    for r in trace:
        if r.step == "0":
            desired[int(r.tick), ["rotator", "abductor", "knee"].index(r.joint)] = float(
                r.desired_deg)
    worst = 0.0
    levers, smallest = [], []
    for t in range(period):
        q = np.radians(desired[t])
        want = 10 * np.array(desired_cm(foot[t]))
        worst = max(worst, np.linalg.norm(fk(q) - want))
        jac = jacobian(q)
        levers.append(np.linalg.norm(jac, axis=0))
        smallest.append(np.linalg.svd(jac, compute_uv=False)[-1])
    levers = np.array(levers)
    # The IK's branches: how many of the (up to four) solutions lie inside the joint limits.
    branches = {}
    for t in range(period):
        want = 10 * np.array(desired_cm(foot[t]))
        key = (len(ik_solutions(want, True)), len(ik_solutions(want, False)))
        branches[key] = branches.get(key, 0) + 1
    errors = direct_errors(run, trace, foot)
    print(f"{run}: FK check {worst:.1e} mm")
    for j, name in enumerate(("rotator", "abductor", "knee")):
        t_min = int(np.argmin(levers[:, j]))
        print(f"  {name} lever mm/rad: min {levers[t_min, j]:.1f} (tick {t_min}, angles "
              f"{np.round(desired[t_min], 1)}), mean {levers[:, j].mean():.1f}, "
              f"max {levers[:, j].max():.1f}; desired range {desired[:, j].min():.1f}.."
              f"{desired[:, j].max():.1f} deg")
    for (inside, every), ticks in sorted(branches.items()):
        print(f"  IK: {inside} solution(s) inside the limits, of {every}, on {ticks} ticks")
    print(f"  smallest singular value mm/rad: min {min(smallest):.1f} (tick "
          f"{int(np.argmin(smallest))}), mean {np.mean(smallest):.1f}")
    print(f"  direct: joint RMS {np.round(errors['joint_rms_deg'], 2)} deg, combined "
          f"{errors['combined_deg']:.1f} deg; foot RMS {errors['foot_cm']:.2f} cm; foot per joint "
          f"error {errors['mm_per_rad']:.1f} mm/rad")
    return errors["mm_per_rad"]


def main(runs):
    paper_combined = math.sqrt(31.0**2 + 29.0**2 + 20.1**2)
    print(f"paper: combined joint RMS {paper_combined:.1f} deg, foot 3.23 cm: "
          f"{32.3 / math.radians(paper_combined):.1f} mm/rad")
    for run in runs:
        ratio = examine(run)
        need = math.degrees(32.3 / ratio)
        print(f"  at this ratio 3.23 cm needs a combined joint RMS of {need:.1f} deg; the paper's "
              f"{paper_combined:.1f} deg would give {ratio * math.radians(paper_combined) / 10:.2f}"
              " cm")


if __name__ == "__main__":
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", metavar="RUN_DIR", help="folders track wrote")
    main(parser.parse_args().runs)
