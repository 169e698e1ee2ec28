"""One-line TypeErrors from the compiled module's calls.

pybind11 answers a call it cannot match (an unknown keyword, a missing or extra argument, a
None where a str goes) with a TypeError of several lines: every signature and the arguments
given. The package promises one line that names the argument, as the programs print, so each
public function and method of the compiled module is wrapped: a call pybind11 refuses is
matched here against the signature it printed, and the TypeError raised instead says which
argument is wrong and why. Calls it accepts pass through unchanged.
"""

from __future__ import annotations

import functools
import re
from types import ModuleType
from typing import Any, Callable, Iterable, Optional, TypeVar, cast

_F = TypeVar("_F", bound=Callable[..., Any])
# A parameter as pybind11's message lists it: name, annotation, has a default, keyword only.
_Parameter = tuple[str, str, bool, bool]

_REFUSED = ("incompatible function arguments", "incompatible constructor arguments")
_SIGNATURE = re.compile(r"^\s*1\. (?P<name>[\w.]*)\((?P<params>.*)\)(?: -> .*)?$", re.M)
_CALLABLE = re.compile(r"^(?P<name>\w+)\(\): ")
# pybind11's annotations that name one Python type, and what each accepts.
_TYPES = {"str": (str,), "float": (int, float), "int": (int,), "bool": (bool,)}


def _split_top_level(text: str) -> list[str]:
    """`text` split at the commas outside brackets (a type may be List[float, int])."""
    parts: list[str] = []
    depth, start = 0, 0
    for i, c in enumerate(text):
        depth += c in "[(" and 1 or (c in "])" and -1 or 0)
        if c == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    if text[start:].strip():
        parts.append(text[start:].strip())
    return parts


def _parameters(message: str) -> Optional[tuple[str, list[_Parameter]]]:
    """(callable's name, [(parameter, annotation, has a default, keyword only)]) of the first
    signature pybind11's message lists, or None."""
    match = _SIGNATURE.search(message)
    if not match:
        return None
    params: list[_Parameter] = []
    keyword_only = False
    for part in _split_top_level(match.group("params")):
        if part == "*":
            keyword_only = True
            continue
        name, _, rest = part.partition(":")
        annotation, _, default = rest.partition("=")
        params.append((name.strip(), annotation.strip(), bool(default.strip()), keyword_only))
    name = match.group("name").rsplit(".", 1)[-1]
    if not name:  # a function's or method's signature omits its name: the first line has it
        called = _CALLABLE.match(message)
        name = called.group("name") if called else "call"
    return name.lstrip("_"), params


def _reason(message: str, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Optional[str]:
    """What is wrong with the call, in one line naming the argument, or None."""
    parsed = _parameters(message)
    if parsed is None:
        return None
    name, params = parsed
    if params and params[0][0] == "self":
        params, args = params[1:], args[1:]
    names = [p[0] for p in params]
    for key in kwargs:
        if key not in names:
            return f"{name}(): unknown keyword '{key}' (it takes {', '.join(names) or 'none'})"
    positional = [p for p in params if not p[3]]
    if len(args) > len(positional):
        return (f"{name}(): takes {len(positional)} positional argument"
                f"{'' if len(positional) == 1 else 's'}, got {len(args)}")
    given = dict(zip((p[0] for p in positional), args))
    for key in kwargs:
        if key in given:
            return f"{name}(): '{key}' given twice (by position and by keyword)"
    given.update(kwargs)
    for parameter, annotation, has_default, _ in params:
        if parameter not in given:
            if not has_default:
                return f"{name}(): missing argument '{parameter}'"
            continue
        value = given[parameter]
        accepted = _TYPES.get(annotation)
        if accepted and (not isinstance(value, accepted) or
                         (bool not in accepted and isinstance(value, bool))):
            return (f"{name}(): {parameter}: expected {annotation}, got "
                    f"{type(value).__name__}")
        # A class of the compiled module, named by its path: an instance of it or a subclass.
        cls = annotation.rsplit(".", 1)[-1]
        if "." in annotation and cls not in (c.__name__ for c in type(value).__mro__):
            return f"{name}(): {parameter}: expected {cls}, got {type(value).__name__}"
    return None


def _out_of_memory(function: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any],
                   method: bool) -> str:
    """One line for a MemoryError (std::bad_alloc) of `function`: the argument with the most
    items, by its name in the signature its docstring opens with."""
    head = (getattr(function, "__doc__", "") or "").split("\n", 1)[0]
    match = re.match(r"(?P<name>\w+)\((?P<params>.*?)\)", head)
    name = (match.group("name") if match else getattr(function, "__name__", "call")).lstrip("_")
    params = [p.split("=")[0].split(":")[0].strip() for p in
              _split_top_level(match.group("params"))] if match else []
    params = [p for p in params if p not in ("self", "*")]
    if method:
        args = args[1:]  # the instance
    sized = list(zip(params, args)) + list(kwargs.items())

    def size(value: Any) -> int:
        try:
            return len(value) if not isinstance(value, (str, bytes)) else 0
        except TypeError:
            return 0
    largest = max(sized, key=lambda item: size(item[1]), default=None)
    if largest is None or size(largest[1]) == 0:
        return f"{name}(): not enough memory for this call"
    return f"{name}(): not enough memory for {largest[0]} of {size(largest[1])} items"


def one_line(function: _F, method: bool = False) -> _F:
    """`function` with pybind11's several-line errors replaced by one line.

    A TypeError for a call pybind11 cannot match becomes one line naming the argument, and a
    MemoryError ("std::bad_alloc") one naming the argument with the most items.

    Parameters
    ----------
    function : callable
        A function or method of the compiled module.
    method : bool, optional
        `function` is a class's, given its instance first.

    Returns
    -------
    callable
        The wrapped function (functools.wraps: its name and docstring are `function`'s).
    """
    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return function(*args, **kwargs)
        except MemoryError as e:
            if str(e) != "std::bad_alloc":
                raise
            raise MemoryError(_out_of_memory(function, args, kwargs, method)) from None
        except TypeError as e:
            first = str(e).split("\n", 1)[0]
            if not any(s in first for s in _REFUSED):
                raise
            # A constructor's signature omits the instance it is given first.
            given = args[1:] if _REFUSED[1] in first else args
            raise TypeError(_reason(str(e), given, kwargs) or first) from None
    return cast(_F, call)  # the same signature: a wrapper that passes every argument on


def wrap_module(module: ModuleType, names: Iterable[str]) -> None:
    """Wraps functions of `module`, and every public method, __init__ and __call__ of its
    classes, with one_line, in place.

    Parameters
    ----------
    module : module
        The compiled module.
    names : iterable of str
        The names of `module` to wrap: functions and classes.
    """
    for attribute in names:
        value = getattr(module, attribute)
        if isinstance(value, type):
            for method in list(vars(value)):
                if method.startswith("_") and method not in ("__init__", "__call__"):
                    continue
                member = vars(value)[method]
                if isinstance(member, staticmethod):
                    setattr(value, method, staticmethod(one_line(member.__func__)))
                elif callable(member) and not isinstance(member, type):
                    setattr(value, method, one_line(member, method=True))
        elif callable(value):
            setattr(module, attribute, one_line(value))
