"""The paper's step test on the knee, and the joint model identified from it (Table 1).

Drives a leglab.Plant through the square wave of eq. 1 on the knee (theta_test for the first
half of each period, 0 for the second, the other joints held at 0), lets it settle for 5
periods and records 8, as `identify` does (experiments/src/rig.cc, RunStepTest), for step
heights of 40 and 110 deg. Then fits the paper's joint model (eq. 3) to both recordings with
leglab.identify, prints it beside the paper's Table 1 (leglab.PAPER_MODEL) with the fit's RMS
residual, and how well the fitted model predicts each recording (JointModel.simulate).

Run from the repository root after building the package:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/step_test_identify.py
    PYTHONPATH=build/python /usr/bin/python3 examples/python/step_test_identify.py --period-ticks 16

The default period, 88 ticks, is identify.yaml's t_step_ticks: long enough for the knee to
reach both step heights. With a short period (16 ticks) the knee cannot: both recordings
swing over the same small band and the fit sees only the top speed and the lag.
"""

import argparse

import numpy as np

import leglab

KNEE = leglab.JOINT_NAMES.index("knee")
SETTLE_CYCLES = 5  # periods run before recording, to reach the cycle's equilibrium
RECORD_CYCLES = 8  # periods recorded and fitted (identify.yaml's record_cycles)


def step_test_requests(theta_test_deg, period_ticks, cycles):
    """Eq. 1 repeated: theta_test for t < period/2 of each period, 0 after; shape (N, 3) with
    only the knee's column moving (the other joints held at 0)."""
    t = np.arange(period_ticks * cycles) % period_ticks
    requests = np.zeros((len(t), 3))
    requests[:, KNEE] = np.where(2 * t < period_ticks, theta_test_deg, 0.0)
    return requests


def main():
    """Runs the step tests, fits the model and prints the comparison."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--period-ticks", type=int, default=88,
                        help="ticks per period of the square wave (default 88)")
    parser.add_argument("--theta", type=float, nargs="+", default=[40.0, 110.0],
                        help="step heights, deg (default 40 110)")
    args = parser.parse_args()
    period = args.period_ticks
    config = leglab.config_path("identify.yaml")

    # One fresh plant per step height, at rest at q = 0, as `identify` runs its step tests.
    full_requests, recorded_requests, recorded_measured = [], [], []
    for theta in args.theta:
        plant = leglab.Plant(config)
        plant.reset([0.0, 0.0, 0.0])
        requests = step_test_requests(theta, period, SETTLE_CYCLES + RECORD_CYCLES)
        run = plant.run(requests)
        first = SETTLE_CYCLES * period
        # The requests as the servo took them (clamped into the limits) and the angles
        # measured right after each: the recording `identify` fits.
        full_requests.append(run["applied"][:, KNEE])
        recorded_requests.append(run["applied"][first:, KNEE])
        recorded_measured.append(run["measured"][first:, KNEE])

    # period_ticks: each recording is whole periods of one request pattern, averaged into one
    # period before the fit (identify.yaml's average_cycles: true).
    fit = leglab.identify(recorded_requests, recorded_measured, period_ticks=period)
    model, paper = fit.model, leglab.PAPER_MODEL

    print(f"Knee step test: period {period} ticks, step heights "
          f"{', '.join(f'{t:g}' for t in args.theta)} deg, {RECORD_CYCLES} periods recorded")
    print()
    print(f"| {'parameter':<22} | {'identified':>10} | {'paper (Table 1)':>15} |")
    print(f"|{'-' * 24}|{'-' * 12}|{'-' * 17}|")
    print(f"| {'v_max (deg/tick)':<22} | {model.v_max_deg_per_tick:>10.3f} | "
          f"{paper.v_max_deg_per_tick:>15.3f} |")
    print(f"| {'theta_0 (deg)':<22} | {model.theta0_deg:>10.3f} | {paper.theta0_deg:>15.3f} |")
    print(f"| {'l (ticks)':<22} | {model.lag_ticks:>10d} | {paper.lag_ticks:>15d} |")
    print(f"| {'a (ticks)':<22} | {model.accel_ticks:>10d} | {paper.accel_ticks:>15d} |")
    print()
    print(f"fit's RMS residual (averaged periods): {fit.rms_residual_deg:.3f} deg")

    # The model's prediction of each recording: run from rest at 0, like the plant, over the
    # same requests (settling periods included), compared on the recorded ticks.
    first = SETTLE_CYCLES * period
    for theta, requests, measured in zip(args.theta, full_requests, recorded_measured):
        predicted = model.simulate(requests, 0.0)[first:]
        error = predicted - measured
        print(f"theta_test {theta:5.1f} deg: measured swings {measured.min():6.1f} .. "
              f"{measured.max():6.1f} deg; model's prediction error RMS "
              f"{np.sqrt(np.mean(error ** 2)):.3f} deg, max {np.max(np.abs(error)):.3f} deg")


if __name__ == "__main__":
    main()
