"""The tables `python3 -m leglab.bus` writes, declared once: each CSV's columns, with units and
meaning. The writers take their names from here, and `python3 -m leglab.bus --list-outputs`
prints them as the programs' --list-outputs do (for docs/outputs.md)."""

from __future__ import annotations

from typing import NamedTuple


class Name(NamedTuple):
    """A column: its name, unit and meaning."""

    name: str
    unit: str
    description: str


class File(NamedTuple):
    """A file: its name pattern, what it holds, and its columns."""

    pattern: str
    description: str
    names: tuple[Name, ...]


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

FILES = (("run", (RUN_CSV, RUN_CSV_PER_SERVO)),)
"""The tables each verb writes into --out. run.json and record's logs (BAM's JSON form, which
identify reads) are described field by field in docs/real-servos.md."""


def column_names(file: File) -> tuple[str, ...]:
    """The names of a file's columns, in order.

    Parameters
    ----------
    file : File
        The file's declaration.

    Returns
    -------
    tuple of str
        Its column names.
    """
    return tuple(n.name for n in file.names)


def markdown() -> str:
    """The declarations as docs/outputs.md shows a program's (--list-outputs).

    Returns
    -------
    str
        The Markdown text.
    """
    out = []
    for _, files in FILES:
        for f in files:
            out.append(f"### `{f.pattern}`\n\n{f.description}\n\n| column | unit | description |"
                       "\n|---|---|---|")
            out += [f"| `{n.name}` | {n.unit} | {n.description} |" for n in f.names]
            out.append("")
    return "\n".join(out)


if __name__ == "__main__":  # tools/gen_config_docs.sh, which needs no built package
    print(markdown(), end="")
