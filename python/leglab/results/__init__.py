"""leglab.results: what a user runs on the programs' results folders, pure Python.

It needs numpy, matplotlib and PyYAML (Pillow, ffmpeg for an animation) but not leglab's
compiled module: a copy of python/leglab without _leglab*.so runs it. Each part is a command,

    python3 -m leglab.results.report RESULTS         the results page (index.html per folder)
    python3 -m leglab.results.plot_figures RUN       the paper's figures of an identify+track run
    python3 -m leglab.results.plot_logs DIR ...      the real servos' log and plan figures
    python3 -m leglab.results.plot_sweep SWEEP_CSV   a sweep's figure
    python3 -m leglab.results.animate RUN --out F    the leg in motion (.gif, .mp4)
    python3 -m leglab.results.compare_engines ODE_RUN DART_RUN   engines.md, ODE beside DART

with PYTHONPATH=<build>/python (or the source tree's python/). Beside them: `reader` (the
programs' files read against their declarations in docs/outputs.md), `figures` (every figure's
file name and caption, registered once), `log_fit_results` (a log fit's methods and mean
errors) and `urdf_chain` (a robot's URDF chain and its forward kinematics). Nothing is imported
here: `import leglab.results.report` loads what the page needs and no more.
"""

__all__ = ["animate", "compare_engines", "figures", "log_fit_results", "plot_figures",
           "plot_logs", "plot_sweep", "reader", "report", "urdf_chain"]
