"""Property-based tests of the Python API: random shapes, dtypes, values and types into every
public call. Whatever goes in, only the documented exceptions come out (ValueError, TypeError,
MemoryError), each one line and never pybind11's list of signatures or a cast failure, and the
interpreter lives."""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import leglab
from conftest import TRACK_YAML
from leglab.envs import LegTrackingEnv

DOCUMENTED = (ValueError, TypeError, MemoryError)
SETTINGS = settings(max_examples=120, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow])

NUMBERS = st.one_of(
    st.integers(min_value=-(2**70), max_value=2**70),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, 1, 3, 4, 6, 88, 1e-300, 5e-324, 1e308, -0.0]),
)
DTYPES = st.sampled_from([np.float64, np.float32, np.int8, np.int64, np.uint8, np.bool_,
                          np.complex128, object, str])


@st.composite
def arrays(draw):
    """A numpy array of 0 to 3 dimensions (each up to 6 long) of any dtype."""
    shape = tuple(draw(st.lists(st.integers(0, 6), max_size=3)))
    dtype = draw(DTYPES)
    values = draw(st.lists(NUMBERS, min_size=int(np.prod(shape)), max_size=int(np.prod(shape))))
    data = np.array(values, dtype=object).reshape(shape)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return data.astype(dtype)
    except (OverflowError, ValueError, TypeError):
        return data


ANYTHING = st.one_of(
    NUMBERS, st.booleans(), st.none(), st.text(max_size=5), st.complex_numbers(max_magnitude=10),
    st.lists(NUMBERS, max_size=6), st.tuples(NUMBERS, NUMBERS), arrays(),
    st.dictionaries(st.text(max_size=12), NUMBERS, max_size=2),
    st.just(leglab.PAPER_MODEL), st.just([leglab.PAPER_MODEL] * 3),
)


def documented_or_returns(call, *args, **kwargs):
    """Calls `call`; any exception must be a documented one, on one line, without pybind11's
    argument-matching or cast messages."""
    try:
        call(*args, **kwargs)
    except DOCUMENTED as error:
        text = str(error)
        assert "\n" not in text, repr(text)
        assert "incompatible function arguments" not in text, text
        assert "Unable to cast" not in text, text


@SETTINGS
@given(ANYTHING, ANYTHING, ANYTHING, ANYTHING)
def test_joint_model_construction(v_max, theta0, lag, accel):
    documented_or_returns(leglab.JointModel, v_max, theta0, lag, accel)


@SETTINGS
@given(ANYTHING, ANYTHING)
def test_model_calls(first, second):
    model = leglab.PAPER_MODEL
    documented_or_returns(model.simulate, first, second)
    documented_or_returns(model.steady_state, first)
    documented_or_returns(model.speed_response, first)
    documented_or_returns(leglab.floor, first, second)


@SETTINGS
@given(ANYTHING, ANYTHING, ANYTHING, ANYTHING)
def test_identify(requests, measured, lag_range, period):
    documented_or_returns(leglab.identify, requests, measured, lag_range_ticks=lag_range)
    documented_or_returns(leglab.identify, requests, measured, period_ticks=period)


@pytest.fixture(scope="module")
def plant():
    return leglab.Plant(TRACK_YAML, {"plant": "model"})


@SETTINGS
@given(request=ANYTHING, settings_value=ANYTHING)
def test_plant_calls(plant, request, settings_value):
    documented_or_returns(plant.tick, request)
    documented_or_returns(plant.run, request)
    documented_or_returns(plant.change_settings, {"servo.delay_ms": settings_value})
    documented_or_returns(plant.change_settings, settings_value)


@pytest.fixture(scope="module")
def env():
    environment = LegTrackingEnv(steps=1, overrides={"plant": "model"})
    environment.reset(seed=1)
    return environment


@SETTINGS
@given(action=ANYTHING, steps=ANYTHING)
def test_env_calls(env, action, steps):
    if env.tick + 1 >= env.episode_ticks:
        env.reset(seed=1)
    documented_or_returns(env.step, action)
    documented_or_returns(LegTrackingEnv, steps=steps, history=steps)


# The XL330's fitted models (identify's fit of the shipped logs), as a log_fit.json holds them.
LOG_FIT = ('{"models": {"extended": {"xl330": {"tick_s": 0.0053, "gain_per_deg_kp": 6.16e-05, '
           '"v_max_deg_s": 856.3, "v_max_given": false, "stall_torque_nm": 0.505, '
           '"friction_duty": 0.0, "friction_load_ratio": 0.376, "velocity_lag_s": 0.1437, '
           '"lag_ticks": 1}}, "paper": {"xl330": {"tick_s": 0.0053, "v_max_deg_per_tick": 2.99, '
           '"theta0_deg": 12.0, "lag_ticks": 0, "accel_ticks": 1, "v_max_deg_s": 565.4}}}}')
JSON = st.recursive(st.none() | st.booleans() | NUMBERS | st.text(max_size=5),
                    lambda inner: st.lists(inner, max_size=3) |
                    st.dictionaries(st.sampled_from(["models", "extended", "paper", "xl330",
                                                     "logs", "folds", "tick_s", "lag_ticks"]),
                                    inner, max_size=3),
                    max_leaves=8)


@pytest.fixture(scope="module")
def servo_model():
    import leglab.servo as servo
    return servo.LogFit(LOG_FIT).model("xl330")


@SETTINGS
@given(desired=ANYTHING, method=ANYTHING, kp=ANYTHING, limit=ANYTHING)
def test_servo_plan_and_model_calls(servo_model, desired, method, kp, limit):
    import leglab.servo as servo
    documented_or_returns(servo.plan, servo_model, desired, method, kp=kp)
    documented_or_returns(servo.plan, servo_model, desired, kp=400, min_deg=limit)
    documented_or_returns(servo_model.simulate, desired, kp=kp, start_deg=limit)
    documented_or_returns(servo.read_desired, method, kp)


@SETTINGS
@given(method=ANYTHING, option=ANYTHING, window=ANYTHING, measured=ANYTHING)
def test_servo_planner_calls(servo_model, method, option, window, measured):
    import leglab.servo as servo
    for keyword in ("preview_ticks", "budget_s", "hold_ticks", "handover_ticks",
                    "optimal_iterations_per_tick", "reanchor_deg"):
        documented_or_returns(servo.ServoPlanner, servo_model, "optimal", kp=400,
                              **{keyword: option})
    documented_or_returns(servo.ServoPlanner, servo_model, method, kp=option)
    planner = servo.ServoPlanner(servo_model, "optimal", kp=400, preview_ticks=20, budget_s=0,
                                 optimal_iterations_per_tick=2)
    documented_or_returns(planner.reset, measured)
    documented_or_returns(planner.request, window, measured)
    documented_or_returns(planner.hold, window)


@SETTINGS
@given(document=JSON, motor=ANYTHING, rung=ANYTHING)
def test_log_fit_of_any_json(document, motor, rung):
    import json

    import leglab.servo as servo
    try:
        fit = servo.LogFit(json.dumps(document))
    except ValueError as error:
        assert "\n" not in str(error)
        return
    repr(fit)
    documented_or_returns(fit.model, motor, rung)
    documented_or_returns(fit.model)


@SETTINGS
@given(path=ANYTHING, form=ANYTHING, meta=ANYTHING)
def test_read_and_write_log_calls(tmp_path_factory, path, form, meta):
    import leglab.servo as servo
    for call in (lambda: servo.read_log(path), lambda: servo.read_log(path, form),
                 lambda: servo.read_log(servo_log_path(), motor=meta, kp=meta),
                 lambda: servo.write_log(path, tmp_path_factory.getbasetemp() / "log.csv")):
        try:
            call()
        except (ValueError, TypeError, MemoryError, OSError) as error:
            assert "\n" not in str(error), repr(str(error))


def servo_log_path():
    from conftest import SOURCE_DIR
    return SOURCE_DIR / "data" / "servo_logs" / "feetech-sts3250" / \
        "sin_sin_kp32_2024-10-26_12h23m27.json"
