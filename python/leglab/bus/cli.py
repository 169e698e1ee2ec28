"""`python3 -m leglab.bus VERB`: scan, record, run and emulate, on a serial port or on an
emulated bus (`--port emulator:MODEL[,key=value...]`, on virtual time).

Bad input is one line on stderr and exit status 2, before anything moves; a session that a
fault ends (a servo that stops answering, a hardware error, SIGINT or SIGTERM) turns the torque
off, writes what it recorded, and exits 2 with one line naming the port and the servo.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Callable, Sequence
from typing import Any, NoReturn, Optional, Union

from . import bus as bus_module
from . import emulator, physics, session, tables, trajectories

MOTOR_ALIASES: dict[str, str] = {"xl330": "xl330-m288", "xl430": "xl430-w250"}
"""Servo models also known by the shorter names the shipped logs give them."""


class ArgumentParser(argparse.ArgumentParser):
    """argparse whose usage errors are one line and exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: {message} (--help lists the options)\n")


def _ids(text: str) -> list[int]:
    try:
        ids = [int(part) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a list of servo ids such as 1,2,3")
    if not ids or any(not 0 <= i <= bus_module.MAX_ID for i in ids) or len(set(ids)) != len(ids):
        raise argparse.ArgumentTypeError(
            f"'{text}': servo ids are distinct integers in [0, {bus_module.MAX_ID}]")
    return ids


def _ranged(low: float, high: float, unit: str = "",
            integer: bool = False) -> Callable[[str], Union[int, float]]:
    def parse(text: str) -> Union[int, float]:
        try:
            value: Union[int, float] = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not {'an integer' if integer else 'a number'}")
        if not (low <= value <= high):
            raise argparse.ArgumentTypeError(f"{text} is outside [{low:g}, {high:g}]{unit}")
        return value
    return parse


def _model(text: str) -> str:
    key = MOTOR_ALIASES.get(text, text)
    if key not in tables.TABLES or key not in physics.SPECS:
        known = ", ".join(k for k in tables.TABLES if k in physics.SPECS)
        raise argparse.ArgumentTypeError(f"unknown servo model '{text}' (valid: {known})")
    return key


def _name(text: str) -> str:
    if not text or len(text) > 64 or any(not (c.isalnum() or c in "-_.") for c in text):
        raise argparse.ArgumentTypeError(
            f"'{text}': a name of 1-64 letters, digits, '-', '_' or '.'")
    return text


def _trajectories(text: str) -> list[str]:
    names = text.split(",")
    if len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"'{text}' names a trajectory twice")
    for name in names:
        if name not in trajectories.NAMES:
            raise argparse.ArgumentTypeError(
                f"unknown trajectory '{name}' (valid: {', '.join(trajectories.NAMES)})")
    return names


def _common(parser: argparse.ArgumentParser, ids_flag: Optional[str] = "--id") -> None:
    parser.add_argument("--port", required=True,
                        help="the serial port (/dev/ttyUSB0, /dev/serial/by-id/...), or "
                             "emulator:MODEL[,key=value...] for an emulated bus on virtual time")
    parser.add_argument("--protocol", choices=sorted(bus_module.PROTOCOLS), default="dynamixel")
    parser.add_argument("--baud", type=int, default=1_000_000, choices=bus_module.BAUD_RATES,
                        metavar="B", help="the bus's baud rate (default 1000000)")
    parser.add_argument("--timeout-ms", type=_ranged(0.1, 10000, " ms"), default=20.0,
                        help="how long a reply is waited for (default 20 ms; in the tick "
                             "loop at most half a tick)")
    parser.add_argument("--retries", type=_ranged(0, 100, integer=True), default=2,
                        help="how many times an instruction is sent again after a missing or "
                             "corrupt reply (default 2)")
    if ids_flag:
        parser.add_argument(ids_flag, dest="ids", type=_ids,
                            help="the servos' ids, e.g. 1 or 1,2,3 (or give --servos)")


def _drive(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--servos", metavar="FILE",
                        help="each servo's own settings, a YAML file (leglab.bus.joints); "
                             "the flags fill what it leaves out")
    parser.add_argument("--kp", type=_ranged(0, 16383, integer=True),
                        help="the position P gain, in the servo's own register units")
    parser.add_argument("--mass-kg", type=_ranged(0, 1000, " kg"),
                        help="the load's mass (a point mass on an arm), kg")
    parser.add_argument("--length-m", type=_ranged(0, 10, " m"),
                        help="the load's arm, m (0 deg: hanging straight down)")
    parser.add_argument("--zero-deg", type=_ranged(0, 360, " deg"),
                        help="the zero on the servo's own 0-360 deg scale (default: the "
                             "reading with the torque off and the load hanging still)")
    parser.add_argument("--no-realtime", action="store_true",
                        help="do not ask for real-time priority")


def parser() -> argparse.ArgumentParser:
    """The command line's parser.

    Returns
    -------
    argparse.ArgumentParser
        Its verbs scan, record, run and emulate, with their flags.
    """
    top = ArgumentParser(prog="python3 -m leglab.bus",
                         description="Servos on a serial bus: scan, record, run, emulate.")
    verbs = top.add_subparsers(dest="verb", required=True, parser_class=ArgumentParser)
    scan = verbs.add_parser("scan", help="the servos on a port and their settings")
    _common(scan, ids_flag=None)
    scan.add_argument("--ids", type=_ids, help="only these ids (default 0-252)")

    record = verbs.add_parser("record", help="logs of the servos following excitations")
    _common(record)
    record.add_argument("--motor", type=_name,
                        help="the servo type's name in the logs (one model is fitted per name)")
    _drive(record)
    record.add_argument("--trajectory", type=_trajectories, required=True,
                        help=f"one or more of {', '.join(trajectories.NAMES)}, comma-separated")
    record.add_argument("--tick-s", type=_ranged(0.001, 0.1, " s"), default=0.005,
                        help="the recording's tick (default 0.005 s)")
    record.add_argument("--out", required=True, help="the folder the logs go into")

    run = verbs.add_parser("run", help="the servos following a desired motion")
    _common(run)
    run.add_argument("--model", required=True, help="identify's log_fit.json")
    run.add_argument("--desired",
                     help="a CSV time_s,desired_deg, or a servo log whose requests are the motion")
    run.add_argument("--method", choices=("direct", "model_based", "optimal"), required=True,
                     help="direct: the desired angles as they are; model_based, optimal: "
                          "the fitted model's requests")
    run.add_argument("--rung", choices=("extended", "paper"), default="extended",
                     help="the model file's rung planned with (default extended)")
    run.add_argument("--lead-ticks", type=_ranged(0, 1000, integer=True), default=0,
                     help="direct: send the desired angle this many ticks early (the paper's "
                          "time shift; default 0)")
    run.add_argument("--online", action="store_true",
                     help="requests from the online planner, tick by tick (default: the batch plan)")
    run.add_argument("--preview-ticks", type=_ranged(0, 100000, integer=True),
                     help="with --online: desired angles ahead (default: the method's own)")
    run.add_argument("--budget-ms", type=_ranged(0, 10000, " ms"),
                     help="with --online --method optimal: the time a tick's planning may take, "
                          "each servo's (default: half the model's tick shared among the servos; "
                          "on an emulator: none, the iteration cap alone, so that virtual time "
                          "gives the same requests every run)")
    run.add_argument("--motor", default="", help="the model file's motor (if it has several)")
    _drive(run)
    run.add_argument("--min-deg", type=_ranged(-180, 180, " deg"),
                     help="the requests' range (default -180 deg)")
    run.add_argument("--max-deg", type=_ranged(-180, 180, " deg"),
                     help="(default 180 deg)")
    run.add_argument("--max-speed-deg-s", type=_ranged(1, 100000, " deg/s"),
                     help="the requests' speed guard (default: the model's top speed)")
    run.add_argument("--out", required=True, help="the folder run.csv and run.json go into")

    emulate = verbs.add_parser("emulate", help="an emulated bus on a pseudo-terminal")
    emulate.add_argument("--protocol", choices=sorted(bus_module.PROTOCOLS), required=True)
    emulate.add_argument("--motor", type=_model, required=True,
                         help=f"the servo model: {', '.join(tables.TABLES)}")
    emulate.add_argument("--ids", type=_ids, required=True)
    emulate.add_argument("--mass-kg", type=_ranged(0, 1000, " kg"), required=True)
    emulate.add_argument("--length-m", type=_ranged(0, 10, " m"), required=True)
    emulate.add_argument("--kp", type=_ranged(0, 16383, integer=True),
                         help="the gain register at power-on (default: the factory's)")
    emulate.add_argument("--baud", type=int, default=1_000_000, choices=bus_module.BAUD_RATES,
                         metavar="B")
    emulate.add_argument("--link", help="also a symbolic link to the terminal at this path")
    _faults(emulate)
    return top


def _faults(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--drop-rate", type=_ranged(0, 1), default=0.0,
                        help="the share of replies not sent")
    parser.add_argument("--corrupt-rate", type=_ranged(0, 1), default=0.0,
                        help="the share of replies with a byte changed")
    parser.add_argument("--silent-after-s", type=_ranged(0, 1e9, " s"), default=math.inf,
                        help="servos stop answering after this time")
    parser.add_argument("--silent-ids", type=_ids, default=(),
                        help="which servos fall silent (default: all)")
    parser.add_argument("--hardware-error-after-s", type=_ranged(0, 1e9, " s"),
                        default=math.inf, help="an overload in every servo after this time")
    parser.add_argument("--seed", type=_ranged(0, 2**31, integer=True), default=0)


def emulated_port(spec: str, protocol: str, ids: list[int], mass_kg: float, length_m: float,
                  baud: int, loads: Optional[dict[int, tuple[float, float]]] = None
                  ) -> tuple[emulator.VirtualPort, emulator.VirtualClock]:
    """An emulated bus from `--port emulator:MODEL[,key=value...]`.

    Parameters
    ----------
    spec : str
        MODEL[,key=value...] with keys drop_rate, corrupt_rate, silent_after_s, silent_ids
        (1+2), hardware_error_after_s, seed, angle_deg (the load's start), kp (the gain at
        power-on), hang_deg (where the load hangs on the servo's 0-360 deg scale, default 180).
    protocol : str
        The bus's protocol.
    ids : list of int
        The servos.
    mass_kg, length_m : float
        Their load.
    baud : int
        The baud rate.
    loads : dict, optional
        {id: (mass_kg, length_m)} for servos with their own load.

    Returns
    -------
    (VirtualPort, VirtualClock)
        The port and its clock.

    Raises
    ------
    SessionError
        A bad spec, naming the key.
    """
    model, *pairs = spec.split(",")
    try:
        model = _model(model)
    except argparse.ArgumentTypeError as e:
        raise session.SessionError(f"--port emulator:{spec}: {e}") from None
    faults, extra, seen = emulator.Faults(), dict[str, Any](), set[str]()
    for pair in pairs:
        key, _, value = pair.partition("=")
        try:
            if key in seen:
                raise ValueError("given twice")
            seen.add(key)
            _emulator_setting(faults, extra, key, value, ids, model)
        except ValueError as e:
            raise session.SessionError(f"--port emulator:{spec}: {pair}: {e}") from None
    try:
        emulated = emulator.make_emulator(protocol, model, ids, mass_kg, length_m, baud=baud,
                                          faults=faults, loads=loads, **extra)
    except ValueError as e:
        raise session.SessionError(f"--port emulator:{spec}: {e}") from None
    clock = emulator.VirtualClock()
    return emulator.VirtualPort(emulated, clock, name=f"emulator:{model}"), clock


def _number(value: str, low: float, high: float, integer: bool = False) -> Union[int, float]:
    """`value` (text) as a number in [low, high]; ValueError otherwise."""
    number: Union[int, float] = int(value) if integer else float(value)
    if not low <= number <= high:  # NaN is in no range
        raise ValueError(f"{value} is outside [{low:g}, {high:g}]")
    return number


def _emulator_setting(faults: emulator.Faults, extra: dict[str, Any], key: str, value: str,
                      ids: Sequence[int], model: str) -> None:
    """One key=value of --port emulator:...: into `faults` or the emulator's `extra`."""
    if key == "silent_ids":
        silent = tuple(int(v) for v in value.split("+"))
        if len(set(silent)) != len(silent) or not set(silent) <= set(ids):
            raise ValueError(f"expected distinct ids of the bus's servos ({ids})")
        faults.silent_ids = silent
    elif key in ("drop_rate", "corrupt_rate"):
        setattr(faults, key, _number(value, 0, 1))
    elif key in ("silent_after_s", "hardware_error_after_s"):
        setattr(faults, key, _number(value, 0, 1e9))
    elif key == "seed":
        faults.seed = int(_number(value, 0, 2**31, integer=True))
    elif key == "hang_deg":  # where the load hangs on the servo's 0-360 scale
        extra["hang_count"] = round(_number(value, 0, 360) * 4096 / 360) % 4096
    elif key == "angle_deg":
        extra[key] = _number(value, -180, 180)
    elif key == "kp":
        extra[key] = _number(value, 0, tables.raw_range(
            tables.TABLES[model].item("position_p_gain"))[1], integer=True)
    else:
        raise ValueError("unknown key (valid: drop_rate, corrupt_rate, silent_after_s, "
                         "silent_ids, hardware_error_after_s, seed, angle_deg, kp, hang_deg)")


def open_bus(args: argparse.Namespace, joints: Sequence[Any] = ()
             ) -> tuple[bus_module.Bus, Union[emulator.VirtualClock, emulator.RealClock]]:
    """The bus of a verb's --port.

    Parameters
    ----------
    args : argparse.Namespace
        The verb's flags (port, protocol, baud, timeout_ms, retries, ids).
    joints : sequence of joints.Joint, optional
        What an emulated bus holds (ids and loads; by default servo 1 with 0.1 kg at 0.1 m).

    Returns
    -------
    (Bus, clock)
        The bus and the clock its loop runs on (virtual for an emulated bus).

    Raises
    ------
    SessionError, BusError
        A bad --port emulator:..., a port that cannot be opened.
    """
    timeout_s = args.timeout_ms / 1e3
    if args.port.startswith("emulator:"):
        ids = [j.id for j in joints] or (getattr(args, "ids", None) or [1])
        loads = {j.id: (j.mass_kg, j.length_m) for j in joints}
        port, virtual = emulated_port(args.port[len("emulator:"):], args.protocol, ids, 0.1, 0.1,
                                    args.baud, loads)
        return bus_module.Bus(port, args.protocol, args.baud, timeout_s, args.retries), virtual
    return (bus_module.Bus(args.port, args.protocol, args.baud, timeout_s, args.retries),
            emulator.RealClock())


def say(line: str) -> None:
    """A line of progress, on stdout at once.

    A reader that has gone (`| head`) is no fault of the session: its lines are dropped, and
    the session goes on to its end (torque off).

    Parameters
    ----------
    line : str
        The line.
    """
    try:
        print(line, flush=True)
    except BrokenPipeError:
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 (for the rest of the process)


def main(argv: Optional[list[str]] = None) -> int:
    """The command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (None: sys.argv[1:]).

    Returns
    -------
    int
        The exit status: 0, or 2 for bad input or a session a fault ended.
    """
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--list-outputs"]:  # the files each verb writes, as docs/outputs.md shows them
        from . import outputs
        print(outputs.markdown(), end="")
        return 0
    args = parser().parse_args(argv)
    from . import verbs  # the verbs' bodies (run needs the compiled leglab module)

    try:
        status: int = getattr(verbs, args.verb)(args)
        return status
    except (session.SessionError, bus_module.BusError, session.Stopped) as e:
        # Before the motion (set-up, zero, a refusal): nothing recorded yet.
        print(f"leglab.bus {args.verb}: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"leglab.bus {args.verb}: interrupted", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
