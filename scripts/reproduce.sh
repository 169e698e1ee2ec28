#!/usr/bin/env bash
# Set-up, build, then every experiment into results/: Table 1 (identify), Table 2 (track) and
# the figures. Usage: ./scripts/reproduce.sh [results-dir]
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
cmake --build --preset release
# The leglab package: the build's (with its compiled module) when built, else the source tree's
# pure-Python parts (leglab.results: the figures, the animation and the results page).
export PYTHONPATH="$PWD/build/python:$PWD/python${PYTHONPATH:+:$PYTHONPATH}"
out="${1:-results}"
mkdir -p "$out"

ran=0
if [ -x build/bin/identify ]; then
  build/bin/identify --config experiments/configs/identify.yaml --out "$out"
  ran=1
fi
if [ -x build/bin/track ]; then
  build/bin/track --config experiments/configs/track.yaml --out "$out"
  ran=1
fi
# The left hind leg: its own Table 1 and Table 2 in results/hind/.
if [ -x build/bin/identify ] && [ -x build/bin/track ]; then
  build/bin/identify --config experiments/configs/identify.yaml --set robot=ers210a_hind \
    --out "$out/hind"
  build/bin/track --config experiments/configs/track_hind.yaml --out "$out/hind"
fi
# Both legs again on the second physics engine (sim.engine: dart) into dart/ and hind/dart/,
# with engines.md: each table and step test beside ODE's (the stand is ODE's alone). A build
# configured without DART (LEGLAB_WITH_DART off in build/CMakeCache.txt) skips them, saying so.
if [ -x build/bin/identify ] && [ -x build/bin/track ] &&
  ! grep -Eiq '^LEGLAB_WITH_DART:BOOL=(ON|1|TRUE|YES|Y)$' build/CMakeCache.txt; then
  echo "reproduce: skipping the runs on DART (dart/, hind/dart/): this build has no DART" \
    "(LEGLAB_WITH_DART is OFF)" >&2
elif [ -x build/bin/identify ] && [ -x build/bin/track ]; then
  build/bin/identify --config experiments/configs/identify.yaml --set sim.engine=dart \
    --out "$out/dart"
  build/bin/track --config experiments/configs/track.yaml --set sim.engine=dart --out "$out/dart"
  build/bin/identify --config experiments/configs/identify.yaml --set robot=ers210a_hind \
    --set sim.engine=dart --out "$out/hind/dart"
  build/bin/track --config experiments/configs/track_hind.yaml --set sim.engine=dart \
    --out "$out/hind/dart"
  /usr/bin/python3 -m leglab.results.compare_engines "$out" "$out/dart"
  /usr/bin/python3 -m leglab.results.compare_engines "$out/hind" "$out/hind/dart"
fi
# Table 2 in the paper's regime: the walk fitted to the paper's direct-method row
# (walk_fit.json, walk_fit.md), then every mode on it (track_paper_regime.yaml: that walk).
if [ -x build/bin/fit_walk ]; then
  build/bin/fit_walk --config experiments/configs/track.yaml --out "$out/walk_fit"
fi
if [ -x build/bin/track ]; then
  build/bin/track --config experiments/configs/track_paper_regime.yaml \
    --out "$out/track_paper_regime"
fi
# The front leg on the single-leg test stand: Table 1 with the foot free of the floor
# (and the same tests in the air, air70/), the loaded step test (loaded/), Table 2 on the stand.
if [ -x build/bin/identify ] && [ -x build/bin/track ]; then
  build/bin/identify --config experiments/configs/identify_stand.yaml --out "$out/stand"
  build/bin/identify --config experiments/configs/identify_stand.yaml --set robot=ers210a \
    --out "$out/stand/air70"
  build/bin/identify --config experiments/configs/identify_stand_loaded.yaml --out "$out/stand/loaded"
  build/bin/track --config experiments/configs/track_stand.yaml --out "$out/stand"
fi
# Learning the model while walking (adaptive): from a wrong model, and through a change of
# the plant at step 20. worn_model/: model_based with the model identified on the changed plant
# (the change of adapt_wear.yaml made from the start), its yardstick.
if [ -x build/bin/track ]; then
  build/bin/track --config experiments/configs/adapt_cold_start.yaml --out "$out/adapt_cold_start"
  build/bin/track --config experiments/configs/adapt_wear.yaml --out "$out/adapt_wear"
  build/bin/track --config experiments/configs/adapt_wear.yaml --out "$out/adapt_wear/worn_model" \
    --set 'plant_changes=[]' --set servo.max_speed_deg_s=250 --set servo.delay_ms=56 \
    --set 'controller.modes=[model_based]'
fi
if [ $ran -eq 1 ]; then
  /usr/bin/python3 -m leglab.results.plot_figures "$out"
  /usr/bin/python3 -m leglab.results.plot_figures "$out/hind"
  /usr/bin/python3 -m leglab.results.plot_figures "$out/track_paper_regime"
  /usr/bin/python3 -m leglab.results.plot_figures "$out/stand"
  /usr/bin/python3 -m leglab.results.plot_figures "$out/adapt_cold_start"
  /usr/bin/python3 -m leglab.results.plot_figures "$out/adapt_wear"
fi
# Real servos: the model ladder on the shipped logs of two hobby servos (data/servo_logs/), one
# parameter set per servo type, each trajectory held out in turn (servo_logs/); the XL330 with
# each gain setting held out in turn (servo_logs/by_kp/); requests planned through the fitted
# extended model for an XL330 log's motion (servo_logs/plan/), and online by preview length
# (servo_logs/online/).
if [ -x build/bin/identify ] && [ -x build/bin/plan ]; then
  build/bin/identify --config experiments/configs/identify_logs.yaml --out "$out/servo_logs"
  build/bin/identify --config experiments/configs/identify_logs.yaml --out "$out/servo_logs/by_kp" \
    --set 'logs.train=[data/servo_logs/dynamixel-xl330]' --set logs.cross_validate=leave_one_kp_out
  build/bin/plan --model "$out/servo_logs/log_fit.json" --method optimal \
    --desired data/servo_logs/dynamixel-xl330/sin_time_square_kp400_2026-01-15_10h29m37.json \
    --out "$out/servo_logs/plan"
  # The learned rungs (an MLP and an LSTM, PyTorch) trained on each fold's training logs and
  # scored beside the others (learned_fit.json and .md in both folders).
  /usr/bin/python3 -m leglab.servo.learned "$out/servo_logs" "$out/servo_logs/by_kp" \
    --learning-curve xl330
  # The online planner against the batch plan, by preview length (servo_logs/online/).
  /usr/bin/python3 scripts/online_preview_table.py --model "$out/servo_logs/log_fit.json" \
    --out "$out/servo_logs/online" > /dev/null
  /usr/bin/python3 -m leglab.results.plot_logs "$out/servo_logs" "$out/servo_logs/by_kp" \
    "$out/servo_logs/plan"
fi
# The shipped sweeps, each with its figure, into results/sweeps/<name>/.
if [ -x build/bin/sweep ]; then
  for sweep in model_mismatch walk_speed stand_load servo_firmware; do
    build/bin/sweep --config "experiments/sweeps/$sweep.yaml" --out "$out/sweeps/$sweep"
    /usr/bin/python3 -m leglab.results.plot_sweep "$out/sweeps/$sweep/sweep.csv"
  done
fi
# The variants the results page quotes (scripts/variants.py: closed-form C_m, the modes' options,
# optimal at four step times, the untuned and held-out walks, adaptive's probes, the stand-load
# sweep on a rigid rail), each into results/variants/<name>/.
if [ -x build/bin/track ] && [ -x build/bin/sweep ]; then
  /usr/bin/python3 scripts/variants.py "$out"
fi
# The servo bus end to end on emulated servos, per protocol: record, identify, run each method
# (scripts/bus_loop.py, virtual time), into results/bus/<protocol>/.
if [ -x build/bin/identify ] && [ -f build/python/leglab/bus/cli.py ]; then
  /usr/bin/python3 scripts/bus_loop.py "$out"
fi
# The leg in motion (leg.gif) for the default run, the stand and the paper's regime; then a page
# for every folder of results (index.html, self-contained), the top one linking the others.
if [ $ran -eq 1 ]; then
  for run in "$out" "$out/stand" "$out/track_paper_regime"; do
    /usr/bin/python3 -m leglab.results.animate "$run" --out "$run/leg.gif"
  done
fi
if [ $ran -eq 1 ]; then
  /usr/bin/python3 -m leglab.results.report "$out"
  # The measured tables of README.md and docs/results/*.md against this run: a difference is
  # named, not fatal (docs_numbers.py "$out" --write puts this run's numbers in the docs).
  if ! /usr/bin/python3 scripts/docs_numbers.py "$out"; then
    echo "reproduce: the docs' tables differ from this run (above)" >&2
  fi
  # Every CSV table of this run against the columns docs/outputs.md declares.
  if ! /usr/bin/python3 tools/check_outputs.py "$out"; then
    echo "reproduce: a table's columns differ from docs/outputs.md (above)" >&2
  fi
fi
if [ $ran -eq 0 ]; then
  echo "reproduce: no experiment programs are built yet (identify, track): nothing to run." >&2
  exit 1
fi
echo "reproduce: results in $out/ (open $out/index.html)"
