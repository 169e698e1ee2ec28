"""The files `python3 -m leglab.bus` writes, declared once: each CSV's columns and each JSON
file's fields, with units and meaning. The writers take their names from here, and
`python3 -m leglab.bus --list-outputs` prints them as the programs' --list-outputs do (for
docs/outputs.md)."""

from typing import NamedTuple


class Name(NamedTuple):
    """A column or field: its name (a JSON field's dotted path; <...> a part named at run
    time, [] every element of a list), unit and meaning."""

    name: str
    unit: str
    description: str


class File(NamedTuple):
    """A file: its name pattern, what it holds, and its columns (CSV) or fields (JSON)."""

    pattern: str
    description: str
    names: tuple


_TICKS = [Name("ticks", "", "ticks run"),
          Name("ticks_late", "", "ticks whose write ended after the next tick began, or that "
                                 "followed skipped ticks"),
          Name("ticks_skipped", "", "ticks that passed with no request sent (the loop woke "
                                    "too late)"),
          *(Name(f"{what}_ms.{q}", "ms", f"the {meaning}: {label}")
            for what, meaning in (("period", "time between tick starts"),
                                  ("work", "tick's work, sync read to sync write"))
            for q, label in (("median", "median"), ("p99", "99th percentile"),
                             ("max", "largest")))]

RUN_CSV = File(
    "run.csv",
    "`run`, one row a tick (with several servos, `run_id<id>.csv` for each). Angles are from "
    "the servo's zero.",
    (Name("time_s", "s", "the tick's start from the run's start, on the loop's clock"),
     Name("desired_deg", "deg", "the desired angle of the tick"),
     Name("request_deg", "deg", "the request sent, as the whole count it went out as"),
     Name("measured_deg", "deg", "the angle read at the tick's start, before its request"),
     Name("late", "", "1 when the tick was late (run.json's ticks_late)")))

RUN_CSV_PER_SERVO = File("run_id<id>.csv", "`run` with several servos: one servo's run.csv.",
                         RUN_CSV.names)

_SETUP = (Name("setup[].id", "", "a register the set-up changed: the servo"),
          Name("setup[].item", "", "the register (leglab.bus.tables' name)"),
          Name("setup[].before", "", "its value before, raw"),
          Name("setup[].after", "", "its value written, raw"),
          Name("setup[].unit", "", "what one count of it is, in the maker's words"))

_ERRORS = (("mae_deg", "mean absolute"), ("rms_deg", "root mean square"),
           ("max_abs_deg", "largest absolute"))

RUN_JSON = File(
    "run.json",
    "`run`'s summary: what plan predicts, measured.",
    (Name("method", "", "direct, model_based or optimal"),
     Name("online", "", "true: the online planner's requests; false: the batch plan's"),
     Name("rung", "", "the model's rung planned with: extended or paper"),
     Name("lead_ticks", "ticks", "direct: how early each desired angle was sent"),
     Name("preview_ticks", "ticks", "online: the desired ticks each request saw ahead"),
     *(Name(n, "deg", f"the {label} error of the measured angles from the desired ones, "
                      "every servo and tick") for n, label in _ERRORS),
     Name("predicted_mae_deg", "deg", "the model's mean absolute error for the same requests "
                                      "(plan's prediction; direct: the desired angles sent)"),
     *_TICKS,
     Name("tick_s", "s", "the tick: the model's"),
     Name("instructions", "", "instruction packets sent in the loop, retries included"),
     Name("retries", "", "instructions sent again after a missing or corrupt reply"),
     Name("errors", "", "instructions that failed after every retry"),
     Name("missing", "", "replies that did not come within the timeout"),
     Name("corrupt", "", "replies with a bad header, length or checksum"),
     Name("stale", "", "late replies to an earlier instruction, dropped"),
     Name("ended", "", "completed, or the one line of the fault or signal that ended the run"),
     Name("model", "", "the --model file"),
     *(Name(f"servos.<id>.{n}", "deg", f"this servo's {label} error") for n, label in _ERRORS),
     Name("servos.<id>.predicted_mae_deg", "deg", "this servo's predicted_mae_deg"),
     Name("servos.<id>.motor", "", "its model's motor"),
     Name("servos.<id>.kp", "", "its position gain register"),
     Name("servos.<id>.mass_kg", "kg", "its load's mass"),
     Name("servos.<id>.length_m", "m", "its load's arm"),
     Name("servos.<id>.zero_deg", "deg", "its zero on the servo's own 0-360 scale"),
     Name("servos.<id>.limits.min_deg", "deg", "its least request"),
     Name("servos.<id>.limits.max_deg", "deg", "its greatest request"),
     Name("servos.<id>.desired", "", "its desired motion's file"),
     *_SETUP))

LOG_JSON = File(
    "<trajectory>_kp<kp>_id<id>.json",
    "`record`: one servo on one trajectory, in BAM's log form, which identify and "
    "leglab.servo.read_log read with no other keys. Angles in radians from the zero.",
    (Name("mass", "kg", "the load's mass"), Name("length", "m", "the load's arm"),
     Name("kp", "", "the position gain register"), Name("vin", "V", "the servo's supply"),
     Name("motor", "", "the servo type (--motor): one model is fitted per name"),
     Name("trajectory", "", "the excitation (leglab.bus.trajectories)"),
     Name("id", "", "the servo's id"), Name("model", "", "the servo's model, as it reports it"),
     Name("protocol", "", "dynamixel or feetech"), Name("port", "", "the port"),
     Name("zero_deg", "deg", "the zero on the servo's own 0-360 scale"),
     Name("tick_s", "s", "the recording's tick"),
     *_TICKS,
     Name("retries", "", "instructions sent again in the session so far"),
     *_SETUP,
     Name("recorded_by", "", "the command that wrote it"),
     Name("ended", "", "completed, or the one line of what ended the recording early"),
     Name("entries[].timestamp", "s", "the tick's start from the trajectory's start"),
     Name("entries[].position", "rad", "the angle read at the tick's start"),
     Name("entries[].goal_position", "rad", "the request sent at the tick, to the count"),
     Name("entries[].torque_enable", "", "whether the torque was on")))

FILES = (("record", (LOG_JSON,)), ("run", (RUN_CSV, RUN_CSV_PER_SERVO, RUN_JSON)))
"""The files each verb writes into --out."""


def column_names(file):
    """The names of a file's columns or fields, in order."""
    return tuple(n.name for n in file.names)


def markdown():
    """The declarations as docs/outputs.md shows a program's (--list-outputs)."""
    out = []
    for _, files in FILES:
        for f in files:
            kind = "column" if f.pattern.endswith(".csv") else "field"
            out.append(f"### `{f.pattern}`\n\n{f.description}\n\n| {kind} | unit | description |"
                       "\n|---|---|---|")
            out += [f"| `{n.name}` | {n.unit} | {n.description} |" for n in f.names]
            out.append("")
    return "\n".join(out)
