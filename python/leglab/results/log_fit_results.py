"""What the results modules read of a log fit (log_fit.json, learned_fit.json): the methods its
logs are scored by, as their `mae_deg` keys name them, and the mean error per motor. report.py
and scripts/docs_numbers.py use it.
"""
from __future__ import annotations

from typing import Any, Iterable, Mapping, Sequence

from ..ladder import LADDER, label

__all__ = ["METHODS", "LEARNED", "logs_of", "mean_errors", "methods_of"]

# identify's methods (log_fit.json's `mae_deg` keys) with their names for a table, in the
# order of the ladder (servo/ladder.json): its baselines and models.
METHODS = tuple((r.name, r.label) for r in LADDER if r.kind != "learned")

# The networks leglab.servo.learned adds to each log's `mae_deg` in learned_fit.json.
LEARNED = tuple((r.name, r.label) for r in LADDER if r.kind == "learned")


def methods_of(logs: Sequence[Mapping[str, Any]]) -> tuple[tuple[str, str], ...]:
    """The methods scored logs hold, with their names for a table.

    Parameters
    ----------
    logs : sequence of mappings
        Rows of a log_fit.json's `logs` (logs_of).

    Returns
    -------
    tuple of (key, name)
        METHODS, then every other `mae_deg` key of the first row in its order (a rung added
        for that fit, named by ``leglab.ladder.label``); METHODS alone when there is no row.
    """
    keys = list(logs[0].get("mae_deg", {})) if logs else []
    known = {key for key, _ in METHODS + LEARNED}
    return METHODS + tuple((key, label(key)) for key in keys if key not in known)


def logs_of(fit: Mapping[str, Any], role: str) -> list[dict]:
    """The logs of a log fit with a role.

    Parameters
    ----------
    fit : mapping
        A parsed log_fit.json or learned_fit.json.
    role : str
        "validate" (each log scored by the models of the fold that held it out) or "train"
        (scored by the final models, fitted on every log).

    Returns
    -------
    list of dict
        Its `logs` entries with that role, in order.
    """
    return [log for log in fit.get("logs", []) if log.get("role") == role]


def mean_errors(logs: Iterable[Mapping[str, Any]],
                keys: Sequence[str]) -> tuple[dict[str, dict[str, float]], dict[str, int]]:
    """The mean error of each method per motor.

    Parameters
    ----------
    logs : iterable of mapping
        Logs of a log fit (logs_of()), each with `motor` and `mae_deg`.
    keys : sequence of str
        The `mae_deg` keys to average (METHODS' or LEARNED's first elements).

    Returns
    -------
    means : dict
        {motor: {key: mean of mae_deg[key] over that motor's logs}}.
    counts : dict
        {motor: its number of logs}.

    Raises
    ------
    KeyError, TypeError, ValueError
        When a log lacks a key or holds no number there.
    """
    sums: dict[str, dict[str, float]] = {}
    counts: dict[str, int] = {}
    for log in logs:
        motor = log["motor"]
        counts[motor] = counts.get(motor, 0) + 1
        row = sums.setdefault(motor, dict.fromkeys(keys, 0.0))
        for key in keys:
            row[key] += float(log["mae_deg"][key])
    means = {motor: {key: total / counts[motor] for key, total in row.items()}
             for motor, row in sums.items()}
    return means, counts
