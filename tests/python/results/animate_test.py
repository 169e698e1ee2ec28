#!/usr/bin/python3
"""leglab.results.animate against the runs it draws: the front leg, the hind leg and the stand.

Usage: PYTHONPATH=BUILD/python /usr/bin/python3 tests/python/results/animate_test.py SOURCE_DIR
       TRACK_BIN WORK_DIR

Runs `track` briefly (1 warm-up step, 2 measured, the model given so nothing is identified)
into WORK_DIR, then checks that the animation's feet, which animate finds by forward
kinematics of the URDF at the traced angles, are foot_<mode>.csv's actual feet (written by the
C++ kinematics) to 1e-6 cm for every mode and tick; that a .gif is written for each run (and
an .mp4 of the stand with ffmpeg on PATH); and that bad input exits 2 with one line naming it
and writes nothing.
Exits 0 when every check passes, 1 otherwise.
"""
import csv
import os
import shutil
import subprocess
import sys

TOLERANCE_CM = 1e-6
RUNS = {  # name -> config
    "front": "track.yaml",
    "hind": "track_hind.yaml",
    "stand": "track_stand.yaml",
}
QUICK = ["warmup_steps=1", "steps=2", "track.search_shift=false",
         "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}"]

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAIL:", what)


def main():
    source, track, work = sys.argv[1:4]
    from leglab.results import animate  # PYTHONPATH: the package

    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    script = [sys.executable, "-m", "leglab.results.animate"]
    for name, config in RUNS.items():
        out = os.path.join(work, name)
        command = [track, "--config", os.path.join("experiments", "configs", config), "--out", out,
                   "--quiet"]
        for setting in QUICK:
            command += ["--set", setting]
        # From the source folder, as the docs run it: table2.json names robots/<name>/robot.yaml.
        result = subprocess.run(command, cwd=source, capture_output=True, text=True)
        if result.returncode != 0:
            check(False, f"{name}: track failed: {result.stderr.strip()}")
            continue

        feet = animate.foot_positions(out, steps=2, every=1)
        check(len(feet) >= 5, f"{name}: {len(feet)} modes drawn, expected every mode run (>= 5)")
        for mode, drawn in feet.items():
            with open(os.path.join(out, f"foot_{mode}.csv"), newline="") as f:
                rows = list(csv.DictReader(f))
            check(len(drawn) == len(rows), f"{name} {mode}: {len(drawn)} ticks drawn, "
                                           f"{len(rows)} in foot_{mode}.csv")
            worst = 0.0
            for (step, tick, position), row in zip(drawn, rows):
                check((step, tick) == (int(row["step"]), int(row["tick"])),
                      f"{name} {mode}: frame ({step}, {tick}) against row ({row['step']}, "
                      f"{row['tick']})")
                for value, axis in zip(position, "xyz"):
                    worst = max(worst, abs(value - float(row[f"actual_{axis}_cm"])))
            check(worst <= TOLERANCE_CM, f"{name} {mode}: foot off foot_{mode}.csv by {worst} cm")
            print(f"{name} {mode}: {len(drawn)} ticks, worst {worst:.2e} cm")

        # The default animation, as a user asks for it, from another folder.
        suffixes = [".gif"] + ([".mp4"] if name == "stand" and shutil.which("ffmpeg") else [])
        for suffix in suffixes:
            movie = os.path.join(work, f"{name}{suffix}")
            result = subprocess.run([*script, out, "--out", movie], cwd=work,
                                    capture_output=True, text=True)
            check(result.returncode == 0, f"{name}{suffix}: exit {result.returncode}: "
                                          f"{result.stderr.strip()}")
            check(os.path.isfile(movie) and os.path.getsize(movie) > 1000,
                  f"{name}{suffix}: not written")
        if name == "front":
            with open(os.path.join(work, "front.gif"), "rb") as f:
                check(f.read(6) in (b"GIF87a", b"GIF89a"), "front.gif: not a GIF")

    # Bad input: exit 2, one line naming the item, nothing written.
    front = os.path.join(work, "front")
    empty = os.path.join(work, "empty")
    os.makedirs(empty)
    bad = [
        ([os.path.join(work, "nowhere"), "--out", "x.gif"], "nowhere"),
        ([empty, "--out", "x.gif"], "trace_"),
        ([front, "--modes", "direct", "walking", "--out", "x.gif"], "walking"),
        ([front, "--out", "x.png"], "x.png"),
    ]
    for arguments, named in bad:
        before = set(os.listdir(work))
        result = subprocess.run(script + arguments, cwd=work, capture_output=True,
                                text=True)
        lines = result.stderr.strip().splitlines()
        check(result.returncode == 2, f"{arguments}: exit {result.returncode}, expected 2")
        check(len(lines) == 1 and named in lines[0], f"{arguments}: stderr {lines}")
        check(set(os.listdir(work)) == before, f"{arguments}: wrote something")

    print("FAILED" if failures else "passed", f"({len(failures)} failures)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
