"""leglab.bus.trajectories: BAM's four trajectories against the requests in the shipped logs
(data/servo_logs/), and leglab's chirp and steps against values computed by hand.

What the logs hold (read from BAM's recorders, bam/dynamixel/record.py and
bam/feetech/record.py, and checked on the files): `goal_position` is the request in radians
from the hanging zero, as the trajectory returned it (a float, not quantised to counts), and
`timestamp` is the middle of the read that follows sending it, so the request was computed a
little before the timestamp: 3.4-5.4 ms before on the XL330 logs (median 3.54 ms), 7.6-26.3 ms
on the STS3250's (median 13.5 ms). At the timestamps themselves the requests differ from the
trajectories by up to 2.5 deg (XL330) and 13.5 deg (STS3250, sin_time_square's fast end).
"""

import json
import math
import os

import pytest

from leglab.bus import trajectories as tr

BAM = ("lift_and_drop", "sin_time_square", "up_and_down", "sin_sin")
LOG_DIR = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(
    __file__)))), "data", "servo_logs")
COUNT_DEG = 360.0 / 4096.0  # one count of a 12-bit servo: the tolerance on a request
# How long before its timestamp each folder's request was computed (s): the window searched,
# a little wider than the 3.4-5.4 ms and 7.6-26.3 ms measured, and the median delay.
LAG_WINDOW_S = {"dynamixel-xl330": (0.003, 0.006), "feetech-sts3250": (0.007, 0.027)}
MEDIAN_LAG_S = {"dynamixel-xl330": 0.00354, "feetech-sts3250": 0.0135}
WINDOW_STEP_S = 0.00025


def _logs():
    """(folder, log dict) of every shipped JSON log."""
    out = []
    for folder in sorted(os.listdir(LOG_DIR)):
        path = os.path.join(LOG_DIR, folder)
        if not os.path.isdir(path):
            continue
        for name in sorted(os.listdir(path)):
            if name.endswith(".json"):
                with open(os.path.join(path, name)) as f:
                    out.append((folder, json.load(f)))
    return out


LOGS = _logs()


def test_the_logs_are_the_sixteen_on_bams_four_trajectories():
    assert len(LOGS) == 16
    assert {log["trajectory"] for _, log in LOGS} == set(BAM)
    assert {folder for folder, _ in LOGS} == set(LAG_WINDOW_S)


def _within_window(name, t_s, request_deg, window):
    """Whether request_deg is within a count of the trajectory somewhere in t_s - window."""
    lo, hi = window
    steps = int(round((hi - lo) / WINDOW_STEP_S))
    values = [tr.sample(name, max(0.0, t_s - lo - k * WINDOW_STEP_S))[0]
              for k in range(steps + 1)]
    return min(values) - COUNT_DEG <= request_deg <= max(values) + COUNT_DEG


@pytest.mark.parametrize("name", BAM)
def test_every_logged_request_is_the_trajectory_just_before_its_timestamp(name):
    for folder, log in LOGS:
        if log["trajectory"] != name:
            continue
        for e in log["entries"]:
            request = math.degrees(e["goal_position"])
            assert _within_window(name, e["timestamp"], request, LAG_WINDOW_S[folder]), (
                folder, log["kp"], e["timestamp"], request)


@pytest.mark.parametrize("name", BAM)
def test_at_the_median_delay_the_requests_match(name):
    """Sampled at timestamp - the folder's median delay: the median difference is under
    0.02 deg everywhere (measured at most 0.012); the greatest, from the delay's jitter, under
    0.25 deg on the XL330 (measured 0.205) and 5 deg on the slower-sampled STS3250 (4.88)."""
    for folder, log in LOGS:
        if log["trajectory"] != name:
            continue
        lag = MEDIAN_LAG_S[folder]
        diffs = sorted(abs(tr.sample(name, max(0.0, e["timestamp"] - lag))[0]
                           - math.degrees(e["goal_position"])) for e in log["entries"])
        assert diffs[len(diffs) // 2] < 0.02, (folder, log["kp"])
        assert diffs[-1] < (0.25 if folder == "dynamixel-xl330" else 5.0), (folder, log["kp"])


def test_bams_trajectories_at_hand_computed_times():
    assert tr.sample("lift_and_drop", 1.0)[0] == pytest.approx(-45.0)  # the cubic's middle
    assert tr.sample("lift_and_drop", 2.0)[0] == pytest.approx(-90.0)
    assert tr.sample("up_and_down", 1.5)[0] == pytest.approx(45.0)
    assert tr.sample("up_and_down", 3.0)[0] == pytest.approx(90.0)
    assert tr.sample("up_and_down", 4.5)[0] == pytest.approx(81.0)  # half way to 72
    assert tr.sample("up_and_down", 6.0)[0] == pytest.approx(72.0)
    assert tr.sample("sin_time_square", math.sqrt(math.pi / 2))[0] == pytest.approx(
        180.0 / math.pi)
    assert tr.sample("sin_sin", math.pi / 2)[0] == pytest.approx(90.0)  # sin(pi) = 0
    for name in BAM:
        assert tr.duration_s(name) == 6.0
        assert tr.start_deg(name) == pytest.approx(0.0, abs=1e-12)


def test_lift_and_drop_turns_the_torque_off_at_2_s_and_holds():
    assert tr.sample("lift_and_drop", 1.999) == (pytest.approx(-90.0, abs=1e-3), True)
    assert tr.sample("lift_and_drop", 2.0) == (-90.0, False)
    assert tr.sample("lift_and_drop", 6.0) == (-90.0, False)
    assert tr.sample("lift_and_drop", 60.0) == (-90.0, False)


def test_lift_and_drop_torque_flags_match_the_logs():
    """A log's flag was computed with its request, in the folder's window before the timestamp:
    on before 2 s, off from 2 s on; only entries whose window straddles 2 s may go either way."""
    for folder, log in LOGS:
        if log["trajectory"] != "lift_and_drop":
            continue
        lo, hi = LAG_WINDOW_S[folder]
        straddling = 0
        for e in log["entries"]:
            t = e["timestamp"]
            if t - lo < 2.0:
                assert e["torque_enable"] is tr.sample("lift_and_drop", t - lo)[1] is True
            elif t - hi >= 2.0:
                assert e["torque_enable"] is tr.sample("lift_and_drop", t - hi)[1] is False
            else:
                straddling += 1
        assert straddling <= 2, folder
        assert not log["entries"][-1]["torque_enable"]


@pytest.mark.parametrize("name", ("sin_time_square", "up_and_down", "sin_sin", "chirp",
                                  "steps"))
def test_the_others_keep_the_torque_on(name):
    ticks = int(tr.duration_s(name) * 100) + 100
    assert all(tr.sample(name, k / 100.0)[1] for k in range(ticks))
    assert all(e["torque_enable"] for _, log in LOGS if log["trajectory"] == name
               for e in log["entries"])


def test_amplitudes():
    assert tr.amplitude_deg("lift_and_drop") == pytest.approx((-90.0, 0.0))
    assert tr.amplitude_deg("up_and_down") == pytest.approx((0.0, 90.0))
    assert tr.amplitude_deg("sin_time_square") == pytest.approx((-180 / math.pi, 180 / math.pi),
                                                                abs=1e-3)
    assert tr.amplitude_deg("chirp") == pytest.approx((-25.0, 25.0), abs=1e-3)
    assert tr.amplitude_deg("steps") == (-45.0, 45.0)


def test_chirp_at_hand_computed_times():
    # phase / 2 pi = 0.5 t + (2.5 / 12) t^2: 0.708333 at 1 s (255 deg), 1.833333 at 2 s
    # (300 deg), 3.375 at 3 s (135 deg), 10.5 at 6 s (180 deg)
    assert tr.sample("chirp", 0.0) == (0.0, True)
    assert tr.sample("chirp", 1.0)[0] == pytest.approx(-24.148145, abs=1e-5)
    assert tr.sample("chirp", 2.0)[0] == pytest.approx(-21.650635, abs=1e-5)
    assert tr.sample("chirp", 3.0)[0] == pytest.approx(17.677670, abs=1e-5)
    assert tr.sample("chirp", 6.0)[0] == pytest.approx(0.0, abs=1e-9)
    assert tr.sample("chirp", 9.0) == tr.sample("chirp", 6.0)
    assert tr.duration_s("chirp") == 6.0


def test_chirp_is_continuous_and_reaches_top_speed_only_near_the_end():
    dt = 0.001
    speeds = [abs(tr.sample("chirp", (k + 1) * dt)[0] - tr.sample("chirp", k * dt)[0]) / dt
              for k in range(6000)]
    assert max(speeds) <= 2 * math.pi * 3.0 * 25.0 + 1e-6  # 471 deg/s at 3 Hz
    assert max(speeds) > 465.0
    assert max(speeds[:5000]) < 451.0  # the STS3250's top speed: not before 5 s
    assert max(speeds[5700:]) > 451.0


def test_steps_levels_and_holds():
    levels = [0, 5, 0, -5, 0, 20, 0, -20, 0, 45, 0, -45, 45, 0]
    assert tr.duration_s("steps") == 7.0
    for k, level in enumerate(levels):
        for t in (0.5 * k, 0.5 * k + 0.25, 0.5 * k + 0.499):
            assert tr.sample("steps", t) == (level, True), t
    assert tr.sample("steps", 7.0) == (0.0, True)
    assert tr.sample("steps", 100.0) == (0.0, True)
    assert tr.start_deg("steps") == 0.0


def test_steps_go_both_ways_in_several_sizes():
    mids = [tr.sample("steps", 0.5 * k + 0.25)[0] for k in range(14)]
    jumps = [b - a for a, b in zip(mids, mids[1:]) if b != a]
    for size in (5, 20, 45):
        assert size in jumps and -size in jumps, size
    assert 90 in jumps


def test_unknown_names_and_bad_times():
    message = ("unknown trajectory 'x' (valid: lift_and_drop, sin_time_square, up_and_down, "
               "sin_sin, chirp, steps)")
    for call in (tr.check_name, tr.duration_s, tr.start_deg, tr.amplitude_deg,
                 lambda n: tr.sample(n, 0.0)):
        with pytest.raises(ValueError) as raised:
            call("x")
        assert str(raised.value) == message
    assert tr.NAMES == ("lift_and_drop", "sin_time_square", "up_and_down", "sin_sin", "chirp",
                        "steps")
    for t in (-0.001, math.nan, math.inf):
        with pytest.raises(ValueError):
            tr.sample("sin_sin", t)
