"""Each servo of a session and what is its own: its model's motor name, gain, load, zero,
limits and desired motion. From the command line's flags (the same for every id), or per servo
from a small YAML file (`--servos FILE`), the flags filling what an entry leaves out:

    # servos.yaml: an SO-101's shoulder and elbow
    servos:
      1: {motor: sts3215, kp: 32, mass_kg: 0.45, length_m: 0.12, min_deg: -90, max_deg: 90}
      2: {motor: sts3215, kp: 32, mass_kg: 0.25, length_m: 0.10, desired: elbow.csv}
"""

# No `from __future__ import annotations` here: Joint's fields' types are read at run time
# (dataclasses.fields(Joint)[i].type is str), which postponed annotations would make text.
import argparse
import dataclasses
import os
from dataclasses import dataclass, field
from typing import Any, Optional

from .bus import first_line
from .files import check_input_file
from .session import SessionError


def _setting(default: Any, *, low: Optional[float] = None, high: Optional[float] = None,
             needed_by: tuple[str, ...] = ("record", "run")) -> Any:
    """A Joint field: its default, its range (numbers), and the verbs that need it given."""
    return field(default=default, metadata={"range": (low, high), "needed_by": needed_by})


@dataclass
class Joint:
    """One servo's settings (angles in degrees from its zero; None: not given)."""

    id: int
    motor: str = _setting(None, needed_by=("record",))  # the model's motor name, the logs' motor
    kp: int = _setting(None, low=0, high=16383)  # the position P gain, in register units
    mass_kg: float = _setting(None, low=0, high=1000)  # the pendulum: a mass on an arm
    length_m: float = _setting(None, low=0, high=10)
    zero_deg: float = _setting(None, low=0, high=360, needed_by=())  # None: found limp
    min_deg: float = _setting(-180.0, low=-180, high=180, needed_by=())  # run: requests' range
    max_deg: float = _setting(180.0, low=-180, high=180, needed_by=())
    desired: str = _setting(None, needed_by=("run",))  # run: its motion (default: --desired)


_SETTINGS = {f.name: f for f in dataclasses.fields(Joint) if f.name != "id"}


def _given(value: object) -> bool:
    return value is not None and value != ""


def _entry(servo_id: int, entry: object, source: str, folder: str) -> dict[str, Any]:
    if not isinstance(entry, dict):
        raise SessionError(f"{source}: servo {servo_id}: expected a mapping of settings")
    values: dict[str, Any] = {}
    for key, value in entry.items():
        where = f"{source}: servo {servo_id}: {key}"
        if key not in _SETTINGS:
            raise SessionError(f"{where}: unknown key (valid: {', '.join(sorted(_SETTINGS))})")
        kind = _SETTINGS[key].type
        if kind is str:
            if not isinstance(value, str) or not value:
                raise SessionError(f"{where}: expected a name, got {_shown(value)}")
            if key == "desired":  # relative to the file's folder
                value = os.path.join(folder, value)
        else:
            wanted: Any = int if kind is int else (int, float)
            if isinstance(value, bool) or not isinstance(value, wanted):
                raise SessionError(f"{where}: expected {'an integer' if kind is int else 'a number'}"
                                   f", got {_shown(value)}")
            low, high = _SETTINGS[key].metadata["range"]
            if not low <= value <= high:
                raise SessionError(f"{where}: {_shown(value)} is outside [{low}, {high}]")
        values[key] = value
    return values


_MAX_FILE_BYTES = 1 << 20  # a servos file is a few lines; this is far beyond any


def _shown(value: object) -> str:
    """`value` for a message, at most 60 characters."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _yaml_loader(yaml: Any) -> Any:
    """PyYAML's safe loader, refusing a key given twice in one mapping (which it would take
    the last of)."""
    class Loader(yaml.SafeLoader):
        pass

    def mapping(loader: Any, node: Any, deep: bool = False) -> Any:
        keys = [loader.construct_object(k, deep=deep) for k, _ in node.value]
        for key in keys:
            if keys.count(key) > 1:
                raise yaml.constructor.ConstructorError(
                    None, None, f"the key {_shown(key)} is given twice", node.start_mark)
        return yaml.SafeLoader.construct_mapping(loader, node, deep)

    Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, mapping)
    return Loader


def read_file(path: str) -> dict[int, dict[str, Any]]:
    """{id: settings} from a servos YAML file; SessionError naming the file, servo and key."""
    try:
        import yaml
    except ImportError:
        raise SessionError("--servos needs PyYAML (Debian: python3-yaml)") from None
    check_input_file(path, "--servos")
    if os.path.getsize(path) > _MAX_FILE_BYTES:
        raise SessionError(f"--servos '{path}': over {_MAX_FILE_BYTES} bytes: not a servos file")
    try:
        with open(path, encoding="utf-8") as f:
            document = yaml.load(f, Loader=_yaml_loader(yaml))  # noqa: S506 (a safe loader)
    except OSError as e:
        raise SessionError(f"--servos '{path}': {e.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as e:
        raise SessionError(f"--servos '{path}': not YAML: {first_line(e)}") from None
    except RecursionError:
        raise SessionError(f"--servos '{path}': nested too deeply to be a servos file") from None
    if not isinstance(document, dict) or set(document) != {"servos"} or not isinstance(
            document["servos"], dict) or not document["servos"]:
        raise SessionError(f"--servos '{path}': expected one key, servos, mapping ids to "
                           "settings")
    entries: dict[int, dict[str, Any]] = {}
    for servo_id, entry in document["servos"].items():
        if isinstance(servo_id, bool) or not isinstance(servo_id, int) or not 0 <= servo_id <= 252:
            raise SessionError(f"--servos '{path}': {_shown(servo_id)} is not a servo id in "
                               "[0, 252]")
        entries[servo_id] = _entry(servo_id, entry, f"--servos '{path}'",
                                   os.path.dirname(os.path.abspath(path)))
    return entries


def joints(args: argparse.Namespace, verb: str) -> list[Joint]:
    """[Joint] of the session of `verb` ("record" or "run"), in id order: --servos' entries
    over the flags (the same names, dashes for underscores); SessionError naming the servo and
    a setting the verb needs that neither gives."""
    flags: dict[str, Any] = {name: getattr(args, name, None) for name in _SETTINGS}
    flags = {name: value for name, value in flags.items() if _given(value)}
    entries = read_file(args.servos) if getattr(args, "servos", None) else {}
    if entries and args.ids and sorted(args.ids) != sorted(entries):
        raise SessionError(f"--id {','.join(map(str, args.ids))} and --servos' ids "
                           f"{','.join(map(str, entries))} differ (give one of them)")
    ids = sorted(entries or args.ids or [])
    if not ids:
        raise SessionError("no servo: give --id or --servos")
    out = []
    for servo_id in ids:
        joint = Joint(servo_id, **{**flags, **entries.get(servo_id, {})})
        for name, setting in _SETTINGS.items():
            if verb in setting.metadata["needed_by"] and not _given(getattr(joint, name)):
                raise SessionError(f"servo {servo_id}: no {name} (give "
                                   f"--{name.replace('_', '-')}, or the key in --servos)")
        if joint.min_deg >= joint.max_deg:
            raise SessionError(f"servo {servo_id}: min_deg {joint.min_deg:g} is not below "
                               f"max_deg {joint.max_deg:g}")
        out.append(joint)
    return out


def settings(joint: Joint, motor: str, zero_deg: float) -> dict[str, Any]:
    """`joint` as run.json records it: its settings, its model's motor and the zero it ran at,
    the desired motion's path made absolute."""
    values = dataclasses.asdict(joint)
    values.update(motor=motor, zero_deg=zero_deg, desired=os.path.abspath(joint.desired or ""))
    del values["id"]
    return values
