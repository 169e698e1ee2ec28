"""Every public name of the package has its numpydoc docstring (docs/python.md): a summary line,
then a Parameters section naming each parameter, a Returns section when it returns something, and
a Raises section when it raises. Public names: leglab's, leglab.envs', leglab.servo's and
leglab.bus' __all__ (and the public functions and classes of the bus's public modules), each
leglab.results module's and leglab.servo.learned's __all__, with their public methods. The compiled module's signatures are read from its stub (_leglab.pyi, which
Checks.PythonStubMatchesTheModule keeps true to the module)."""

import ast
import dataclasses
import importlib
import inspect
import pathlib
import re
import textwrap
import types

import pytest

import leglab
import leglab.envs
import leglab.results
import leglab.servo
import leglab.servo.learned
from leglab import bus

STUB = pathlib.Path(leglab.__file__).resolve().parent / "_leglab.pyi"


def _stub_signatures():
    """{qualified name: (parameters, returns something)} of the stub's functions and methods."""
    found = {}
    tree = ast.parse(STUB.read_text())

    def add(node, prefix):
        arguments = node.args
        names = [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]
        names = [n for n in names if n != "self"]
        returns = not (isinstance(node.returns, ast.Constant) and node.returns.value is None)
        found[prefix + node.name] = (names, returns)

    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            add(node, "")
        elif isinstance(node, ast.ClassDef):
            for member in node.body:
                if isinstance(member, ast.FunctionDef) and not any(
                        isinstance(d, ast.Name) and d.id == "property" for d in member.decorator_list):
                    add(member, node.name + ".")
    return found


STUB_SIGNATURES = _stub_signatures()
STUB_CLASSES = {node.name for node in ast.parse(STUB.read_text()).body
                if isinstance(node, ast.ClassDef)}


def _public_names():
    """(label, object, owner class or None) of every public function, class and method."""
    modules = [(leglab, leglab.__all__), (leglab.envs, ["LegTrackingEnv", "Box"]),
               (leglab.servo, leglab.servo.__all__), (bus, bus.__all__)]
    for name in bus.__all__:
        value = getattr(bus, name)
        if isinstance(value, types.ModuleType):
            modules.append((value, [n for n in vars(value) if not n.startswith("_")]))
    for name in leglab.results.__all__:
        module = importlib.import_module(f"leglab.results.{name}")
        modules.append((module, module.__all__))
    modules.append((leglab.servo.learned, leglab.servo.learned.__all__))
    seen = set()
    for module, names in modules:
        for name in names:
            value = getattr(module, name)
            if isinstance(value, types.ModuleType) or id(value) in seen:
                continue
            if not (inspect.isclass(value) or callable(value)):
                continue  # a constant: its docstring is the comment beside it
            if getattr(value, "__module__", "").split(".")[0] not in ("leglab",):
                continue  # imported from elsewhere (dataclass, Path, ...)
            seen.add(id(value))
            yield f"{module.__name__}.{name}", value, None
            if inspect.isclass(value):
                for member_name, member in vars(value).items():
                    if member_name.startswith("_") or not callable(member) or \
                            isinstance(member, type):
                        continue
                    yield f"{module.__name__}.{name}.{member_name}", member, value


PUBLIC = list(_public_names())


def _signature(label, value, owner):
    """(parameter names, returns something, raises something) of a public callable."""
    function = inspect.unwrap(value.__func__ if isinstance(value, (classmethod, staticmethod))
                              else value)
    stub_name = label.split(".", 1)[1] if label.startswith("leglab.") else label
    stub_name = stub_name.replace("servo.", "", 1) if stub_name.startswith("servo.") else stub_name
    if stub_name in STUB_SIGNATURES:  # a compiled function: every call can be refused
        names, returns = STUB_SIGNATURES[stub_name]
        return names, returns, bool(names)
    if stub_name.split(".")[0] in STUB_CLASSES and stub_name.endswith(".__init__"):
        return [], False, False  # a compiled class only the module makes: no constructor
    source = textwrap.dedent(inspect.getsource(function))
    node = ast.parse(source).body[0]
    arguments = node.args
    names = [a.arg for a in arguments.posonlyargs + arguments.args + arguments.kwonlyargs]
    if arguments.vararg:
        names.append(arguments.vararg.arg)
    if arguments.kwarg:
        names.append(arguments.kwarg.arg)
    names = [n for n in names if n not in ("self", "cls")]
    returns = not (node.returns is None or isinstance(node.returns, ast.Constant) and
                   node.returns.value is None or isinstance(node.returns, ast.Name) and
                   node.returns.id == "NoReturn")  # NoReturn: it never returns (exits)
    raises = any(isinstance(n, ast.Raise) and n.exc is not None for n in ast.walk(node))
    return names, returns, raises


def _section(doc, title):
    """The text of numpydoc section `title` in `doc`, or None."""
    match = re.search(rf"^\s*{title}\n\s*-{{{len(title)}}}\n(.*?)(?=^\s*\w[\w ]*\n\s*-{{3,}}\n|\Z)",
                      doc, re.S | re.M)
    return match.group(1) if match else None


def _documents(section, name):
    """Whether a Parameters (or Attributes) section names parameter `name`."""
    name = name.lstrip("*")
    return section is not None and re.search(
        rf"^\s*(\*\*?)?([\w, *]*\b)?{re.escape(name)}\b[\w, *]*( :|$)", section, re.M) is not None


@pytest.mark.parametrize("label, value, owner", PUBLIC, ids=[p[0] for p in PUBLIC])
def test_every_public_name_has_a_numpydoc_docstring(label, value, owner):
    doc = inspect.getdoc(value) or ""
    assert doc.strip(), f"{label}: no docstring"
    if inspect.isclass(value):
        init = vars(value).get("__init__")
        if dataclasses.is_dataclass(value) or issubclass(value, tuple) or init is None or \
                getattr(init, "__objclass__", None) is not None:
            # A record (its fields are its constructor's parameters) or a class the package
            # makes: its fields are Attributes, or it has none.
            fields = [f.name for f in dataclasses.fields(value)] if dataclasses.is_dataclass(
                value) else list(getattr(value, "_fields", ()))
            section = _section(doc, "Attributes") or _section(doc, "Parameters")
            missing = [f for f in fields if not f.startswith("_") and not _documents(section, f)]
            assert not missing, f"{label}: its Attributes do not name {missing}"
            return
        names, _, raises = _signature(label + ".__init__", init, value)
        init_doc = inspect.getdoc(init) if init.__doc__ else ""
        doc = doc + "\n" + (init_doc or "")
    else:
        names, returns, raises = _signature(label, value, owner)
        if returns:
            assert _section(doc, "Returns") is not None or _section(doc, "Yields") is not None, \
                f"{label}: no Returns section"
    if names:
        section = _section(doc, "Parameters")
        missing = [n for n in names if not _documents(section, n)]
        assert not missing, f"{label}: its Parameters do not name {missing}"
    if raises:
        assert _section(doc, "Raises") is not None, f"{label}: no Raises section"
