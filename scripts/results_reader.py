"""The files the programs write, read one way for every script (report.py, plot_figures.py,
plot_logs.py, plot_sweep.py, animate.py, compare_engines.py): CSV tables as rows keyed by
column name, JSON as parsed, a Markdown table row as its cells. UTF-8 whatever the locale. Errors are the caller's to turn into
its one-line exit 2: OSError, UnicodeDecodeError and ValueError (a JSON syntax error) as
Python raises them, csv.Error for a malformed CSV.

Imported from the scripts' folder (Python puts a script's own folder first on its path).
"""
import csv
import json
import re


def read_csv(path):
    """A CSV table: (header, rows), each row a dict from column name to text (a short row's
    missing cells None, a long row's extra cells under None, as csv.DictReader gives them)."""
    with open(path, encoding="utf-8", newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        return list(reader.fieldnames or []), rows


def read_rows(path):
    """read_csv's rows alone."""
    return read_csv(path)[1]


def read_json(path):
    """A JSON file, parsed."""
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def split_row(line):
    """The cells of a Markdown table row ('| a | b |'), with '\\|' kept as a literal bar."""
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    cells = re.split(r"(?<!\\)\|", line)
    return [c.strip().replace("\\|", "|") for c in cells]
