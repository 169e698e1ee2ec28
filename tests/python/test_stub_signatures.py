"""The stub's signatures are the compiled module's. Checks.PythonStubMatchesTheModule (mypy's
stubtest) finds every name of the stub in the module and the other way round, but pybind11 gives
stubtest no signature to compare; pybind11 does list a function's parameters when it refuses a
call, so each public function, method and constructor of leglab._leglab is called with a keyword
it does not take, and the parameters pybind11 lists (names, order, which have a default, which
are keyword-only) must be the stub's."""

import ast
import pathlib

import pytest

import leglab
import leglab.servo
from leglab import _leglab, _one_line

STUB = pathlib.Path(leglab.__file__).resolve().parent / "_leglab.pyi"
LOG_FIT = ('{"models": {"extended": {"xl330": {"tick_s": 0.0053, "gain_per_deg_kp": 6.16e-05, '
           '"v_max_deg_s": 856.3, "v_max_given": false, "stall_torque_nm": 0.505, '
           '"friction_duty": 0.0, "friction_load_ratio": 0.376, "velocity_lag_s": 0.1437, '
           '"lag_ticks": 1}}}}')


def _stub_functions():
    """{name or Class.name: [(parameter, has a default, keyword only)]} of the stub's public
    functions, methods and constructors (not properties, not dunders but __init__)."""
    found = {}

    def parameters(node):
        a = node.args
        positional = a.posonlyargs + a.args
        defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
        out = [(p.arg, d, False) for p, d in zip(positional, defaults) if p.arg != "self"]
        out += [(p.arg, d is not None, True) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
        return out

    for node in ast.parse(STUB.read_text()).body:
        if isinstance(node, ast.FunctionDef) and not node.name.startswith("_"):
            found[node.name] = parameters(node)
        elif isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
            for member in node.body:
                if not isinstance(member, ast.FunctionDef) or member.decorator_list:
                    continue
                if member.name.startswith("_") and member.name != "__init__":
                    continue
                found[f"{node.name}.{member.name}"] = parameters(member)
    return found


STUB_FUNCTIONS = _stub_functions()


def _instances():
    """An instance of each class of the module whose methods are checked."""
    plant = leglab.Plant(leglab.config_path("track.yaml"), {"plant": "model"})
    model = leglab.servo.LogFit(LOG_FIT).model("xl330")
    return {"JointModel": leglab.PAPER_MODEL, "Plant": plant, "Robot": plant.robot,
            "ServoModel": model, "ServoPlanner": _leglab.ServoPlanner(model, kp=400)}


INSTANCES = _instances()
# Classes only the module makes, and whose instances only a run holds (ControllerContext): their
# methods are checked where an instance can be had; a constructor they do not have is not.
UNCHECKED = {"ControllerContext.foot_mm"}


def _module_parameters(name):
    """[(parameter, has a default, keyword only)] as pybind11 lists them when it refuses a call."""
    owner, _, member = name.rpartition(".")
    if not owner:
        function, instance = getattr(_leglab, name), None
    elif member == "__init__":  # on an instance not yet made, as the class's call does
        cls = getattr(_leglab, owner)
        function, instance = cls.__init__, cls.__new__(cls)
    else:
        function, instance = getattr(type(INSTANCES[owner]), member), INSTANCES[owner]
    function = getattr(function, "__wrapped__", function)  # pybind11's own, not the one-line's
    try:
        function(*([instance] if instance is not None else []), __stub_check__=1)
    except TypeError as error:
        parsed = _one_line._parameters(str(error))
    else:
        pytest.fail(f"{name} took a keyword it does not have")
    assert parsed is not None, f"{name}: pybind11 listed no signature"
    params = [p for p in parsed[1] if p[0] != "self"]
    return [(p, default, keyword_only) for p, _, default, keyword_only in params]


@pytest.mark.parametrize("name", sorted(set(STUB_FUNCTIONS) - UNCHECKED))
def test_the_stubs_parameters_are_the_modules(name):
    assert _module_parameters(name) == STUB_FUNCTIONS[name], name


def test_every_public_callable_of_the_module_is_in_the_stub():
    """The other way round: no public function or method of the module lacks a stub signature
    (stubtest finds a missing name; this finds a name the stub has as something else)."""
    for name in dir(_leglab):
        value = getattr(_leglab, name)
        if name.startswith("_"):
            continue
        if isinstance(value, type):
            for member, attribute in vars(value).items():
                if callable(attribute) and not member.startswith("_"):
                    assert f"{name}.{member}" in STUB_FUNCTIONS, f"{name}.{member}"
        elif callable(value):
            assert name in STUB_FUNCTIONS, name
