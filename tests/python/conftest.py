"""Shared fixtures of the Python package's tests: the package itself (skipped with the reason
when it was not built), the build folder, and a reference implementation of eq. 3 written
here from the paper, independent of the C++ code under test."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

leglab = pytest.importorskip(
    "leglab",
    reason="the leglab Python package was not built (LEGLAB_PYTHON OFF: pybind11-dev and "
    "python3-dev are needed); PYTHONPATH must hold <build>/python")

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
BUILD_DIR = pathlib.Path(os.environ.get("LEGLAB_BUILD_DIR", SOURCE_DIR / "build"))
TRACK_YAML = str(SOURCE_DIR / "experiments" / "configs" / "track.yaml")


def eq3(v_max, theta0, lag, accel, requests, start):
    """The paper's eq. 3 from rest at `start`, tick by tick, as the paper writes it:
    M(t) = M(t-1) + (1/a) sum_{i=l+1}^{l+a} f(R(t-i) - M(t-1)), f linear with slope
    v_max / theta0 inside +-theta0 and saturated at +-v_max outside (eq. 2); requests before
    t = 0 equal `start`."""
    def f(x):
        return max(-v_max, min(v_max, x * v_max / theta0))

    history = {}
    angle = start
    out = []
    for t, r in enumerate(requests):
        history[t] = r
        total = 0.0
        for i in range(lag + 1, lag + accel + 1):
            total += f(history.get(t - i, start) - angle)
        angle = angle + total / accel
        out.append(angle)
    return np.array(out)


def run_program(program, *args):
    """Runs build/bin/<program> with `args`; returns the CompletedProcess (text)."""
    return subprocess.run([str(BUILD_DIR / "bin" / program), *map(str, args)],
                          capture_output=True, text=True, check=False)


def read_csv(path):
    """A CSV file as {column: numpy array} (numbers as float64, text as str)."""
    import csv
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    columns = {}
    for c, name in enumerate(rows[0]):
        cells = [row[c] for row in rows[1:]]
        try:
            columns[name] = np.array([float(x) for x in cells])
        except ValueError:
            columns[name] = np.array(cells)
    return columns
