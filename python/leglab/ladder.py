"""The servo model ladder, as ``servo/ladder.json`` declares it once.

Each rung is a way of predicting a servo's measured angle from its requests: the baselines
(the request itself, the best time shift in hindsight), the models ``identify`` fits (the
paper's, the extended) and the networks ``leglab.servo.learned`` trains. ``identify`` compiles
the same file in, so the names here are log_fit.json's ``mae_deg`` keys and the log CSVs'
``<name>_deg`` columns. Pure Python: importable without the compiled module.
"""

from __future__ import annotations

import json
import pathlib
from typing import NamedTuple

__all__ = ["Rung", "LADDER", "KINDS", "rung", "label"]

#: The kinds of rung, in the order of the ladder.
KINDS = ("baseline", "model", "learned")


class Rung(NamedTuple):
    """One rung of the ladder (see ``servo/ladder.json``'s ``about`` for each field)."""

    name: str
    """log_fit.json's key and the CSV column's stem (``<name>_deg``)."""
    kind: str
    """``baseline``, ``model`` or ``learned``."""
    label: str
    """Its heading in tables."""
    description: str
    """What it predicts, a phrase."""
    column: str
    """The log CSV column's description."""
    legend: str
    """Its curve's label in a figure."""
    color: str
    """Its curve's matplotlib color."""
    linestyle: str
    """Its curve's matplotlib line style."""


def _read(path: pathlib.Path) -> tuple[Rung, ...]:
    with open(path, encoding="utf-8") as f:
        rungs = json.load(f)["rungs"]
    return tuple(Rung(name=r["name"], kind=r["kind"], label=r["label"],
                      description=r["description"], column=r["column"], legend=r["legend"],
                      color=r["style"]["color"], linestyle=r["style"]["linestyle"])
                 for r in rungs)


#: Every rung, in the order tables show them.
LADDER: tuple[Rung, ...] = _read(pathlib.Path(__file__).with_name("ladder.json"))


def rung(name: str) -> Rung | None:
    """The ladder's rung named `name`.

    Parameters
    ----------
    name : str
        A rung's name, e.g. ``"best_shift"``.

    Returns
    -------
    Rung or None
        The rung, or None when the ladder has none of that name (a rung added for one fit).
    """
    return next((r for r in LADDER if r.name == name), None)


def label(name: str) -> str:
    """A rung's heading in tables.

    Parameters
    ----------
    name : str
        A rung's name, one of the ladder's or one added for a fit.

    Returns
    -------
    str
        The ladder's label, or for a rung the ladder does not hold its name with spaces for
        underscores.
    """
    found = rung(name)
    return found.label if found else name.replace("_", " ")
