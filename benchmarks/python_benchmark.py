"""The Python package's cost, measured side by side with the same work in C++.

    PYTHONPATH=build/python /usr/bin/python3 benchmarks/python_benchmark.py \
        [--rounds N] [--build DIR] [--min-time S]

In interleaved rounds (the machine is shared and noisy: each figure is the median over rounds
of a ratio or difference taken within one round, never a single timing):

  (a) Plant.run over 1760 requests (20 steps of track.yaml's 88-tick walk, plant: sim), reset
      included, timed from Python, against
  (b) the same loop in C++: plant_loop_benchmark's BM_PlantRun1760 (real time per
      iteration). Printed: the ratio Python/C++ (target at
      most 1.05: Plant.run's conversions are a small part of a run);
  (c) Plant.tick's cost per call from Python on the model plant (a Python loop of calls, the
      loop's own cost included), less BM_ModelPlantTick's time per tick: the binding's
      overhead per call, us, for a numpy request and for a list of three floats (target at
      most 5 us);
  (d) a controller written in Python in run_track: the direct mode as a leglab.Controller
      against the built-in `direct` (one thread, models given so nothing is identified),
      as the ratio of their runs' wall times. Skipped with a message while leglab.run_track's
      C++ half is not built;
  (e) leglab.servo.ServoPlanner.request from a Python loop, one call a tick along the XL330's
      sin_time_square log (the planner measuring what its model predicts), model_based and
      optimal, against servo_planner_benchmark's BM_PlannerTick (the same loop in C++): the
      time per tick as a share of the XL330's 5.3 ms tick (target at most 10 % for
      model_based from Python).

Both languages are timed alike: each repetition is the mean wall time per call over
--min-time seconds (Google Benchmark's iteration time; Python repeats the call as long), and a
round takes the fastest of 3 repetitions (REPETITIONS). Nothing here is asserted: the targets are
printed beside the figures.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import leglab
import leglab.servo as servo

RUN_TICKS = 1760     # BM_PlantRun1760's ticks: 20 steps of the 88-tick walk
TICK_CALLS = 20000   # Python tick calls timed per repetition in (c)
REPETITIONS = 3      # repetitions per round, of which the fastest counts (both languages)

# The joint model given to run_track in (d), so that it identifies nothing: Table 1's.
GIVEN_MODEL = {"v_max_deg_per_tick": 2.5, "theta0_deg": 7.0, "lag_ticks": 4, "accel_ticks": 3}


def mean_s(work, min_time_s):
    """The mean wall time of `work()` over as many calls as fill `min_time_s` (at least one),
    s: what Google Benchmark reports per iteration of one repetition."""
    calls = 0
    start = time.perf_counter()
    while True:
        work()
        calls += 1
        elapsed = time.perf_counter() - start
        if elapsed >= min_time_s:
            return elapsed / calls


def python_run_s(plant, requests, min_time_s):
    """reset + Plant.run(requests), s: the fastest of REPETITIONS repetitions, each the mean
    over min_time_s (as BM_PlantRun1760 is timed)."""
    def work():
        plant.reset(requests[0])
        plant.run(requests)

    return min(mean_s(work, min_time_s) for _ in range(REPETITIONS))


def python_tick_s(plant, requests, min_time_s):
    """One Plant.tick call from a Python loop over `requests` (a list of requests), s: the
    fastest of REPETITIONS repetitions, each the mean over min_time_s."""
    tick = plant.tick

    def work():
        for request in requests:
            tick(request)

    return min(mean_s(work, min_time_s) for _ in range(REPETITIONS)) / len(requests)


def cpp_times_s(program, min_time_s):
    """{benchmark name: the fastest repetition's real time per iteration, s} of
    plant_loop_benchmark's two cases."""
    out = subprocess.run(
        [program, "--benchmark_filter=BM_PlantRun1760|BM_ModelPlantTick",
         "--benchmark_format=json", f"--benchmark_min_time={min_time_s}",
         f"--benchmark_repetitions={REPETITIONS}"],
        check=True, capture_output=True, text=True).stdout
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = b.get("run_name", b["name"]).split("/")[0]
        seconds = b["real_time"] * scale[b["time_unit"]]
        times[name] = min(times.get(name, float("inf")), seconds)
    return times


# servo_planner_benchmark's XL330 models (identify's fit of identify_logs.yaml).
XL330_FIT = {"models": {"extended": {"xl330": {
    "tick_s": 0.005292177200317383, "gain_per_deg_kp": 6.164324274979596e-05,
    "v_max_deg_s": 856.3316406008295, "stall_torque_nm": 0.504851487618676,
    "friction_duty": 2.3869350476813286e-14, "friction_load_ratio": 0.37634236423778544,
    "velocity_lag_s": 0.14366047744528795, "lag_ticks": 1}}}}
XL330_LOG = "data/servo_logs/dynamixel-xl330/sin_time_square_kp400_2026-01-15_10h29m37.json"


def planner_tick_s(method, min_time_s):
    """One ServoPlanner.request call from a Python loop along the log's requests, s: the
    fastest of REPETITIONS repetitions, each the mean over min_time_s."""
    model = servo.LogFit(json.dumps(XL330_FIT)).model("xl330")
    log = servo.read_log(os.path.join(leglab.data_dir(), XL330_LOG))
    ticks = np.arange(log.time_s[0], log.time_s[-1] + 1e-9, model.tick_s)
    desired = log.request_deg[np.searchsorted(log.time_s, ticks, side="right") - 1]
    planner = servo.ServoPlanner(model, method, kp=log.kp, mass_kg=log.mass_kg,
                                 length_m=log.length_m)
    window = planner.preview_ticks + 1
    request = planner.request

    def work():
        planner.reset(desired[0])
        for t in range(len(desired)):
            request(desired[t:t + window], planner.expected_deg)

    return min(mean_s(work, min_time_s) for _ in range(REPETITIONS)) / len(desired)


def cpp_planner_times_s(program, min_time_s):
    """{"model_based": s, "optimal": s}: servo_planner_benchmark's BM_PlannerTick."""
    out = subprocess.run(
        [program, "--benchmark_filter=BM_PlannerTick", "--benchmark_format=json",
         f"--benchmark_min_time={min_time_s}", f"--benchmark_repetitions={REPETITIONS}",
         "--rounds=1"],
        check=True, capture_output=True, text=True).stdout
    out = out[:out.rindex("}") + 1]  # the side-by-side report printed after the JSON
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        name = "model_based" if b.get("run_name", b["name"]).endswith("/0") else "optimal"
        times[name] = min(times.get(name, float("inf")),
                          b["real_time"] * scale[b["time_unit"]])
    return times


class PythonDirect(leglab.Controller):
    """The built-in `direct` mode written in Python: request the desired angle of the tick."""

    name = "py_direct"

    def reset(self, context):
        """Keeps the desired cycle."""
        self.desired = np.array(context.desired)

    def request(self, tick, measured):
        """The desired angles of this tick."""
        return self.desired[tick % len(self.desired)]


def run_track_s(controllers):
    """The wall time of run_track with only the built-in direct mode and `controllers`, s."""
    overrides = {"controller.modes": "[direct]", "steps": 5, "model": GIVEN_MODEL}
    start = time.perf_counter()
    leglab.run_track(leglab.config_path("track.yaml"), overrides, controllers=controllers,
                     threads=1)
    return time.perf_counter() - start


def main():
    """Parses the flags, runs the rounds and prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7, help="interleaved rounds (default 7)")
    parser.add_argument("--build", default="build", help="the build folder (default build)")
    parser.add_argument("--min-time", type=float, default=0.3,
                        help="Google Benchmark's min time per repetition, s (default 0.3)")
    args = parser.parse_args()
    program = os.path.join(args.build, "bin", "plant_loop_benchmark")
    if not os.access(program, os.X_OK):
        sys.exit(f"python_benchmark: no {program}; build it: "
                 f"cmake --build {args.build} --target plant_loop_benchmark")

    config = leglab.config_path("track.yaml")
    walk = leglab.Walk(config)
    requests = np.tile(walk.angles_deg, (RUN_TICKS // walk.period + 1, 1))[:RUN_TICKS]
    sim = leglab.Plant(config)
    model = leglab.Plant(config, {"plant": "model"})
    model.reset(walk.angles_deg[0])
    tick_rows = np.tile(walk.angles_deg, (TICK_CALLS // walk.period + 1, 1))[:TICK_CALLS]
    numpy_requests = [row.copy() for row in tick_rows]
    list_requests = [[float(x) for x in row] for row in tick_rows]

    run_ratios, py_run, cpp_run, numpy_over, list_over, cpp_tick = [], [], [], [], [], []
    for round_ in range(args.rounds):
        def python_side():
            """(a) and (c) of this round: Plant.run's time, and one tick's per request kind."""
            py_run.append(python_run_s(sim, requests, args.min_time))
            numpy_s = python_tick_s(model, numpy_requests, args.min_time)
            list_s = python_tick_s(model, list_requests, args.min_time)
            return numpy_s, list_s

        # Alternate which language goes first, so that a slow spell of the machine falls on
        # both alike over the rounds.
        if round_ % 2 == 0:
            numpy_s, list_s = python_side()
            cpp = cpp_times_s(program, args.min_time)
        else:
            cpp = cpp_times_s(program, args.min_time)
            numpy_s, list_s = python_side()
        cpp_run.append(cpp["BM_PlantRun1760"])
        cpp_tick.append(cpp["BM_ModelPlantTick"])
        run_ratios.append(py_run[-1] / cpp_run[-1])
        numpy_over.append(numpy_s - cpp_tick[-1])
        list_over.append(list_s - cpp_tick[-1])

    track_line = None
    if hasattr(leglab._leglab, "_run_track"):
        ratios = []
        for round_ in range(max(1, args.rounds // 2)):
            if round_ % 2 == 0:
                builtin = run_track_s([])
                both = run_track_s([PythonDirect()])
            else:
                both = run_track_s([PythonDirect()])
                builtin = run_track_s([])
            # `both` ran the built-in direct and the Python one: the Python one's share is the
            # difference.
            ratios.append((both - builtin) / builtin)
        track_line = (f"| (d) run_track: a Python direct run's extra wall time / the built-in "
                      f"direct run's | "
                      f"{statistics.median(ratios):.2f} | - |")

    planner_program = os.path.join(args.build, "bin", "servo_planner_benchmark")
    planner_py = {"model_based": [], "optimal": []}
    planner_cpp = {"model_based": [], "optimal": []}
    if os.access(planner_program, os.X_OK):
        for round_ in range(args.rounds):
            def planner_python():
                """(e) from Python, this round."""
                for method in planner_py:
                    planner_py[method].append(planner_tick_s(method, args.min_time))

            if round_ % 2 == 0:
                planner_python()
                cpp = cpp_planner_times_s(planner_program, args.min_time)
            else:
                cpp = cpp_planner_times_s(planner_program, args.min_time)
                planner_python()
            for method in planner_cpp:
                planner_cpp[method].append(cpp[method])

    median = statistics.median
    print(f"Python package cost: medians of {args.rounds} interleaved rounds, fastest of "
          f"{REPETITIONS} repetitions of {args.min_time:g} s within each")
    print()
    print("| measure | figure | target |")
    print("|---|---|---|")
    print(f"| (a) Plant.run, {RUN_TICKS} sim ticks, from Python | {median(py_run) * 1e3:.1f} ms "
          f"| - |")
    print(f"| (b) the same loop in C++ (BM_PlantRun1760) | {median(cpp_run) * 1e3:.1f} ms | - |")
    print(f"| (a)/(b) Python/C++ | {median(run_ratios):.3f} | <= 1.05 |")
    print(f"| model plant tick in C++ (BM_ModelPlantTick) | {median(cpp_tick) * 1e6:.3f} us "
          f"| - |")
    print(f"| (c) Plant.tick overhead per call, numpy request | {median(numpy_over) * 1e6:.2f} us "
          f"| <= 5 us |")
    print(f"| (c) Plant.tick overhead per call, list of floats | {median(list_over) * 1e6:.2f} us "
          f"| <= 5 us |")
    tick_s = XL330_FIT["models"]["extended"]["xl330"]["tick_s"]
    if planner_py["model_based"]:
        for method, target in (("model_based", "<= 10 %"), ("optimal", "-")):
            py_s, cpp_s = median(planner_py[method]), median(planner_cpp[method])
            print(f"| (e) ServoPlanner.request, {method}, per tick from Python (C++) | "
                  f"{py_s * 1e6:.2f} us ({cpp_s * 1e6:.2f} us): {100 * py_s / tick_s:.3f} % "
                  f"({100 * cpp_s / tick_s:.3f} %) of the 5.3 ms tick | {target} |")
    else:
        print(f"| (e) ServoPlanner.request | skipped: no {planner_program} | - |")
    if track_line:
        print(track_line)
    else:
        print("| (d) run_track with a Python controller | skipped: leglab.run_track's C++ half "
              "(_run_track) is not built | - |")


if __name__ == "__main__":
    main()
