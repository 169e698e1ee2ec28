"""Each servo of a session and what is its own: its model's motor name, gain, load, zero,
limits and desired motion. From the command line's flags (the same for every id), or per servo
from a small YAML file (`--servos FILE`), the flags filling what an entry leaves out:

    # servos.yaml: an SO-101's shoulder and elbow
    servos:
      1: {motor: sts3215, kp: 32, mass_kg: 0.45, length_m: 0.12, min_deg: -90, max_deg: 90}
      2: {motor: sts3215, kp: 32, mass_kg: 0.25, length_m: 0.10, desired: elbow.csv}
"""

import math
import os
from dataclasses import dataclass, fields

from .session import SessionError


@dataclass
class Joint:
    """One servo's settings (angles in degrees from its zero)."""

    id: int
    motor: str = ""            # the model's motor name (log_fit.json's), the logs' motor
    kp: int = -1               # the position P gain, the servo's register units (-1: not given)
    mass_kg: float = math.nan  # the pendulum load: a point mass on an arm
    length_m: float = math.nan
    zero_deg: float = math.nan  # on the servo's own scale; NaN: found with the torque off
    min_deg: float = -180.0    # run: the requests' range
    max_deg: float = 180.0
    desired: str = ""          # run: its desired motion (default: --desired)


_RANGES = {"kp": (0, 16383), "mass_kg": (0, 1000), "length_m": (0, 10), "zero_deg": (0, 360),
           "min_deg": (-180, 180), "max_deg": (-180, 180)}


def _entry(servo_id, entry, source, folder):
    if not isinstance(entry, dict):
        raise SessionError(f"{source}: servo {servo_id}: expected a mapping of settings")
    names = {f.name for f in fields(Joint)} - {"id"}
    values = {}
    for key, value in entry.items():
        where = f"{source}: servo {servo_id}: {key}"
        if key not in names:
            raise SessionError(f"{where}: unknown key (valid: {', '.join(sorted(names))})")
        if key in ("motor", "desired"):
            if not isinstance(value, str) or not value:
                raise SessionError(f"{where}: expected a name, got {value!r}")
            if key == "desired" and not os.path.isabs(value):
                value = os.path.join(folder, value)
        else:
            integer = key == "kp"
            if isinstance(value, bool) or not isinstance(value, int if integer else (int, float)):
                raise SessionError(f"{where}: expected {'an integer' if integer else 'a number'}"
                                   f", got {value!r}")
            low, high = _RANGES[key]
            if not low <= value <= high:
                raise SessionError(f"{where}: {value!r} is outside [{low}, {high}]")
        values[key] = value
    return values


def read_file(path):
    """{id: settings} from a servos YAML file; SessionError naming the file, servo and key."""
    try:
        import yaml
    except ImportError:
        raise SessionError("--servos needs PyYAML (Debian: python3-yaml)") from None
    try:
        with open(path, encoding="utf-8") as f:
            document = yaml.safe_load(f)
    except OSError as e:
        raise SessionError(f"--servos '{path}': {e.strerror}") from None
    except (yaml.YAMLError, UnicodeDecodeError) as e:
        raise SessionError(f"--servos '{path}': not YAML: "
                           f"{str(e).splitlines()[0]}") from None
    if not isinstance(document, dict) or set(document) != {"servos"} or not isinstance(
            document["servos"], dict) or not document["servos"]:
        raise SessionError(f"--servos '{path}': expected one key, servos, mapping ids to "
                           "settings")
    entries = {}
    for servo_id, entry in document["servos"].items():
        if isinstance(servo_id, bool) or not isinstance(servo_id, int) or not 0 <= servo_id <= 252:
            raise SessionError(f"--servos '{path}': {servo_id!r} is not a servo id in [0, 252]")
        entries[servo_id] = _entry(servo_id, entry, f"--servos '{path}'",
                                   os.path.dirname(os.path.abspath(path)))
    return entries


def joints(args, needs=("kp", "mass_kg", "length_m")):
    """[Joint] of the session, in id order: --servos' entries over the flags; SessionError
    naming the servo and the setting missing from both."""
    flags = {"motor": getattr(args, "motor", "") or "", "kp": args.kp, "mass_kg": args.mass_kg,
             "length_m": args.length_m, "zero_deg": args.zero_deg,
             "min_deg": getattr(args, "min_deg", None), "max_deg": getattr(args, "max_deg", None),
             "desired": getattr(args, "desired", None)}
    flags = {k: v for k, v in flags.items() if v not in (None, "")}
    entries = read_file(args.servos) if getattr(args, "servos", None) else {}
    ids = list(entries) if entries else (args.ids or [])
    if entries and args.ids and sorted(args.ids) != sorted(entries):
        raise SessionError(f"--id {','.join(map(str, args.ids))} and --servos' ids "
                           f"{','.join(map(str, entries))} differ (give one of them)")
    if not ids:
        raise SessionError("no servo: give --id or --servos")
    out = []
    for servo_id in sorted(ids):
        joint = Joint(servo_id, **{**flags, **entries.get(servo_id, {})})
        for key in needs:
            value = getattr(joint, key)
            if value == "" or (isinstance(value, float) and math.isnan(value)) or value == -1:
                raise SessionError(f"servo {servo_id}: no {key} (give --{key.replace('_', '-')}, "
                                   "or the key in --servos)")
        if joint.min_deg >= joint.max_deg:
            raise SessionError(f"servo {servo_id}: min_deg {joint.min_deg:g} is not below "
                               f"max_deg {joint.max_deg:g}")
        out.append(joint)
    return out
