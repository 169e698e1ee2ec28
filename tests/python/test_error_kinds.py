"""The kind of error a bad argument raises, over the public functions and constructors: an
argument of the wrong type is a TypeError, one of the right type but a wrong value (NaN,
infinity, negative where a positive number goes, an unknown name, an empty array) a ValueError,
each one line naming the argument (docs/python.md, "Errors"). Hypothesis draws the bad values
per argument (derandomized: the same cases every run); every other argument is valid."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import leglab
import leglab.servo as servo
from conftest import TRACK_YAML
from leglab import bus
from leglab.bus import dynamixel, feetech, tables, trajectories
from leglab.envs import LegTrackingEnv

SETTINGS = settings(max_examples=12, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow,
                                           HealthCheck.function_scoped_fixture])

# Wrong types, by what the argument is. bool is no number here (docs/python.md).
NOT_A_NUMBER = st.sampled_from(["1.0", None, [1.0], {}, object(), True, 1j])
NOT_AN_INTEGER = st.sampled_from(["1", None, [1], {}, object(), True, 2.5])
NOT_A_STR = st.sampled_from([3, 2.5, [b"a"], {}, object(), b"model_based"])
NOT_AN_ARRAY = st.sampled_from(["1.0", None, {}, {1.0}, object(), b"\x00"])
NOT_A_PATH = st.sampled_from([3, 2.5, [1], {}, object()])
NOT_A_DICT = st.sampled_from(["steps=2", [("steps", 2)], 3, object()])
NOT_A_MODEL = st.sampled_from(["xl330", None, [1.0], {}, object(), 3])

# Wrong values of the right type.
NOT_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
NOT_POSITIVE = st.one_of(NOT_FINITE, st.floats(max_value=0.0, allow_nan=False))
NEGATIVE_INTEGER = st.integers(max_value=-1)
HUGE_INTEGER = st.integers(min_value=10**12)
UNKNOWN_NAME = st.sampled_from(["nope", "", "MODEL_BASED", "model based", "\x00"])
EMPTY_OR_NOT_FINITE_ARRAY = st.sampled_from(
    [np.zeros(0), [], [math.nan, 0.0, 0.0], np.array([0.0, math.inf, 0.0]), np.zeros((2, 2, 2))])

LOG_FIT = ('{"models": {"extended": {"xl330": {"tick_s": 0.0053, "gain_per_deg_kp": 6.16e-05, '
           '"v_max_deg_s": 856.3, "v_max_given": false, "stall_torque_nm": 0.505, '
           '"friction_duty": 0.0, "friction_load_ratio": 0.376, "velocity_lag_s": 0.1437, '
           '"lag_ticks": 1}}, "paper": {"xl330": {"tick_s": 0.0053, "v_max_deg_per_tick": 2.99, '
           '"theta0_deg": 12.0, "lag_ticks": 0, "accel_ticks": 1, "v_max_deg_s": 565.4}}}}')
FIT = servo.LogFit(LOG_FIT)
MODEL = FIT.model("xl330")
PLANT = leglab.Plant(TRACK_YAML, {"plant": "model"})
T = np.arange(5) * 0.01


def _env():
    env = LegTrackingEnv(steps=1, history=1, preview=1, overrides={"plant": "model"})
    env.reset(seed=1)
    return env


ENV = _env()


def _planner():
    planner = servo.ServoPlanner(MODEL, kp=400)
    planner.reset(0.0)
    return planner


def _bus():
    emulated = bus.make_emulator("dynamixel", "xl330-m288", [1], 0.1, 0.1)
    return bus.Bus(bus.VirtualPort(emulated, bus.VirtualClock()), "dynamixel")


# (name, the call, its valid keyword arguments): each argument is replaced in turn.
CALLS = {
    "JointModel": (leglab.JointModel, dict(v_max_deg_per_tick=2.5, theta0_deg=7.0, lag_ticks=4,
                                            accel_ticks=6)),
    "JointModel.simulate": (leglab.PAPER_MODEL.simulate, dict(requests=np.zeros(5),
                                                              start_deg=0.0)),
    "JointModel.steady_state": (leglab.PAPER_MODEL.steady_state, dict(cycle=np.zeros(5))),
    "JointModel.speed_response": (leglab.PAPER_MODEL.speed_response, dict(x_deg=1.0)),
    "floor": (leglab.floor, dict(desired_cycle=np.zeros(5), model=leglab.PAPER_MODEL)),
    "identify": (leglab.identify, dict(requests=np.zeros(60), measured=np.zeros(60),
                                       lag_range_ticks=(0, 3), accel_range_ticks=(1, 3),
                                       period_ticks=None)),
    "Plant": (leglab.Plant, dict(config=TRACK_YAML, overrides={"plant": "model"})),
    "Robot": (leglab.Robot, dict(config=TRACK_YAML, overrides=None)),
    "Walk": (leglab.Walk, dict(config=TRACK_YAML, overrides=None)),
    "Plant.reset": (PLANT.reset, dict(pose=[0.0, 0.0, 0.0])),
    "Plant.tick": (PLANT.tick, dict(request=[0.0, 0.0, 0.0])),
    "Plant.run": (PLANT.run, dict(requests=np.zeros((2, 3)))),
    "Plant.change_settings": (PLANT.change_settings,
                              dict(settings={"plant_model.lag_ticks": 4})),
    "Robot.foot_mm": (PLANT.robot.foot_mm, dict(q_deg=[0.0, 0.0, 0.0])),
    "config_path": (leglab.config_path, dict(name="track.yaml")),
    "run_track": (leglab.run_track, dict(config=TRACK_YAML, overrides={"steps": 1},
                                         controllers=(), out=None, threads=1)),
    "LegTrackingEnv": (LegTrackingEnv, dict(config=None, overrides={"plant": "model"}, steps=1,
                                            history=1, preview=1, action="request")),
    "LegTrackingEnv.reset": (ENV.reset, dict(seed=1, options=None)),
    "LegTrackingEnv.step": (ENV.step, dict(action=np.zeros(3))),
    "servo.ServoLog": (servo.ServoLog, dict(time_s=T, request_deg=T, measured_deg=T,
                                            torque_enabled=None, motor="m", kp=1.0, mass_kg=0.0,
                                            length_m=0.0, trajectory="", file="")),
    "servo.read_log": (servo.read_log, dict(path="log.csv", format="csv", motor="m", kp=1.0)),
    "servo.write_log": (servo.write_log, dict(log=servo.ServoLog(T, T, T, motor="m", kp=1.0),
                                              path="/no/such/folder/log.csv")),
    "servo.LogFit": (servo.LogFit, dict(text=LOG_FIT)),
    "servo.LogFit.load": (servo.LogFit.load, dict(path="/no/such/log_fit.json")),
    "servo.LogFit.model": (FIT.model, dict(motor="xl330", rung="extended")),
    "servo.fit": (servo.fit, dict(config=[], overrides={"logs.iterations": 1}, threads=1)),
    "servo.plan": (servo.plan, dict(model=MODEL, desired_deg=np.zeros(3), method="model_based",
                                    kp=400, mass_kg=0.0, length_m=0.0, min_deg=-180.0,
                                    max_deg=180.0)),
    "servo.read_desired": (servo.read_desired, dict(path="/no/such/desired.csv",
                                                    tick_s=0.005)),
    "servo.ServoPlanner": (servo.ServoPlanner, dict(model=MODEL, method="model_based", kp=400,
                                                    mass_kg=0.0, length_m=0.0,
                                                    preview_ticks=None, min_deg=-180.0,
                                                    max_deg=180.0, reanchor_deg=2.0,
                                                    optimal_iterations_per_tick=200,
                                                    budget_s=None, hold_ticks=0,
                                                    handover_ticks=None)),
    "servo.ServoPlanner.reset": (_planner().reset, dict(angle_deg=0.0)),
    "servo.ServoPlanner.request": (_planner().request, dict(window_deg=np.zeros(5),
                                                            measured_deg=0.0)),
    "servo.ServoPlanner.hold": (_planner().hold, dict(window_deg=np.zeros(5))),
    "servo.ServoModel.simulate": (MODEL.simulate, dict(requests_deg=np.zeros(5), start_deg=None,
                                                       kp=400, mass_kg=0.0, length_m=0.0)),
    "bus.Bus": (bus.Bus, dict(port=bus.VirtualPort(bus.make_emulator(
        "dynamixel", "xl330-m288", [1], 0.1, 0.1), bus.VirtualClock()), protocol="dynamixel",
        baud=1_000_000, timeout_s=0.02, retries=2)),
    "bus.Bus.ping": (_bus().ping, dict(servo_id=1)),
    "bus.make_emulator": (bus.make_emulator, dict(protocol="dynamixel", model="xl330-m288",
                                                  ids=[1], mass_kg=0.1, length_m=0.1)),
    "tables.ControlTable.item": (tables.TABLES["sts3215"].item, dict(name="goal_position")),
    "tables.from_units": (tables.from_units, dict(item=tables.TABLES["sts3215"].item(
        "goal_position"), value=180.0)),
    "tables.encode": (tables.encode, dict(item=tables.TABLES["sts3215"].item("goal_position"),
                                          raw=2048)),
    "trajectories.sample": (trajectories.sample, dict(name="sin_sin", t_s=0.5)),
    "dynamixel.ping": (dynamixel.ping, dict(id=1)),
    "dynamixel.read": (dynamixel.read, dict(id=1, address=132, size=4)),
    "feetech.ping": (feetech.ping, dict(id=1)),
    "feetech.read": (feetech.read, dict(id=1, address=56, size=2)),
}

# (call, argument, what a wrong type is, the words that name the argument in the message).
TYPES = [
    ("JointModel", "v_max_deg_per_tick", NOT_A_NUMBER, None),
    ("JointModel", "theta0_deg", NOT_A_NUMBER, None),
    ("JointModel", "lag_ticks", NOT_AN_INTEGER, None),
    ("JointModel", "accel_ticks", NOT_AN_INTEGER, None),
    ("JointModel.simulate", "requests", NOT_AN_ARRAY, None),
    ("JointModel.simulate", "start_deg", NOT_A_NUMBER, None),
    ("JointModel.steady_state", "cycle", NOT_AN_ARRAY, None),
    ("JointModel.speed_response", "x_deg", NOT_A_NUMBER, None),
    ("floor", "desired_cycle", NOT_AN_ARRAY, None),
    ("floor", "model", NOT_A_MODEL, None),
    ("identify", "requests", NOT_AN_ARRAY, None),
    ("identify", "measured", NOT_AN_ARRAY, None),
    ("identify", "lag_range_ticks", st.sampled_from([3, 2.5, "0,3", {}, object()]), None),
    ("identify", "period_ticks", st.sampled_from(["1", [1], {}, object(), True, 2.5]), None),
    ("Plant", "config", NOT_A_PATH, None),
    ("Plant", "overrides", NOT_A_DICT, None),
    ("Robot", "config", NOT_A_PATH, None),
    ("Walk", "overrides", NOT_A_DICT, None),
    ("Plant.reset", "pose", NOT_AN_ARRAY, None),
    ("Plant.tick", "request", NOT_AN_ARRAY, None),
    ("Plant.run", "requests", NOT_AN_ARRAY, None),
    ("Plant.change_settings", "settings", NOT_A_DICT, None),
    ("Robot.foot_mm", "q_deg", NOT_AN_ARRAY, None),
    ("config_path", "name", NOT_A_STR, None),
    ("run_track", "config", NOT_A_PATH, None),
    ("run_track", "overrides", NOT_A_DICT, None),
    ("run_track", "controllers", st.sampled_from(["direct", 3, [3], {"a": 1}, [object()]]),
     None),
    ("run_track", "out", NOT_A_PATH, None),
    ("run_track", "threads", NOT_AN_INTEGER, None),
    ("LegTrackingEnv", "config", NOT_A_PATH, None),
    ("LegTrackingEnv", "overrides", NOT_A_DICT, None),
    ("LegTrackingEnv", "steps", NOT_AN_INTEGER, None),
    ("LegTrackingEnv", "history", NOT_AN_INTEGER, None),
    ("LegTrackingEnv", "preview", NOT_AN_INTEGER, None),
    ("LegTrackingEnv", "action", NOT_A_STR, None),
    ("LegTrackingEnv.reset", "seed", st.sampled_from(["1", [1], {}, object(), True, 2.5]), None),
    ("LegTrackingEnv.reset", "options", NOT_A_DICT, None),
    ("LegTrackingEnv.step", "action", NOT_AN_ARRAY, None),
    ("servo.ServoLog", "time_s", NOT_AN_ARRAY, None),
    ("servo.ServoLog", "measured_deg", NOT_AN_ARRAY, None),
    ("servo.ServoLog", "torque_enabled", st.sampled_from(["1", {}, object()]), None),
    ("servo.ServoLog", "motor", NOT_A_STR, None),
    ("servo.ServoLog", "kp", NOT_A_NUMBER, None),
    ("servo.ServoLog", "mass_kg", NOT_A_NUMBER, None),
    ("servo.read_log", "path", NOT_A_PATH, None),
    ("servo.read_log", "format", NOT_A_STR, None),
    ("servo.read_log", "motor", NOT_A_STR, None),
    ("servo.read_log", "kp", NOT_A_NUMBER, None),
    ("servo.write_log", "log", st.sampled_from(["log", None, [], {}, object()]), None),
    ("servo.write_log", "path", NOT_A_PATH, None),
    ("servo.LogFit", "text", st.sampled_from([3, None, [], {}, object(), b"{}"]), None),
    ("servo.LogFit.load", "path", NOT_A_PATH, None),
    ("servo.LogFit.model", "motor", st.sampled_from([3, [1], {}, object()]), None),
    ("servo.LogFit.model", "rung", NOT_A_STR, None),
    ("servo.fit", "config", st.sampled_from([3, 2.5, [3], {}, object(), ["log"]]),
     ("config", "fit()")),
    ("servo.fit", "overrides", NOT_A_DICT, None),
    ("servo.fit", "threads", NOT_AN_INTEGER, None),
    ("servo.plan", "model", NOT_A_MODEL, None),
    ("servo.plan", "desired_deg", NOT_AN_ARRAY, None),
    ("servo.plan", "method", NOT_A_STR, None),
    ("servo.plan", "kp", st.sampled_from(["1.0", [1.0], {}, object(), True]), None),
    ("servo.plan", "mass_kg", NOT_A_NUMBER, None),
    ("servo.plan", "min_deg", NOT_A_NUMBER, None),
    ("servo.read_desired", "path", NOT_A_PATH, None),
    ("servo.read_desired", "tick_s", NOT_A_NUMBER, None),
    ("servo.ServoPlanner", "model", NOT_A_MODEL, None),
    ("servo.ServoPlanner", "method", NOT_A_STR, None),
    ("servo.ServoPlanner", "kp", st.sampled_from(["1.0", [1.0], {}, object(), True]), None),
    ("servo.ServoPlanner", "preview_ticks", st.sampled_from(["1", [1], {}, object(), True, 2.5]),
     None),
    ("servo.ServoPlanner", "reanchor_deg", NOT_A_NUMBER, None),
    ("servo.ServoPlanner", "optimal_iterations_per_tick", NOT_AN_INTEGER, None),
    ("servo.ServoPlanner", "budget_s", st.sampled_from(["1.0", [1.0], {}, object(), True]), None),
    ("servo.ServoPlanner", "hold_ticks", NOT_AN_INTEGER, None),
    ("servo.ServoPlanner.reset", "angle_deg", NOT_A_NUMBER, None),
    ("servo.ServoPlanner.request", "window_deg", NOT_AN_ARRAY, None),
    ("servo.ServoPlanner.request", "measured_deg", NOT_A_NUMBER, None),
    ("servo.ServoPlanner.hold", "window_deg", NOT_AN_ARRAY, None),
    ("servo.ServoModel.simulate", "requests_deg", NOT_AN_ARRAY, None),
    ("servo.ServoModel.simulate", "start_deg", st.sampled_from(["1.0", [1.0], {}, object(), True]),
     None),
    ("servo.ServoModel.simulate", "kp", st.sampled_from(["1.0", [1.0], {}, object(), True]), None),
    ("bus.Bus", "protocol", NOT_A_STR, None),
    ("bus.Bus", "baud", NOT_AN_INTEGER, None),
    ("bus.Bus", "timeout_s", NOT_A_NUMBER, None),
    ("bus.Bus", "retries", NOT_AN_INTEGER, None),
    ("bus.Bus.ping", "servo_id", NOT_AN_INTEGER, ("servo id",)),
    ("bus.make_emulator", "protocol", NOT_A_STR, None),
    ("bus.make_emulator", "model", NOT_A_STR, None),
    ("tables.ControlTable.item", "name", NOT_A_STR, ("item",)),
    # A bool is taken here (b.write(id, "torque_enable", True)), as it always was.
    ("tables.from_units", "value", NOT_A_NUMBER.filter(lambda v: v is not True),
     ("goal_position",)),
    ("tables.encode", "raw", st.sampled_from(["1", None, [1], {}, object(), 2.5]),
     ("goal_position",)),
    ("trajectories.sample", "name", NOT_A_STR, ("trajectory",)),
    ("trajectories.sample", "t_s", NOT_A_NUMBER, ("trajectory time",)),
    ("dynamixel.ping", "id", NOT_AN_INTEGER, None),
    ("dynamixel.read", "address", NOT_AN_INTEGER, None),
    ("feetech.ping", "id", NOT_AN_INTEGER, None),
    ("feetech.read", "size", NOT_AN_INTEGER, None),
]

# (call, argument, what a wrong value is, the words that name it): the right type, a bad value.
VALUES = [
    ("JointModel", "v_max_deg_per_tick", NOT_POSITIVE, None),
    ("JointModel", "theta0_deg", NOT_POSITIVE, None),
    ("JointModel", "lag_ticks", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("JointModel", "accel_ticks", st.one_of(st.integers(max_value=0), HUGE_INTEGER), None),
    ("JointModel.simulate", "requests", EMPTY_OR_NOT_FINITE_ARRAY.filter(
        lambda a: len(np.asarray(a)) > 0), None),
    ("JointModel.simulate", "start_deg", NOT_FINITE, None),
    ("JointModel.steady_state", "cycle", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("JointModel.speed_response", "x_deg", NOT_FINITE, None),
    ("floor", "desired_cycle", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("identify", "requests", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("identify", "lag_range_ticks", st.sampled_from([(3, 1), (-1, 2), (0, 51), (1, 2, 3)]),
     None),
    ("identify", "period_ticks", st.one_of(st.integers(max_value=0), HUGE_INTEGER), None),
    ("Plant", "config", st.sampled_from(["/no/such.yaml", ""]), ("config",)),
    ("Plant", "overrides", st.sampled_from([{"nope": 1}, {"servo.delay_ms": math.nan},
                                            {"plant": "bogus"}]),
     ("nope", "servo.delay_ms", "plant")),
    ("Plant.reset", "pose", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("Plant.tick", "request", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("Plant.run", "requests", st.sampled_from([np.zeros((2, 2)), [[0.0, math.nan, 0.0]],
                                               np.zeros(3)]), None),
    ("Plant.change_settings", "settings", st.sampled_from(
        [{"nope": 1.0}, {"plant_model.lag_ticks": -1}, {"plant_model.lag_ticks": math.nan}]),
     ("nope", "plant_model.lag_ticks")),
    ("Robot.foot_mm", "q_deg", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("config_path", "name", UNKNOWN_NAME, ("config",)),
    ("run_track", "config", st.sampled_from(["/no/such.yaml"]), ("config",)),
    ("run_track", "threads", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("LegTrackingEnv", "steps", st.one_of(st.integers(max_value=0), HUGE_INTEGER), None),
    ("LegTrackingEnv", "history", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("LegTrackingEnv", "action", UNKNOWN_NAME, None),
    ("LegTrackingEnv.reset", "seed", st.one_of(NEGATIVE_INTEGER, st.integers(min_value=10**19)),
     None),
    ("LegTrackingEnv.step", "action", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("servo.ServoLog", "time_s", st.sampled_from([np.zeros(5), np.full(5, math.nan),
                                                  np.zeros(4)]), ("time_s",)),
    ("servo.ServoLog", "kp", NOT_FINITE, None),
    ("servo.read_log", "path", st.sampled_from(["/no/such/log.csv"]), ("log",)),
    ("servo.read_log", "format", UNKNOWN_NAME, None),
    ("servo.LogFit", "text", st.sampled_from(["", "[]", "{", '{"logs": 3}']), ("LogFit",)),
    ("servo.LogFit.model", "motor", st.sampled_from(["nope", "XL330"]), ("motor",)),
    ("servo.LogFit.model", "rung", UNKNOWN_NAME, None),
    ("servo.fit", "overrides", st.sampled_from([{"logs.nope": 1}, {"logs.iterations": -1}]),
     ("logs.nope", "logs.iterations")),
    ("servo.fit", "threads", NEGATIVE_INTEGER, None),
    ("servo.plan", "desired_deg", EMPTY_OR_NOT_FINITE_ARRAY, None),
    ("servo.plan", "method", UNKNOWN_NAME, None),
    ("servo.plan", "kp", NOT_POSITIVE, None),
    ("servo.plan", "mass_kg", st.one_of(NOT_FINITE, st.floats(max_value=-1e-9)), None),
    ("servo.plan", "min_deg", st.one_of(NOT_FINITE, st.floats(min_value=181.0, max_value=1e9)),
     None),
    ("servo.read_desired", "tick_s", NOT_POSITIVE, ("tick_s", "desired")),
    ("servo.ServoPlanner", "method", UNKNOWN_NAME, None),
    ("servo.ServoPlanner", "kp", NOT_POSITIVE, None),
    ("servo.ServoPlanner", "preview_ticks", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("servo.ServoPlanner", "reanchor_deg", st.one_of(st.just(math.nan), st.floats(max_value=0)),
     None),
    ("servo.ServoPlanner", "optimal_iterations_per_tick", st.one_of(NEGATIVE_INTEGER,
                                                                    HUGE_INTEGER), None),
    ("servo.ServoPlanner", "hold_ticks", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("servo.ServoPlanner.reset", "angle_deg", NOT_FINITE, ("angle",)),
    ("servo.ServoPlanner.request", "window_deg", EMPTY_OR_NOT_FINITE_ARRAY,
     ("window_deg", "desired")),
    ("servo.ServoPlanner.request", "measured_deg", NOT_FINITE, ("measured",)),
    ("servo.ServoModel.simulate", "requests_deg", EMPTY_OR_NOT_FINITE_ARRAY.filter(
        lambda a: len(np.asarray(a)) > 0), None),
    ("servo.ServoModel.simulate", "kp", NOT_POSITIVE, None),
    ("bus.Bus", "protocol", UNKNOWN_NAME, ("protocol",)),
    ("bus.Bus", "baud", st.sampled_from([0, -9600, 9601, 10**9]), None),
    ("bus.Bus", "timeout_s", NOT_POSITIVE.filter(lambda x: x != math.inf), None),
    ("bus.Bus", "retries", st.one_of(NEGATIVE_INTEGER, HUGE_INTEGER), None),
    ("bus.Bus.ping", "servo_id", st.one_of(NEGATIVE_INTEGER, st.integers(min_value=253)),
     ("servo id",)),
    ("bus.make_emulator", "protocol", UNKNOWN_NAME, ("protocol",)),
    ("bus.make_emulator", "model", UNKNOWN_NAME, ("servo model",)),
    ("tables.ControlTable.item", "name", UNKNOWN_NAME, ("item",)),
    ("tables.from_units", "value", st.one_of(NOT_FINITE, st.floats(min_value=1e6, max_value=1e9)),
     ("goal_position",)),
    ("tables.encode", "raw", st.one_of(st.integers(max_value=-2**15),
                                       st.integers(min_value=2**15)),
     ("goal_position",)),
    ("trajectories.sample", "name", UNKNOWN_NAME, ("trajectory",)),
    ("trajectories.sample", "t_s", st.one_of(NOT_FINITE, st.floats(max_value=-1e-9)),
     ("trajectory time",)),
    ("dynamixel.ping", "id", st.one_of(NEGATIVE_INTEGER, st.integers(min_value=255)), ("id",)),
    ("dynamixel.read", "size", st.one_of(st.integers(max_value=0), st.integers(min_value=2**16)),
     ("size",)),
    ("feetech.ping", "id", st.one_of(NEGATIVE_INTEGER, st.integers(min_value=255)), ("id",)),
    ("feetech.read", "address", st.one_of(NEGATIVE_INTEGER, st.integers(min_value=256)),
     ("address",)),
]


def _raised(call, arguments):
    """The exception `call(**arguments)` raises (None when it returns)."""
    try:
        call(**arguments)
    except Exception as error:  # noqa: BLE001  (the test looks at its kind)
        return error
    return None


def _check(name, argument, bad, names, kind):
    call, valid = CALLS[name]
    error = _raised(call, {**valid, argument: bad})
    shown = f"{name}({argument}={bad!r})"
    assert isinstance(error, kind) and not isinstance(error, MemoryError), \
        f"{shown}: expected {kind.__name__}, got {error!r}"
    text = str(error)
    assert "\n" not in text, f"{shown}: more than one line: {text!r}"
    assert any(word in text for word in names or (argument,)), \
        f"{shown}: {text!r} names none of {names or (argument,)}"


@pytest.mark.parametrize("name, argument, wrong, names", TYPES,
                         ids=[f"{c}-{a}" for c, a, _, _ in TYPES])
@SETTINGS
@given(data=st.data())
def test_an_argument_of_a_wrong_type_is_a_one_line_type_error_naming_it(name, argument, wrong,
                                                                         names, data):
    _check(name, argument, data.draw(wrong), names, TypeError)


@pytest.mark.parametrize("name, argument, wrong, names", VALUES,
                         ids=[f"{c}-{a}" for c, a, _, _ in VALUES])
@SETTINGS
@given(data=st.data())
def test_a_wrong_value_is_a_one_line_value_error_naming_it(name, argument, wrong, names, data):
    _check(name, argument, data.draw(wrong), names, ValueError)


def test_every_valid_call_of_the_tables_is_accepted():
    """The baselines are valid, so that each case above tests its one argument: every call
    with its valid arguments returns (or, where the valid arguments name no file, raises only
    the error about that file)."""
    needs_a_file = {"servo.read_log", "servo.write_log", "servo.LogFit.load",
                    "servo.read_desired", "servo.fit"}
    for name, (call, valid) in CALLS.items():
        if name in ("run_track", "LegTrackingEnv"):
            continue  # valid runs take seconds; their arguments are each checked above
        error = _raised(call, valid)
        if name in needs_a_file:
            assert error is None or isinstance(error, (OSError, ValueError)), (name, error)
        elif name == "identify":  # zeros never move: nothing to identify, a value error
            assert isinstance(error, ValueError) and "never moved" in str(error), error
        else:
            assert error is None, (name, error)
