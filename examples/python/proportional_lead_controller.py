"""A request policy written in Python, run in Table 2's experiment beside the built-in modes.

ProportionalLead requests, for each joint at tick t,

    R(t) = d(t + lead) + gain * (d(t - 1) - m(t - 1))

where d is the desired cycle (repeating every T ticks), m(t - 1) the angle measured right
after the previous request, `lead` a time shift in ticks (the servo reaches a request some
ticks late, so asking for where the joint should be `lead` ticks from now makes up for it: the
paper's time_shift mode with a fixed shift) and `gain` a proportional correction of the latest
error it can see. The request is clamped into the joint limits, as the servos would.

Defaults lead = 8 ticks, gain = 0.25: the best of a coarse grid (lead 0..12, gain 0, 0.25, 0.5,
1) on track.yaml's plant. A gain near 1 makes it worse: the error it corrects is several ticks
old by the time the servo acts on it.

The script runs the track experiment (leglab.run_track, as build/bin/track does) with the modes
direct and model_based and three ProportionalLead controllers (lead 6, 8 and 10 ticks: a tiny
search over the lead) for 5 measured steps, and prints the foot rows of Table 2 (foot error
L2 and Linf, cm) for every mode. Run from the repository root after building the package:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/proportional_lead_controller.py
"""

import numpy as np

import leglab


class ProportionalLead(leglab.Controller):
    """R(t) = d(t + lead) + gain * (d(t - 1) - m(t - 1)), clamped into the joint limits.

    Args:
        lead: ticks the desired angle is taken ahead of the tick (>= 0).
        gain: the proportional gain on the latest seen error (dimensionless, >= 0).
        name: the controller's name in the tables (letters a-z, digits and _); default
            "p_lead<lead>".
    """

    def __init__(self, lead=8, gain=0.25, name=None):
        """See the class docstring; ValueError for a negative lead or gain."""
        if lead < 0 or gain < 0:
            raise ValueError(f"ProportionalLead: lead and gain must be >= 0, got {lead}, {gain}")
        self.lead = int(lead)
        self.gain = float(gain)
        self.name = name or f"p_lead{self.lead}"

    def reset(self, context):
        """Keeps the desired cycle (T, 3), deg, and the joint limits (3, 2), deg."""
        self.desired = np.array(context.desired, dtype=float)
        self.limits = np.array(context.limits_deg, dtype=float)

    def request(self, tick, measured):
        """The law above for tick `tick` (counted from the run's first tick, warm-up
        included: the desired cycle's tick is tick % T)."""
        period = len(self.desired)
        ahead = self.desired[(tick + self.lead) % period]
        seen_error = self.desired[(tick - 1) % period] - np.asarray(measured, dtype=float)
        request = ahead + self.gain * seen_error
        return np.clip(request, self.limits[:, 0], self.limits[:, 1])


def main():
    """Runs track with direct, model_based and three leads; prints the foot rows."""
    controllers = [ProportionalLead(lead=lead) for lead in (6, 8, 10)]
    result = leglab.run_track(
        leglab.config_path("track.yaml"),
        {"controller.modes": "[direct, model_based]", "steps": 5},
        controllers=controllers)

    foot = result.table2["foot_cm"]
    print(f"Foot error over {result.table2['steps']} measured steps, cm "
          f"(track.yaml, {result.plant_ticks} plant ticks in all)")
    print()
    print(f"| {'mode':<12} | {'L2 mean':>8} | {'L2 std':>7} | {'Linf mean':>9} | {'Linf std':>8} |")
    print(f"|{'-' * 14}|{'-' * 10}|{'-' * 9}|{'-' * 11}|{'-' * 10}|")
    for mode in ["direct", "model_based"] + [c.name for c in controllers]:
        row = foot[mode]
        print(f"| {mode:<12} | {row['L2']['mean']:>8.3f} | {row['L2']['std']:>7.3f} | "
              f"{row['Linf']['mean']:>9.3f} | {row['Linf']['std']:>8.3f} |")


if __name__ == "__main__":
    main()
