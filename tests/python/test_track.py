"""leglab.run_track against the `track` program (the same numbers, the same files) and
controllers written in Python run beside the built-in modes."""

import json
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import leglab
from conftest import TRACK_YAML, read_csv, run_program

SHORT = {"steps": 3, "warmup_steps": 1, "controller.modes": "[direct, model_based]"}


class PyDirect(leglab.Controller):
    """The built-in direct mode, written in Python."""
    name = "py_direct"

    def reset(self, context):
        self.desired = context.desired

    def request(self, tick, measured):
        return self.desired[tick % len(self.desired)]


def program_run(tmp_path, overrides=None):
    out = tmp_path / "program"
    args = [f"--set={k}={v}" for k, v in (overrides or {}).items()]
    run = run_program("track", "--config", TRACK_YAML, "--out", out, "--quiet", *args)
    assert run.returncode == 0, run.stderr
    return out


def test_run_track_is_track(tmp_path):
    out = program_run(tmp_path)
    result = leglab.run_track(TRACK_YAML)
    assert result.table2 == json.loads((out / "table2.json").read_text())
    assert set(result.traces) == {"direct", "time_shift", "model_based", "optimal", "ilc"}
    for mode in result.traces:
        for kind, tables in (("trace", result.traces), ("foot", result.feet)):
            written = read_csv(out / f"{kind}_{mode}.csv")
            assert list(tables[mode]) == list(written)
            for column, values in written.items():
                assert np.array_equal(tables[mode][column], values), (mode, kind, column)
    assert result.markdown == (out / "table2.md").read_text()
    assert result.config_yaml in (out / "track_config.yaml").read_text()
    for joint in leglab.JOINT_NAMES:
        model = result.models[joint].to_dict()
        assert {k: result.table2["model"][joint][k] for k in model} == model


def test_out_writes_what_track_writes(tmp_path):
    out = program_run(tmp_path, SHORT)
    mine = tmp_path / "mine"
    leglab.run_track(TRACK_YAML, SHORT, out=mine)
    written = sorted(p.name for p in mine.iterdir())
    assert written == sorted(p.name for p in out.iterdir())
    for name in written:
        assert (mine / name).read_bytes() == (out / name).read_bytes(), name


def test_a_python_direct_controller_is_the_direct_row():
    result = leglab.run_track(TRACK_YAML, SHORT, controllers=[PyDirect()])
    foot = result.table2["foot_cm"]
    assert foot["py_direct"] == foot["direct"]
    for joint in leglab.JOINT_NAMES:
        rows = result.table2["joints"][joint]
        assert rows["L2(Des,py_direct)"] == rows["L2(Des,Dir)"]
        assert rows["Linf(Des,py_direct)"] == rows["Linf(Des,Dir)"]
    for column in ("request_deg", "actual_deg"):
        assert np.array_equal(result.traces["py_direct"][column], result.traces["direct"][column])
    assert "py_direct" in result.markdown


def test_same_seed_same_bits_any_thread_count():
    one = leglab.run_track(TRACK_YAML, SHORT, controllers=[PyDirect()], threads=1)
    two = leglab.run_track(TRACK_YAML, SHORT, controllers=[PyDirect()], threads=2)
    assert one.table2 == two.table2
    other = leglab.run_track(TRACK_YAML, {**SHORT, "seed": 9}, controllers=[PyDirect()])
    assert other.table2["foot_cm"]["py_direct"] != one.table2["foot_cm"]["py_direct"]


def test_the_hooks_are_called_as_documented():
    class Recorder(PyDirect):
        name = "recorder"

        def reset(self, context):
            super().reset(context)
            self.context, self.ticks, self.steps, self.seen = context, [], [], []

        def request(self, tick, measured):
            self.ticks.append(tick)
            return np.array([500.0, 0.0, 0.0]) if tick == 7 else super().request(tick, measured)

        def observe(self, request, reading):
            self.seen.append((request, reading))

        def end_of_step(self, step):
            self.steps.append(step)

    recorder = Recorder()
    leglab.run_track(TRACK_YAML, SHORT, controllers=recorder)
    period = recorder.context.period
    assert recorder.ticks == list(range(4 * period))  # one warm-up step and three measured
    assert recorder.steps == [0, 1, 2, 3]
    assert len(recorder.seen) == 4 * period
    request, reading = recorder.seen[7]
    assert request[0] == recorder.context.limits_deg[0, 1]  # clamped, as the servo took it
    assert np.isnan(reading.true).all() and np.isfinite(reading.measured).all()
    c = recorder.context
    assert c.desired.shape == (period, 3) and c.warmup_steps == 1
    assert len(c.models) == 3 and isinstance(c.models[0], leglab.JointModel)
    np.testing.assert_allclose(c.foot_mm(c.desired[3]), c.desired_foot_mm[3], atol=1e-12)
    assert c.approximation.shape == (period, 3)


class Boom(Exception):
    pass


def test_what_a_controller_raises_comes_out_unchanged():
    class Broken(PyDirect):
        name = "broken"

        def request(self, tick, measured):
            if tick == 30:
                raise Boom("at tick 30")
            return super().request(tick, measured)

    with pytest.raises(Boom, match="at tick 30"):
        leglab.run_track(TRACK_YAML, SHORT, controllers=[Broken()])


@pytest.mark.parametrize("controller, message", [
    (type("NaN", (PyDirect,), {"name": "nan", "request": lambda s, t, m: [0.0, np.nan, 0.0]}),
     r"controller 'nan': request\(tick 0\): the abductor's angle is nan"),
    (type("Short", (PyDirect,), {"name": "short", "request": lambda s, t, m: [0.0, 1.0]}),
     r"controller 'short': request\(tick 0\): expected 3 angles"),
    (type("Clash", (PyDirect,), {"name": "direct"}), "direct"),
    (type("Spaced", (PyDirect,), {"name": "My Ctrl"}), "My Ctrl"),
    (type("Nameless", (PyDirect,), {"name": None}), "name"),
])
def test_bad_controllers_are_one_line_value_errors(controller, message):
    with pytest.raises(ValueError, match=message) as error:
        leglab.run_track(TRACK_YAML, SHORT, controllers=[controller()])
    assert "\n" not in str(error.value)


# Types: a controller's request that is no array, or controllers that are not Controllers,
# are TypeErrors (the first was ValueError "dtype" before the package followed Python's
# convention everywhere; CHANGELOG.md, Changed).
@pytest.mark.parametrize("controllers, message", [
    ([type("Text", (PyDirect,), {"name": "text", "request": lambda s, t, m: "abc"})()],
     r"controller 'text': request\(tick 0\): expected an array of numbers, got str"),
    ("direct", "controllers: expected a sequence of Controller, got str"),
    ([3], "controllers: expected Controller instances, got int"),
])
def test_controllers_of_the_wrong_type_are_one_line_type_errors(controllers, message):
    with pytest.raises(TypeError, match=message) as error:
        leglab.run_track(TRACK_YAML, SHORT, controllers=controllers)
    assert "\n" not in str(error.value)


def test_two_controllers_of_one_name_are_refused_before_any_run(tmp_path):
    with pytest.raises(ValueError, match="py_direct"):
        leglab.run_track(TRACK_YAML, SHORT, controllers=[PyDirect(), PyDirect()],
                         out=tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_bad_config_is_a_value_error_and_writes_nothing(tmp_path):
    with pytest.raises(ValueError, match="steps"):
        leglab.run_track(TRACK_YAML, {"steps": -1}, out=tmp_path / "out")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("threads, error, message", [
    (1.5, TypeError, "threads: expected an integer, got float 1.5"),
    (True, TypeError, "threads: expected an integer, got bool"),
    (-1, ValueError, r"threads must be an integer in \[0, 4096\], got -1"),
    (2**80, ValueError, r"threads must be an integer in \[0, 4096\]"),
])
def test_a_bad_thread_count_is_one_line_and_runs_nothing(tmp_path, threads, error, message):
    with pytest.raises(error, match=message) as raised:
        leglab.run_track(TRACK_YAML, SHORT, threads=threads, out=tmp_path / "out")
    assert "\n" not in str(raised.value)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("signal_number", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_during_run_track_leaves_nothing_behind(tmp_path, signal_number):
    # A child runs a long track into out=; the signal comes mid-run. SIGTERM still ends the
    # process as a SIGTERM, SIGINT is a KeyboardInterrupt, and neither leaves the staging
    # folder, the lock or the folder itself.
    out = tmp_path / "out"
    script = textwrap.dedent(f"""
        import sys, leglab
        print("running", flush=True)
        try:
            leglab.run_track({TRACK_YAML!r}, {{"steps": 5000, "controller.modes": "[direct]"}},
                             out={str(out)!r}, threads=1)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", flush=True)
            sys.exit(0)
        print("finished", flush=True)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline().strip() == "running"
    time.sleep(1.5)  # well into the run (identification, then steps: about 10 ms each)
    child.send_signal(signal_number)
    output, errors = child.communicate(timeout=120)
    if signal_number == signal.SIGTERM:
        assert child.returncode == -signal.SIGTERM, (output, errors)
    else:
        assert child.returncode == 0 and output.strip() == "KeyboardInterrupt", (output, errors)
    assert sorted(p.name for p in tmp_path.iterdir()) == [], list(tmp_path.iterdir())
