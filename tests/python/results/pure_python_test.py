#!/usr/bin/python3
"""leglab.results without the compiled module: a copy of python/leglab with no _leglab*.so (and no
build's _paths.py) on PYTHONPATH, leglab's data named by LEGLAB_DATA_DIR (the source tree, as
an installed share/leglab would be). Every leglab.results module imports without loading
leglab._leglab, a compiled name (leglab.Plant) raises ImportError naming the missing module,
and plot_figures, animate and report run on a short track run, each writing its files.

Usage: pure_python_test.py SOURCE_DIR TRACK WORK_DIR   (TRACK: BUILD/bin/track)
Exit 0: passed; 1: failed (every failure printed).
"""
import os
import shutil
import subprocess
import sys

MODULES = ("animate", "compare_engines", "figures", "log_fit_results", "plot_figures",
           "plot_logs", "plot_sweep", "reader", "report", "urdf_chain")
IMPORTS = f"""
import importlib, sys
import leglab
for name in {MODULES!r}:
    importlib.import_module("leglab.results." + name)
assert "leglab._leglab" not in sys.modules, "leglab._leglab was imported"
try:
    leglab.Plant
except ImportError as e:
    print("compiled:", e)
"""


def main(source, track, work):
    failures = []
    shutil.rmtree(work, ignore_errors=True)
    package = os.path.join(work, "python", "leglab")
    shutil.copytree(os.path.join(source, "python", "leglab"), package,
                    ignore=shutil.ignore_patterns("__pycache__", "_leglab*", "_paths.py"))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(PYTHONPATH=os.path.join(work, "python"), LEGLAB_DATA_DIR=source)

    def run(*command):
        # From the source folder, as the docs run them: table2.json names robots/<name>/...
        result = subprocess.run(command, cwd=source, env=env, capture_output=True, text=True)
        if result.returncode != 0:
            failures.append(f"{' '.join(command)}: exit {result.returncode}: {result.stderr}")
        return result

    result = run(sys.executable, "-c", IMPORTS)
    if "compiled: leglab.Plant: the compiled module leglab._leglab is not in" not in result.stdout:
        failures.append(f"leglab.Plant without the compiled module: {result.stdout!r}")
    out = os.path.join(work, "run")
    run(track, "--config", "experiments/configs/track.yaml", "--out", out, "--quiet",
        "--set", "warmup_steps=1", "--set", "steps=2", "--set", "track.search_shift=false",
        "--set", "controller.modes=[direct, model_based]",
        "--set", "model={v_max_deg_per_tick: 2.5, theta0_deg: 7, lag_ticks: 4, accel_ticks: 6}")
    run(sys.executable, "-m", "leglab.results.plot_figures", out)
    run(sys.executable, "-m", "leglab.results.animate", out, "--out",
        os.path.join(out, "leg.gif"))
    run(sys.executable, "-m", "leglab.results.report", out)
    for name in ("fig1_foot_direct.png", "leg.gif", "index.html"):
        if not os.path.isfile(os.path.join(out, name)):
            failures.append(f"no {name} written into {out}")
    for failure in failures:
        print("FAIL:", failure)
    if not failures:
        print("leglab.results: imported and run without leglab._leglab")
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__.split("\n\n")[1])
    sys.exit(main(*(os.path.abspath(a) for a in sys.argv[1:])))
