#!/usr/bin/python3
"""The runs docs/results/*.md's tables quote besides reproduce.sh's own: each a program on a
shipped config with `--set` overrides (the command the results page gives for it), written to
RESULTS/variants/<name>/, where scripts/docs_numbers.py reads them.

Usage: /usr/bin/python3 scripts/variants.py RESULTS [--bin DIR] [--only NAME ...] [--list]

The variants are declared once, in variants() below: the closed-form C_m, the walk-fitted model
for model_based, ILC's joint objective, optimal's model and objective at four step times, the
untuned and held-out walks (their desired.csv files written to RESULTS/variants/inputs/ first,
from the waves of untuned_walks()), optimal without move suppression on the slow triangle,
adaptive's probes, and the stand-load sweep on a rigid rail. Runs go two at a time (one per
core); each run's files are the same whatever the order. --only: just these variants (and the
walks they need). --list: each variant's command, one a line, and nothing run.

Bad input (an unknown --only name, no program in --bin): one line on stderr, exit status 2.
A program that fails: its command and its last line of stderr, exit status 1.
"""
import concurrent.futures
import math
import os
import pathlib
import shlex
import subprocess
import sys

import yaml

try:
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"variants.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

SOURCE_DIR = pathlib.Path(__file__).resolve().parent.parent
CONFIGS = pathlib.Path("experiments") / "configs"
SWEEPS = pathlib.Path("experiments") / "sweeps"

# Optimal's model and objective, each column of docs/results/beyond.md's table at each step time:
# (name, overrides). The shipped pair (foot objective, walk model) is the step time's own run.
OPTIMAL_VARIANTS = (
    ("optimal_joint_step_tests", ["optimal.objective=joint", "optimal.model=step_tests"]),
    ("optimal_foot_step_tests", ["optimal.model=step_tests"]),
    ("optimal_joint_walk", ["optimal.objective=joint"]),
)
T_STEPS = (88, 66, 52, 44)

# The untuned walks (every mode, and ILC's joint objective) and the held-out ones (measured only
# after optimal's last change; four modes): (wave, step time in ticks).
UNTUNED = (("sine", 88), ("triangle", 88), ("sine", 44), ("triangle", 44))
HELD_OUT = tuple((wave, t) for wave in ("sawtooth", "trapezoid", "harmonics") for t in (66, 88, 120)
                 ) + (("triangle", 66), ("triangle", 120), ("sine", 66), ("sine", 120))
HELD_OUT_MODES = "controller.modes=[time_shift,model_based,optimal,ilc]"

# Adaptive's probes: (name, probe_deg, probe_ticks); ticks 0 is a pulse of l + a ticks.
PROBES = (("pulse_6", 6, 0), ("pulse_12", 12, 0), ("pulse_20", 20, 0),
          ("excursion_20_24", 20, 24), ("excursion_20_40", 20, 40),
          ("excursion_30_32", 30, 32), ("excursion_40_32", 40, 32),
          ("excursion_40_44", 40, 44))


def untuned_walks():
    """{wave name: w(p)}, each periodic in p with period 2 pi and within [-1, 1]. A walk is one
    cycle of rotator 65 + 20 w(p), abductor 21 + 8 w(p + 1), knee 45 + 30 w(p + 2) deg,
    p = 2 pi t / T."""
    def tri(p):
        x = p / (2 * math.pi) - math.floor(p / (2 * math.pi))
        return 4 * x if x < 0.25 else (2 - 4 * x if x < 0.75 else 4 * x - 4)

    def saw(p):  # rises over 3/4 of the cycle
        x = p / (2 * math.pi) - math.floor(p / (2 * math.pi))
        return -1 + 2 * x / 0.75 if x < 0.75 else 1 - 2 * (x - 0.75) / 0.25
    return {"sine": math.sin, "triangle": tri, "sawtooth": saw,
            "trapezoid": lambda p: max(-1.0, min(1.0, 1.6 * tri(p))),
            "harmonics": lambda p: (math.sin(p) + 0.4 * math.sin(2 * p + 0.5)) / 1.2}


def walk_text(wave, t_step):
    """The desired.csv of one cycle of `wave` over `t_step` ticks."""
    w = untuned_walks()[wave]
    lines = ["tick,rotator_deg,abductor_deg,knee_deg"]
    for t in range(t_step):
        p = 2 * math.pi * t / t_step
        lines.append(f"{t},{65 + 20 * w(p)!r},{21 + 8 * w(p + 1)!r},{45 + 30 * w(p + 2)!r}")
    return "\n".join(lines) + "\n"


def walk_name(wave, t_step):
    return f"{wave}_{t_step}"


class Variant:
    """One run: `program` on `config` with `overrides` into RESULTS/variants/<name>/; `walk` the
    (wave, step time) whose desired.csv it reads, or None; `sweep` a sweep file's text to write
    and run instead of a config."""

    def __init__(self, name, program, config, overrides=(), walk=None, sweep=None):
        self.name, self.program, self.config = name, program, config
        self.overrides, self.walk, self.sweep = list(overrides), walk, sweep

    def command(self, bin_dir, results):
        out = results / "variants" / self.name
        config = out / "sweep.yaml" if self.sweep is not None else self.config
        sets = [x for o in self.overrides for x in ("--set", o)]
        if self.walk is not None:
            walk = results / "variants" / "inputs" / (walk_name(*self.walk) + ".csv")
            sets += ["--set", f"desired.csv={walk}", "--set", f"track.t_step_ticks={self.walk[1]}"]
        return [str(bin_dir / self.program), "--quiet", "--config", str(config), *sets,
                "--out", str(out)]


def rigid_rail_sweep():
    """experiments/sweeps/stand_load.yaml with the sled held rigid (a rail): its text."""
    path = SOURCE_DIR / SWEEPS / "stand_load.yaml"
    with open(path, encoding="utf-8") as f:
        sweep = yaml.safe_load(f)
    sweep["base"] = str((path.parent / sweep["base"]).resolve())
    sweep["stand"] = {"sled_stiffness_n_per_m": 0}
    return ("# experiments/sweeps/stand_load.yaml on a rigid rail (scripts/variants.py)\n" +
            yaml.safe_dump(sweep, sort_keys=False))


def variants():
    """Every variant, in the order docs/results/*.md quote them."""
    track = CONFIGS / "track.yaml"
    out = [Variant("cm_closed", "track", track,
                   ["controller.cm=closed", "controller.modes=[model_based]"]),
           Variant("ilc_joint", "track", track,
                   ["ilc.objective=joint", "controller.modes=[ilc]"])]
    for t in T_STEPS:
        at = [f"track.t_step_ticks={t}"]
        if t != 88:  # at 88 the shipped run is reproduce.sh's own
            out.append(Variant(f"t_step_{t}", "track", track, at))
        out.append(Variant(f"t_step_{t}_model_based_walk", "track", track,
                           at + ["controller.model=walk", "controller.modes=[model_based]"]))
        out += [Variant(f"t_step_{t}_{name}", "track", track, at + sets +
                        ["controller.modes=[optimal]"]) for name, sets in OPTIMAL_VARIANTS]
    for walk in UNTUNED:
        name = walk_name(*walk)
        out += [Variant(f"walk_{name}", "track", track, walk=walk),
                Variant(f"walk_{name}_ilc_joint", "track", track,
                        ["ilc.objective=joint", "controller.modes=[ilc]"], walk=walk)]
    out += [Variant(f"walk_{walk_name(*walk)}", "track", track, [HELD_OUT_MODES], walk=walk)
            for walk in HELD_OUT]
    out.append(Variant("walk_triangle_88_no_smoothing", "track", track,
                       ["optimal.request_smoothing=0", "controller.modes=[optimal]"],
                       walk=("triangle", 88)))
    for start in ("adapt_cold_start", "adapt_wear"):
        out += [Variant(f"{start}_{name}", "track", CONFIGS / f"{start}.yaml",
                        [f"adaptive.probe_deg={deg}", f"adaptive.probe_ticks={ticks}",
                         "controller.modes=[adaptive]"]) for name, deg, ticks in PROBES]
    out.append(Variant("stand_load_rigid", "sweep", None, sweep=rigid_rail_sweep()))
    return out


def run(variant, bin_dir, results):
    """Runs one variant; None, or what failed."""
    out = results / "variants" / variant.name
    out.mkdir(parents=True, exist_ok=True)
    if variant.sweep is not None:
        (out / "sweep.yaml").write_text(variant.sweep, encoding="utf-8")
    command = variant.command(bin_dir, results)
    done = subprocess.run(command, cwd=SOURCE_DIR, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["(nothing on stderr)"])[-1]
        return f"{shlex.join(command)} failed (exit {done.returncode}): {last}"
    return None


def main(argv):
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", type=pathlib.Path, help="the results folder (results/)")
    parser.add_argument("--bin", type=pathlib.Path, default=SOURCE_DIR / "build" / "bin",
                        help="the folder of the built programs (build/bin)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="just these variants")
    parser.add_argument("--list", action="store_true", help="print the commands, run nothing")
    args = parser.parse_args(argv)
    chosen = variants()
    if args.only:
        known = {v.name for v in chosen}
        unknown = [n for n in args.only if n not in known]
        if unknown:
            print(f"variants: unknown variant '{unknown[0]}' (see --list)", file=sys.stderr)
            return 2
        chosen = [v for v in chosen if v.name in args.only]
    results = args.results.resolve()
    if args.list:
        for v in chosen:
            print(v.name + ": " + shlex.join(v.command(args.bin, results)))
        return 0
    for program in {v.program for v in chosen}:
        if not os.access(args.bin / program, os.X_OK):
            print(f"variants: no program '{program}' in {args.bin} (build first)", file=sys.stderr)
            return 2
    walks = results / "variants" / "inputs"
    walks.mkdir(parents=True, exist_ok=True)
    for walk in {v.walk for v in chosen if v.walk is not None}:
        (walks / (walk_name(*walk) + ".csv")).write_text(walk_text(*walk), encoding="utf-8")
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        failures = [f for f in pool.map(lambda v: run(v, args.bin, results), chosen) if f]
    for failure in failures:
        print(f"variants: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
