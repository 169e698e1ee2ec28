"""leglab.JointModel, identify and floor against eq. 3 written out here, brute force and the
`identify` program's own fit."""

import json
import pickle
import re

import numpy as np
import pytest

import leglab
from conftest import TRACK_YAML, eq3, read_csv, run_program


def test_simulate_is_eq3_by_hand():
    rng = np.random.default_rng(7)
    requests = np.cumsum(rng.normal(0.0, 6.0, 300))
    for params in [(2.5, 7.0, 4, 3), (1.0, 0.6, 0, 1), (3.3, 20.0, 7, 5)]:
        model = leglab.JointModel(*params)
        got = model.simulate(requests, 5.0)
        want = eq3(*params, requests, 5.0)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)


def test_a_step_by_hand():
    # Table 1's joint (l 4, a 6) asked 10 deg from rest at 0: R(0) first acts at tick l + 1 = 5,
    # as one of the a terms averaged, f(10 - 0) = 2.5 at top speed, the others f(0) = 0.
    assert (leglab.PAPER_MODEL.lag_ticks, leglab.PAPER_MODEL.accel_ticks) == (4, 6)
    m = leglab.PAPER_MODEL.simulate([10.0] * 6, 0.0)
    assert list(m[:5]) == [0.0] * 5
    assert m[5] == pytest.approx(2.5 / 6, abs=1e-15)


def test_the_papers_tables_as_published():
    # Stronger & Stone, Table 2 and the foot table, typed from the paper.
    assert leglab.PAPER_TABLE2 == {
        "L2(Des,Dir)": (31.0, 29.0, 20.1), "Linf(Des,Dir)": (57.2, 59.5, 42.6),
        "L2(Des,MB)": (9.1, 10.4, 5.6), "Linf(Des,MB)": (29.4, 24.5, 11.1),
        "L2(Pwl,MB)": (2.7, 2.7, 2.6), "Linf(Pwl,MB)": (6.4, 6.0, 6.2)}
    assert leglab.PAPER_FOOT_CM["direct"] == {"L2": {"mean": 3.23, "std": 0.01},
                                              "Linf": {"mean": 4.61, "std": 0.05}}
    assert leglab.PAPER_FOOT_CM["time_shift"]["L2"]["mean"] == 1.55
    assert leglab.PAPER_FOOT_CM["model_based"]["Linf"]["mean"] == 2.34
    assert sorted(leglab.PAPER_FOOT_CM) == ["direct", "model_based", "time_shift"]


def test_the_ranges_ends_are_models():
    # Each end of the config's model.* ranges is a JointModel.
    for params in ((0.01, 0.01, 0, 1), (45.0, 180.0, 50, 50)):
        assert leglab.JointModel(*params).lag_ticks == params[2]


def test_steady_state_is_the_repeated_cycle():
    cycle = 30.0 * np.sin(np.linspace(0.0, 2.0 * np.pi, 40, endpoint=False))
    model = leglab.PAPER_MODEL
    got = model.steady_state(cycle)
    played = eq3(2.5, 7.0, 4, 6, np.tile(cycle, 60), float(np.mean(cycle)))
    np.testing.assert_allclose(got, played[-40:], rtol=0, atol=1e-8)


def test_a_model_that_never_settles_is_a_value_error():
    swinging = leglab.JointModel(5.0, 2.0, 0, 1)  # v_max >= 2 theta_0
    assert not swinging.settles_on_every_cycle
    # A swing of period 2 about the request fits no cycle of odd length.
    with pytest.raises(ValueError, match="steady_state"):
        swinging.steady_state([0.0] * 7 + [10.0] * 8)


def test_identify_recovers_a_known_model():
    true = (2.1, 9.0, 3, 4)
    period = 16
    requests, measured = [], []
    for theta in (40.0, 110.0):
        cycle = np.where(np.arange(period) < period // 2, 0.0, theta)
        r = np.tile(cycle, 13)
        m = eq3(*true, r, 0.0)
        requests.append(r[5 * period:])
        measured.append(m[5 * period:])
    fit = leglab.identify(requests, measured)
    assert (fit.model.lag_ticks, fit.model.accel_ticks) == (3, 4)
    assert fit.model.v_max_deg_per_tick == pytest.approx(2.1, rel=1e-6)
    assert fit.model.theta0_deg == pytest.approx(9.0, rel=1e-6)
    assert fit.rms_residual_deg < 1e-6


def test_identify_gives_the_identify_programs_fit(tmp_path):
    # identify writes each step test's recording (step_<joint>_<theta>.csv: the requests as the
    # servo took them and the measured angles); fitted from Python as identify fits them
    # (cycles averaged over the config's t_step_ticks), they give table1.json's models exactly.
    out = tmp_path / "identify"
    run = run_program("identify", "--config", TRACK_YAML.replace("track.yaml", "identify.yaml"),
                      "--out", out, "--quiet")
    assert run.returncode == 0, run.stderr
    table1 = json.loads((out / "table1.json").read_text())
    period = int(re.search(r"t_step_ticks: (\d+)", (out / "identify_config.yaml").read_text())[1])
    for joint in leglab.JOINT_NAMES:
        # In the config's order of step heights (40, then 110), as identify fits them.
        files = sorted(out.glob(f"step_{joint}_*.csv"), key=lambda f: float(f.stem.split("_")[-1]))
        assert len(files) == 2
        columns = [read_csv(f) for f in files]
        fit = leglab.identify([c["request_deg"] for c in columns],
                              [c["actual_deg"] for c in columns], period_ticks=period)
        want = table1["joints"][joint]
        assert fit.model.to_dict() == {k: want[k] for k in fit.model.to_dict()}
        assert fit.rms_residual_deg == want["fit_rms_deg"]


def test_floor_is_feasible_and_no_farther_than_a_feasible_path():
    t = np.arange(88)
    desired = 60.0 * np.sign(np.sin(2.0 * np.pi * t / 88))  # a square wave: far too fast
    model = leglab.PAPER_MODEL
    x = leglab.floor(desired, model)
    speed = np.diff(np.append(x, x[0]))
    assert np.max(np.abs(speed)) <= 2.5 + 1e-9
    accel = np.diff(np.append(speed, speed[0]))
    assert np.max(np.abs(accel)) <= 2 * 2.5 / 3 + 1e-9
    # The constant mean is feasible, so the floor is at least as near to D.
    assert np.sqrt(np.mean((x - desired) ** 2)) <= np.sqrt(np.mean((desired.mean() - desired) ** 2))
    # A slow cycle is already feasible: returned as it is.
    slow = 5.0 * np.sin(2.0 * np.pi * t / 88)
    np.testing.assert_array_equal(leglab.floor(slow, model), slow)


def test_floor_of_three_joints_is_three_floors():
    walk = leglab.Walk(TRACK_YAML)
    models = [leglab.PAPER_MODEL, leglab.JointModel(2.0, 5.0, 2, 2), leglab.PAPER_MODEL]
    both = leglab.floor(walk.angles_deg, models)
    for j in range(3):
        np.testing.assert_array_equal(both[:, j], leglab.floor(walk.angles_deg[:, j], models[j]))


def test_models_compare_pickle_and_print():
    m = leglab.JointModel(2.5, 7.0, 4, 6)
    assert m == leglab.PAPER_MODEL
    assert pickle.loads(pickle.dumps(m)) == m
    # Another type compares unequal (it raised pybind11's several-line TypeError before).
    assert m != 3 and not (m == "JointModel") and m != None  # noqa: E711
    assert repr(m) == "JointModel(v_max_deg_per_tick=2.5, theta0_deg=7.0, lag_ticks=4, accel_ticks=6)"
    assert "eq. 3" in leglab.JointModel.__doc__


@pytest.mark.parametrize("call, message", [
    (lambda: leglab.JointModel(-1.0, 7.0, 4, 3), "v_max"),
    (lambda: leglab.JointModel(2.5, 0.0, 4, 3), "theta"),
    (lambda: leglab.JointModel(2.5, 7.0, 4, 0), "accel"),
    (lambda: leglab.PAPER_MODEL.simulate([1.0, float("nan")], 0.0), r"requests\[1\] is nan"),
    (lambda: leglab.PAPER_MODEL.simulate([[1.0]], 0.0), "1-D"),
    (lambda: leglab.PAPER_MODEL.simulate(["a"], 0.0), "dtype"),
    (lambda: leglab.identify([1.0, 2.0], [1.0]), "2 requests but 1 measured"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, lag_range_ticks=(5, 2)), "lag_range_ticks"),
    (lambda: leglab.identify([1.0] * 30, [1.0] * 30, period_ticks=16), "cycles|whole"),
    (lambda: leglab.floor([1.0, 2.0], leglab.PAPER_MODEL), "at least 3"),
    (lambda: leglab.floor(np.zeros((5, 3)), [leglab.PAPER_MODEL]), "one JointModel per joint"),
    # Bounds from the model's key declarations (the config's model.* ranges, as
    # docs/configuration.md lists them), before anything is allocated.
    (lambda: leglab.JointModel(2.5, 7.0, 2**40, 6), r"lag_ticks must be an integer in \[0, 50\] ticks"),
    (lambda: leglab.JointModel(2.5, 7.0, 10**9, 6), r"lag_ticks must be an integer in \[0, 50\] ticks"),
    (lambda: leglab.JointModel(2.5, 7.0, 51, 6), r"lag_ticks must be an integer in \[0, 50\] ticks"),
    (lambda: leglab.JointModel(2.5, 7.0, 4, 51), r"accel_ticks must be an integer in \[1, 50\] ticks"),
    (lambda: leglab.JointModel(1e308, 5e-324, 0, 1),
     r"v_max_deg_per_tick must be in \[0.01, 45\] deg/tick"),
    (lambda: leglab.JointModel(0.005, 7.0, 4, 6),
     r"v_max_deg_per_tick must be in \[0.01, 45\] deg/tick"),
    (lambda: leglab.JointModel(2.5, 181.0, 4, 6), r"theta0_deg must be in \[0.01, 180\] deg"),
    (lambda: leglab.JointModel(2.5, float("inf"), 0, 1), "theta0_deg: expected a finite number"),
    (lambda: leglab.JointModel(2.5, 7.0, 2**70, 1), r"lag_ticks must be an integer in \[0, 50\] ticks"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, lag_range_ticks=(0, 51)),
     r"lag_range_ticks\[1\] must be an integer in \[0, 50\] ticks"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, accel_range_ticks=(0, 6)),
     r"accel_range_ticks\[0\] must be an integer in \[1, 50\] ticks"),
    (lambda: leglab.PAPER_MODEL.speed_response(float("nan")), "x_deg: expected a finite number"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, period_ticks=0), "period_ticks"),
    # A fit outside the model's ranges is an error, not a model the constructor would refuse.
    (lambda: leglab.identify(np.r_[np.zeros(50), np.ones(50)] * 1e300,
                             np.r_[np.zeros(50), np.ones(50)] * 1e300), "outside the model's ranges"),
])
def test_bad_input_is_a_one_line_value_error(call, message):
    with pytest.raises(ValueError, match=message) as error:
        call()
    assert "\n" not in str(error.value)


@pytest.mark.parametrize("call, message", [
    (lambda: leglab.JointModel(2.5, 7.0, 4.5, 6), "lag_ticks: expected an integer, got float 4.5"),
    (lambda: leglab.JointModel("2.5", 7.0, 4, 6), "v_max_deg_per_tick: expected a number, got str"),
    (lambda: leglab.JointModel(2.5, 7.0, True, 6), "lag_ticks: expected an integer, got bool"),
    (lambda: leglab.JointModel(2.5, 7.0, 4, np.bool_(True)), "accel_ticks: expected an integer"),
    (lambda: leglab.JointModel(2.5, 7.0 + 1j, 4, 6), "theta0_deg: expected a number, got complex"),
    (lambda: leglab.PAPER_MODEL.speed_response(np.zeros(3)), "x_deg: expected a number, got ndarray"),
    (lambda: leglab.PAPER_MODEL.simulate([1.0], True), "start_deg: expected a number, got bool"),
    (lambda: leglab.floor(np.zeros(10), "paper"), "model: expected a JointModel, got str"),
    (lambda: leglab.floor(np.zeros((5, 3)), [leglab.PAPER_MODEL, 1, 2]), r"model\[1\]: expected"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, lag_range_ticks=5), "lag_range_ticks"),
    (lambda: leglab.identify([1.0] * 40, [1.0] * 40, accel_range_ticks=(1, 2.5)),
     r"accel_range_ticks\[1\]: expected an integer"),
    # These were ValueError before the package followed Python's convention everywhere
    # (CHANGELOG.md, Changed): one JointModel where a (T, 3) cycle needs three, and an array
    # argument that is no array at all.
    (lambda: leglab.floor(np.zeros((5, 3)), leglab.PAPER_MODEL), "got a JointModel"),
    (lambda: leglab.PAPER_MODEL.simulate(None, 0.0), "requests: expected an array of numbers"),
    (lambda: leglab.PAPER_MODEL.steady_state("abc"), "cycle: expected an array of numbers"),
])
def test_a_value_of_the_wrong_type_is_a_one_line_type_error(call, message):
    # Python's convention: TypeError for the wrong type (bool is not a number here), never
    # pybind11's several-line list of signatures.
    with pytest.raises(TypeError, match=message) as error:
        call()
    assert "\n" not in str(error.value)


def test_numpy_scalars_are_numbers():
    model = leglab.JointModel(np.float64(2.5), np.int64(7), np.int32(4), np.uint8(6))
    assert model == leglab.PAPER_MODEL
