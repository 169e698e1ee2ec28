"""Excitation trajectories: the requests a recorder sends a servo swinging a pendulum load.

Each trajectory is a pure function of the time since its start: sample(name, t_s) gives
(request_deg, torque_enabled). Angles are degrees from the load's hanging zero (positive and
negative as the shipped logs in data/servo_logs/ count them); times are seconds. Past its
duration a trajectory holds its last value (request and torque flag).

Four are BAM's ("BAM: Better Actuator Models", Duclusaud, Passault, Padois and Ly, ICRA 2025;
Apache License 2.0), on which the shipped logs were recorded; their math is taken from
github.com/Rhoban/bam, bam/trajectory.py (identical at the logs' commits af22604 and d13c057
and at 1b5a1ce), where they are in radians; here they are converted to degrees:

- lift_and_drop: a cubic from 0 to -90 deg over 2 s (zero slope at both ends), then the
  torque off from 2 s on (the pendulum falls); the request stays -90 deg.
- sin_time_square: sin(t^2) rad, a sine ever faster (about 57.3 deg amplitude).
- up_and_down: cubics 0 -> 90 deg over 0..3 s, then 90 -> 72 deg over 3..6 s.
- sin_sin: sin(t) * pi/2 + sin(5 t) * 0.5 * sin(2 t) rad.

Two are leglab's own:

- chirp: 25 deg * sin(phase), the frequency sweeping linearly from 0.5 Hz to 3 Hz over 6 s.
  The request's speed peaks at 2 pi f * 25 deg: 471 deg/s at 3 Hz, above the STS3250's
  published no-load speed (451 deg/s at 12 V), which it passes from about 5.7 s on, so a fit
  sees the top speed near the end, after the lag and gain at low frequency. The phase at 6 s is
  21 pi, so it starts and ends at 0 deg (continuous with the rest before and the hold after);
  its slope jumps from 0 to 78.5 deg/s at the start, as sin_sin's does (90 deg/s).
- steps: 0.5 s holds at 0, 5, 0, -5, 0, 20, 0, -20, 0, 45, 0, -45, 45, 0 deg (7 s): steps of
  5, 20 and 45 deg each way (lag and gain, acceleration) and one 90 deg step through zero
  (top speed). Piecewise constant: each level holds from its start (inclusive) to the next.

All keep the torque on throughout except lift_and_drop after 2 s.
Standard library only; no import of the compiled module.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable
from typing import Union

NAMES: tuple[str, ...] = ("lift_and_drop", "sin_time_square", "up_and_down", "sin_sin", "chirp",
                          "steps")

_BAM_DURATION_S = 6.0  # every BAM trajectory lasts 6 s
_DROP_S = 2.0  # lift_and_drop: torque off from here on
_CHIRP_AMPLITUDE_DEG = 25.0
_CHIRP_F0_HZ = 0.5
_CHIRP_F1_HZ = 3.0
_CHIRP_DURATION_S = 6.0
_STEP_HOLD_S = 0.5
_STEP_LEVELS_DEG = (0.0, 5.0, 0.0, -5.0, 0.0, 20.0, 0.0, -20.0, 0.0, 45.0, 0.0, -45.0, 45.0, 0.0)
_AMPLITUDE_TICK_S = 0.001  # amplitude_deg's sampling step


def _ease(t_s: float, t0_s: float, x0: float, t1_s: float, x1: float) -> float:
    """The cubic from x0 at t0_s to x1 at t1_s with zero slope at both ends (BAM's keyframes)."""
    s = (t_s - t0_s) / (t1_s - t0_s)
    return x0 + (x1 - x0) * s * s * (3.0 - 2.0 * s)


def _lift_and_drop_rad(t_s: float) -> float:
    """BAM's LiftAndDrop: 0 -> -pi/2 rad over 2 s, then held (rad)."""
    return _ease(min(t_s, _DROP_S), 0.0, 0.0, _DROP_S, -math.pi / 2)


def _sin_time_square_rad(t_s: float) -> float:
    """BAM's SinusTimeSquare: sin(t^2) (rad)."""
    return math.sin(t_s * t_s)


def _up_and_down_rad(t_s: float) -> float:
    """BAM's UpAndDown: 0 -> pi/2 rad over 0..3 s, then -> 0.8 pi/2 rad over 3..6 s (rad)."""
    if t_s <= 3.0:
        return _ease(t_s, 0.0, 0.0, 3.0, math.pi / 2)
    return _ease(t_s, 3.0, math.pi / 2, 6.0, 0.8 * math.pi / 2)


def _sin_sin_rad(t_s: float) -> float:
    """BAM's SinSin: sin(t) pi/2 + sin(5 t) 0.5 sin(2 t) (rad)."""
    return math.sin(t_s) * math.pi / 2 + math.sin(5.0 * t_s) * 0.5 * math.sin(2.0 * t_s)


def _chirp_deg(t_s: float) -> float:
    """25 deg sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T))): f0 = 0.5 Hz to f1 = 3 Hz over T = 6 s."""
    sweep = (_CHIRP_F1_HZ - _CHIRP_F0_HZ) / (2.0 * _CHIRP_DURATION_S)
    cycles = _CHIRP_F0_HZ * t_s + sweep * t_s * t_s
    return _CHIRP_AMPLITUDE_DEG * math.sin(2.0 * math.pi * cycles)


def _steps_deg(t_s: float) -> float:
    """The level held at t_s: _STEP_LEVELS_DEG[k] over [k, k + 1) * 0.5 s (deg)."""
    k = min(int(t_s / _STEP_HOLD_S), len(_STEP_LEVELS_DEG) - 1)
    return _STEP_LEVELS_DEG[k]


# name: (request in deg at t within the duration, duration in s)
_TRAJECTORIES: dict[str, tuple[Callable[[float], float], float]] = {
    "lift_and_drop": (lambda t: math.degrees(_lift_and_drop_rad(t)), _BAM_DURATION_S),
    "sin_time_square": (lambda t: math.degrees(_sin_time_square_rad(t)), _BAM_DURATION_S),
    "up_and_down": (lambda t: math.degrees(_up_and_down_rad(t)), _BAM_DURATION_S),
    "sin_sin": (lambda t: math.degrees(_sin_sin_rad(t)), _BAM_DURATION_S),
    "chirp": (_chirp_deg, _CHIRP_DURATION_S),
    "steps": (_steps_deg, _STEP_HOLD_S * len(_STEP_LEVELS_DEG)),
}


def check_name(name: str) -> None:
    """Checks a trajectory's name.

    Parameters
    ----------
    name : str
        The name.

    Raises
    ------
    TypeError
        `name` not a str.
    ValueError
        `name` not one of NAMES, naming the valid trajectories.
    """
    if not isinstance(name, str):
        raise TypeError(f"trajectory: expected a str ({', '.join(NAMES)}), got "
                        f"{type(name).__name__}")
    if name not in NAMES:
        raise ValueError(f"unknown trajectory {name!r} (valid: {', '.join(NAMES)})")


def duration_s(name: str) -> float:
    """A trajectory's duration; after it, sample holds the last value.

    Parameters
    ----------
    name : str
        One of NAMES.

    Returns
    -------
    float
        The duration, s.

    Raises
    ------
    TypeError, ValueError
        As check_name.
    """
    check_name(name)
    return _TRAJECTORIES[name][1]


def sample(name: str, t_s: float) -> tuple[float, bool]:
    """A trajectory's request and torque flag at a time.

    Beyond duration_s(name) the value at the duration is held.

    Parameters
    ----------
    name : str
        One of NAMES.
    t_s : float
        Seconds from the start, finite and >= 0.

    Returns
    -------
    request_deg : float
        Degrees from the load's hanging zero.
    torque_enabled : bool
        Whether the torque is on.

    Raises
    ------
    TypeError
        `name` not a str, `t_s` not a number.
    ValueError
        An unknown name, `t_s` negative or not finite.
    """
    check_name(name)
    if isinstance(t_s, bool) or not isinstance(t_s, (int, float)):
        raise TypeError(f"trajectory time: expected a number of seconds, got "
                        f"{type(t_s).__name__}")
    if not (math.isfinite(t_s) and t_s >= 0.0):
        raise ValueError(f"trajectory time must be finite and >= 0 s, got {t_s!r}")
    request, duration = _TRAJECTORIES[name]
    t_s = min(t_s, duration)
    torque = not (name == "lift_and_drop" and t_s >= _DROP_S)
    return float(request(t_s)), torque


def start_deg(name: str) -> float:
    """Where to hold the load before a trajectory starts.

    Parameters
    ----------
    name : str
        One of NAMES.

    Returns
    -------
    float
        The request at t = 0, deg.

    Raises
    ------
    TypeError, ValueError
        As check_name.
    """
    return sample(name, 0.0)[0]


def amplitude_deg(name: str) -> tuple[float, float]:
    """A trajectory's range of requests, sampled every 1 ms and at the end.

    Parameters
    ----------
    name : str
        One of NAMES.

    Returns
    -------
    (float, float)
        The least and the greatest request over [0, duration], deg.

    Raises
    ------
    TypeError, ValueError
        As check_name.
    """
    duration = duration_s(name)
    ticks = int(round(duration / _AMPLITUDE_TICK_S))
    values = [sample(name, min(k * _AMPLITUDE_TICK_S, duration))[0] for k in range(ticks + 1)]
    return min(values), max(values)


def pick_and_place_deg(tick_s: float = 0.005,
                       poses_deg: tuple[float, ...] = (0.0, 50.0, -30.0, 0.0),
                       move_s: float = 0.5, hold_s: float = 0.4) -> list[float]:
    """A desired motion, not an excitation: the motion the docs' and tests' runs follow, which
    no excitation holds.

    Parameters
    ----------
    tick_s : float, optional
        The tick, s.
    poses_deg : tuple of float, optional
        The poses, deg from the zero.
    move_s : float, optional
        Each move's time: an eased move (smoothstep: no speed at either end).
    hold_s : float, optional
        Each hold's time, after each move and at the first pose.

    Returns
    -------
    list of float
        One angle a tick, deg.
    """
    moves = round(move_s / tick_s)
    ease = [3 * s ** 2 - 2 * s ** 3 for s in (k / moves for k in range(1, moves + 1))]
    hold = round(hold_s / tick_s)
    out = [poses_deg[0]] * hold
    for start, end in zip(poses_deg, poses_deg[1:]):
        out += [start + (end - start) * e for e in ease] + [end] * hold
    return out


def write_desired_csv(path: Union[str, os.PathLike[str]], desired_deg: Iterable[float],
                      tick_s: float = 0.005) -> None:
    """Writes a desired motion as the desired CSV `plan` and `run` read.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    desired_deg : iterable of float
        One angle a tick, deg.
    tick_s : float, optional
        The tick, s.

    Raises
    ------
    OSError
        The file cannot be written.

    Notes
    -----
    The columns are time_s,desired_deg, each number the shortest text that reads back as the
    same double.
    """
    with open(path, "w", encoding="ascii") as f:
        f.write("time_s,desired_deg\n")
        f.writelines(f"{k * tick_s!r},{float(d)!r}\n" for k, d in enumerate(desired_deg))
