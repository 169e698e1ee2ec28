"""leglab.Plant, Robot and Walk against the programs' own runs (the same bits), eq. 3 by hand
and hostile input."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import leglab
from conftest import TRACK_YAML, eq3, read_csv, run_program

SHORT = {"steps": 2, "warmup_steps": 1, "controller.modes": "[direct]"}
# Whether the build has DART (LEGLAB_WITH_DART; ctest sets it, tests/python/CMakeLists.txt).
WITH_DART = os.environ.get("LEGLAB_WITH_DART", "ON") == "ON"


def test_requests_of_trace_direct_reproduce_its_measured_angles(tmp_path):
    # track's direct mode requests the desired cycle from rest at its first pose on a fresh
    # plant; the same requests from Python on a plant of the same config give the same bits.
    run = run_program("track", "--config", TRACK_YAML, "--out", tmp_path, "--quiet",
                      *[f"--set={k}={v}" for k, v in SHORT.items()])
    assert run.returncode == 0, run.stderr
    trace = read_csv(tmp_path / "trace_direct.csv")
    walk = leglab.Walk(TRACK_YAML, SHORT)
    plant = leglab.Plant(TRACK_YAML, SHORT)
    plant.reset(walk.angles_deg[0])
    requests = np.tile(walk.angles_deg, (1 + 2, 1))  # warm-up step, then the two measured
    out = plant.run(requests)
    recorded = out["measured"][walk.period:]
    actual = trace["actual_deg"].reshape(-1, 3)  # one row per tick and joint, joint fastest
    assert np.array_equal(recorded, actual)
    assert np.array_equal(out["applied"][walk.period:], trace["request_deg"].reshape(-1, 3))


def test_tick_by_tick_is_run():
    walk = leglab.Walk(TRACK_YAML)
    requests = np.tile(walk.angles_deg, (2, 1))
    a, b = leglab.Plant(TRACK_YAML), leglab.Plant(TRACK_YAML)
    for p in (a, b):
        p.reset(walk.angles_deg[0])
    ticked = [a.tick(r) for r in requests]
    ran = b.run(requests)
    assert np.array_equal(np.array([r.measured for r in ticked]), ran["measured"])
    assert np.array_equal(np.array([r.true for r in ticked]), ran["true"])
    assert np.array_equal(np.array([r.applied for r in ticked]), ran["applied"])
    assert np.array_equal(a.reading.measured, b.reading.measured)


def test_same_seed_same_bits_other_seed_other_noise():
    requests = np.tile([20.0, 10.0, 30.0], (200, 1))
    runs = [leglab.Plant(TRACK_YAML, {"seed": s}).run(requests) for s in (5, np.uint64(5), 6)]
    assert np.array_equal(runs[0]["measured"], runs[1]["measured"])
    assert not np.array_equal(runs[0]["measured"], runs[2]["measured"])
    # The noise is in the sensor only: the motion itself is the same.
    assert np.array_equal(runs[0]["true"], runs[2]["true"])


@pytest.mark.skipif(not WITH_DART, reason="this build has no DART (LEGLAB_WITH_DART=OFF)")
def test_the_engine_is_an_override_and_the_driven_leg_does_not_depend_on_it():
    # The walk on both engines: the firmware drives the joints at its commanded speeds, so the
    # true angles agree far inside the sensor's 0.1 deg of noise; the same seed, the same bits
    # on DART too.
    walk = leglab.Walk(TRACK_YAML)
    requests = np.tile(walk.angles_deg, (2, 1))
    runs = {}
    for engine in ("ode", "dart", "dart"):
        plant = leglab.Plant(TRACK_YAML, {"sim.engine": engine})
        plant.reset(walk.angles_deg[0])
        runs.setdefault(engine, []).append(plant.run(requests))
    assert np.array_equal(runs["dart"][0]["measured"], runs["dart"][1]["measured"])
    assert np.max(np.abs(runs["dart"][0]["true"] - runs["ode"][0]["true"])) < 0.01
    assert not np.array_equal(runs["dart"][0]["true"], runs["ode"][0]["true"])


def test_an_engine_not_built_or_unknown_is_a_value_error_naming_the_key():
    if not WITH_DART:
        refusal = "^config: sim.engine: dart, but this build of leglab has no DART"
        with pytest.raises(ValueError, match=refusal):
            leglab.Plant(TRACK_YAML, {"sim.engine": "dart"})
    with pytest.raises(ValueError, match="sim.engine must be ode or dart, got 'bullet'"):
        leglab.Plant(TRACK_YAML, {"sim.engine": "bullet"})


def test_the_model_plant_is_eq3():
    plant = leglab.Plant(TRACK_YAML, {"plant": "model"})
    assert plant.name == "model"
    plant.reset([0.0, 0.0, 0.0])
    rng = np.random.default_rng(3)
    requests = np.clip(np.cumsum(rng.normal(0.0, 4.0, (150, 3)), axis=0), -10.0, 80.0)
    got = plant.run(requests)["measured"]
    for j in range(3):
        want = eq3(2.5, 7.0, 4, 6, requests[:, j], 0.0)  # plant_model's default: Table 1
        np.testing.assert_allclose(got[:, j], want, rtol=0, atol=1e-9)


def test_requests_are_clamped_into_the_limits():
    plant = leglab.Plant(TRACK_YAML)
    limits = plant.robot.limits_deg
    reading = plant.tick([500.0, -500.0, 0.0])
    assert list(reading.applied) == [limits[0, 1], limits[1, 0], 0.0]


def test_change_settings_changes_the_servo_and_refuses_bad_keys():
    requests = np.tile([30.0, 0.0, 30.0], (60, 1))
    slow = leglab.Plant(TRACK_YAML)
    slow.change_settings({"servo.max_speed_deg_s": 100.0})
    reference = leglab.Plant(TRACK_YAML, {"servo.max_speed_deg_s": 100})
    assert np.array_equal(slow.run(requests)["true"], reference.run(requests)["true"])
    plant = leglab.Plant(TRACK_YAML)
    for bad, message in [({"servo.nope": 1.0}, "servo.nope"),
                         ({"servo.max_speed_deg_s": -1.0}, "max_speed"),
                         # The config's ranges and rules, as track's plant_changes checks them.
                         ({"servo.delay_ms": 80000}, r"servo.delay_ms must be in \[0, 400\] ms"),
                         ({"sensor.noise_deg": 1e9}, r"sensor.noise_deg must be in \[0, 2\] deg"),
                         ({"servo.smoothing_ms": 400000}, "servo.smoothing_ms must be in"),
                         ({"servo.smoothing_ms": 12}, "multiple of 8 ms"),
                         ({"servo.max_torque_nm": 1e6}, "servo.max_torque_nm must be in")]:
        with pytest.raises(ValueError, match=message):
            plant.change_settings(bad)
    # A wrong type is a TypeError (ValueError before the package followed Python's convention
    # everywhere; CHANGELOG.md, Changed).
    for bad, message in [({"servo.delay_ms": "x"}, "servo.delay_ms"),
                         ({"servo.delay_ms": True},
                          "servo.delay_ms: expected one number, got bool"),
                         ({"servo.delay_ms": [8]}, "servo.delay_ms: expected one number, got list"),
                         ({1: 8}, "a key is not a str"),
                         ([1, 2], "dict")]:
        with pytest.raises(TypeError, match=message):
            plant.change_settings(bad)
    # Refused settings left it as it was.
    assert np.array_equal(plant.run(requests)["true"],
                          leglab.Plant(TRACK_YAML).run(requests)["true"])


def test_robot_and_walk():
    walk = leglab.Walk(TRACK_YAML)
    robot = leglab.Robot(TRACK_YAML)
    assert walk.period == 88 and walk.angles_deg.shape == (88, 3)
    feet = robot.foot_mm(walk.angles_deg)
    np.testing.assert_allclose(feet, walk.foot_mm, rtol=0, atol=1e-9)
    assert np.array_equal(feet[5], robot.foot_mm(walk.angles_deg[5]))
    # Thigh and shin of the ERS-210A's front leg: the foot at q = 0 hangs below the shoulder
    # by their lengths (69.5 mm and 76.4 mm in the URDF, with its small offsets).
    hanging = robot.foot_mm([0.0, 0.0, 0.0])
    assert -160.0 < hanging[2] < -120.0
    assert robot.name == "ers210a_front_left_leg"
    assert robot.limits_deg.shape == (3, 2)
    assert "servo:" in leglab.Plant(TRACK_YAML).config_yaml


HOSTILE = [
    (lambda p: p.tick([1.0, 2.0]), r"shape \(2,\)"),
    (lambda p: p.tick([1.0, float("nan"), 2.0]), "abductor's angle is nan"),
    (lambda p: p.tick([1.0, float("inf"), 2.0]), "abductor's angle is inf"),
    (lambda p: p.tick(np.zeros(3, dtype=complex)), "dtype complex128"),
    (lambda p: p.tick(["a", "b", "c"]), "dtype"),
    (lambda p: p.tick([True, False, True]), "dtype bool"),
    (lambda p: p.tick([[1.0], [2.0, 3.0]]), "not an array of numbers"),
    (lambda p: p.run(np.zeros((10, 2))), r"shape \(T, 3\)"),
    (lambda p: p.run(np.array([[0.0, 0.0, 0.0], [0.0, 0.0, np.nan]])), r"requests\[1, 2\]"),
    (lambda p: p.reset([0.0, 0.0, 400.0]), "knee"),
    (lambda p: p.reset([0.0, np.nan, 0.0]), "abductor"),
]


@pytest.mark.parametrize("call, message", HOSTILE)
def test_hostile_input_is_a_one_line_value_error(call, message):
    plant = leglab.Plant(TRACK_YAML)
    with pytest.raises(ValueError, match=message) as error:
        call(plant)
    assert "\n" not in str(error.value)


# No array at all is a TypeError (ValueError "dtype object" before the package followed Python's
# convention everywhere; CHANGELOG.md, Changed).
@pytest.mark.parametrize("call, message", [
    (lambda p: p.tick(None), "request: expected an array of numbers, got NoneType"),
    (lambda p: p.tick("abc"), "request: expected an array of numbers, got str"),
    (lambda p: p.run({}), "requests: expected an array of numbers, got dict"),
    (lambda p: p.reset(object()), "pose: expected an array of numbers, got object"),
])
def test_an_argument_that_is_no_array_is_a_one_line_type_error(call, message):
    plant = leglab.Plant(TRACK_YAML)
    with pytest.raises(TypeError, match=message) as error:
        call(plant)
    assert "\n" not in str(error.value)


def test_a_refused_run_ticks_nothing():
    plant, fresh = leglab.Plant(TRACK_YAML), leglab.Plant(TRACK_YAML)
    bad = np.zeros((50, 3))
    bad[49, 0] = np.nan
    with pytest.raises(ValueError):
        plant.run(bad)
    requests = np.tile([10.0, 10.0, 10.0], (30, 1))
    assert np.array_equal(plant.run(requests)["true"], fresh.run(requests)["true"])


@pytest.mark.parametrize("overrides, message", [
    ({"nope": 1}, "unknown key 'nope'"),
    ({"servo.delay_ms": 7}, "servo.delay_ms"),
    ({"servo.delay_ms": float("nan")}, "servo.delay_ms"),
    ({"servo.delay_ms": None}, "servo.delay_ms must be a value, not null"),
    ({"servo.delay_ms": ""}, "servo.delay_ms must be a value, not null"),
    ({"plant": "bogus"}, "plant"),
    ({"robot": "no_such_robot"}, "no_such_robot"),
    ({"urdf": "/no/such.urdf"}, "such.urdf"),
])
def test_bad_configs_are_value_errors_naming_the_key(overrides, message):
    with pytest.raises(ValueError, match=message) as error:
        leglab.Plant(TRACK_YAML, overrides)
    assert "\n" not in str(error.value)


# Overrides of the wrong type: TypeError (ValueError before the package followed Python's
# convention everywhere; CHANGELOG.md, Changed).
@pytest.mark.parametrize("overrides, message", [
    ({1: 2}, "config key"),
    ("steps=2", "dict"),
    ({"steps": object()}, "steps = <object"),
])
def test_overrides_of_the_wrong_type_are_type_errors_naming_them(overrides, message):
    with pytest.raises(TypeError, match=message) as error:
        leglab.Plant(TRACK_YAML, overrides)
    assert "\n" not in str(error.value)


def test_bad_config_files_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="missing.yaml"):
        leglab.Plant(tmp_path / "missing.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("servo: [\n")
    with pytest.raises(ValueError, match="broken.yaml"):
        leglab.Plant(broken)
    # Not a path at all: TypeError (ValueError before; CHANGELOG.md, Changed).
    with pytest.raises(TypeError, match="path"):
        leglab.Plant(42)


def test_hostile_calls_never_crash_the_interpreter():
    # Everything above and a few more in a fresh interpreter: it must end normally.
    script = textwrap.dedent(f"""
        import numpy as np, leglab
        p = leglab.Plant({TRACK_YAML!r}, {{"plant": "model"}})
        calls = [lambda: p.tick(np.zeros((3, 3))), lambda: p.tick(np.zeros(0)),
                 lambda: p.run(np.zeros((0, 3))), lambda: p.run(np.zeros((5, 3))[:, ::2]),
                 lambda: p.tick(np.array([1, 2, 3], dtype=np.int8)),
                 lambda: p.run(np.ones((4, 3), dtype=np.float32)),
                 lambda: p.tick(np.ones(6)[::2]), lambda: p.change_settings({{"x": [1]}}),
                 lambda: leglab.identify([], []), lambda: leglab.floor([], leglab.PAPER_MODEL),
                 lambda: leglab.JointModel(1e308, 1e-308, 10**6, 10**6)]
        for call in calls:
            try:
                call()
            except (ValueError, TypeError, OverflowError):
                pass
        print("alive")
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            check=False)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "alive"


def test_a_copy_there_is_no_memory_for_is_a_memory_error_not_a_crash():
    # A float32 array under the size bound whose float64 copy does not fit under the
    # address-space limit (set 200 MB above what the process holds): numpy's conversion fails,
    # and the call raises MemoryError naming the argument.
    script = textwrap.dedent(f"""
        import resource, numpy as np, leglab
        p = leglab.Plant({TRACK_YAML!r}, {{"plant": "model"}})
        big = np.ones((3 * 10**7, 3), np.float32)
        size = next(int(line.split()[1]) * 1024 for line in open("/proc/self/status")
                    if line.startswith("VmSize:"))
        resource.setrlimit(resource.RLIMIT_AS, (size + 200_000_000, size + 200_000_000))
        for name, call in [("run", lambda: p.run(big)),
                           ("floor", lambda: leglab.floor(big[:, 0], leglab.PAPER_MODEL)),
                           ("simulate", lambda: leglab.PAPER_MODEL.simulate(big[:, 0], 0.0))]:
            try:
                call()
                print(name, "returned")
            except MemoryError as e:
                print(name, "MemoryError", str(e).splitlines()[0])
    """)
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                            check=False)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.strip().splitlines()
    assert [line.split()[:2] for line in lines] == [
        ["run", "MemoryError"], ["floor", "MemoryError"], ["simulate", "MemoryError"]], lines
    assert "requests: no memory for a float64 copy of 90000000 values" in lines[0], lines


def test_an_array_over_the_size_bound_is_refused_before_its_copy():
    # A broadcast view of 10^9 rows costs nothing to make; its copy would be 24 GB.
    plant = leglab.Plant(TRACK_YAML, {"plant": "model"})
    huge = np.broadcast_to(np.zeros(3), (10**9, 3))
    with pytest.raises(ValueError, match="requests: 3000000000 values, over the limit of 100000000"):
        plant.run(huge)
    with pytest.raises(ValueError, match="desired_cycle: 1000000000 values, over the limit"):
        leglab.floor(huge[:, 0], leglab.PAPER_MODEL)


def test_docstrings_read_well():
    for thing in (leglab.Plant, leglab.Plant.tick, leglab.Plant.run, leglab.Plant.reset,
                  leglab.Plant.change_settings, leglab.Reading, leglab.Robot, leglab.Walk,
                  leglab.JointModel, leglab.identify, leglab.floor):
        assert thing.__doc__ and len(thing.__doc__) > 40, thing
    assert "8 ms" in leglab.Plant.__doc__
