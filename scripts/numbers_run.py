"""A results folder's files as scripts/docs_numbers.py's blocks read them, and the cells' formats.

A block reads RESULTS' files through a Run (each file read once, checked against its
declaration); a file RESULTS lacks raises Missing, which cell() turns into UNKNOWN (a cell the
check does not compare and --write never writes).
"""
import csv
import os

import yaml

from leglab.results.reader import read_json, read_rows


JOINTS = ("rotator", "abductor", "knee")


class UserError(Exception):
    """Bad input: one line, exit 2."""


class Missing(Exception):
    """A file of RESULTS that a cell needs is not there."""


class Run:
    """RESULTS' files, each read once; `missing` collects what was asked for and absent."""

    def __init__(self, folder):
        self.folder = folder
        self.cache = {}
        self.missing = set()

    def json(self, rel):
        """A JSON file of RESULTS, parsed."""
        return self._read(rel, read_json, "JSON", (OSError, UnicodeDecodeError, ValueError))

    def rows(self, rel):
        """A CSV file of RESULTS as rows keyed by column."""
        return self._read(rel, read_rows, "CSV", (OSError, UnicodeDecodeError, csv.Error))

    def yaml(self, rel):
        """A YAML file of RESULTS (a program's record of its config), parsed."""
        def read(path):
            with open(path, encoding="utf-8") as f:
                return yaml.safe_load(f)
        return self._read(rel, read, "YAML", (OSError, UnicodeDecodeError, yaml.YAMLError))

    def _read(self, rel, reader, kind, errors):
        if rel not in self.cache:
            path = os.path.join(self.folder, rel)
            if not os.path.isfile(path):
                self.missing.add(rel)
                raise Missing(rel)
            try:
                self.cache[rel] = reader(path)
            except errors as e:
                raise UserError(f"{path}: not readable as {kind}: {e}") from None
        return self.cache[rel]


# A cell whose file RESULTS lacks: matches any text in a check, never written.
UNKNOWN = None


def cell(compute):
    """compute(), or UNKNOWN if a file it reads is missing."""
    try:
        return compute()
    except Missing:
        return UNKNOWN


def fixed(value, digits=2):
    return f"{float(value):.{digits}f}"


def paper_value(value):
    """A published number as the paper prints it (31.0, 2.7, 4)."""
    return str(value)


def with_paper(value, paper):
    """Ours to two decimals with the paper's in brackets: "11.42 [31.0]"."""
    return f"{fixed(value)} [{paper_value(paper)}]"


def joint_norm(table2, key, joint):
    return fixed(table2["joints"][joint][key]["mean"])
