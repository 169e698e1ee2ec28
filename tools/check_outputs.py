#!/usr/bin/python3
"""Checks that every CSV table in a results folder has the columns docs/outputs.md declares for
its file, and every JSON file a program declares only the fields it declares: the page is
generated from the programs' declarations (--list-outputs), so this finds a writer that does not
write what it declares.

Usage: /usr/bin/python3 tools/check_outputs.py RESULTS [--docs FILE]

Each *.csv under RESULTS (recursively; a sweep shard's first line, its stamp, skipped) is matched
to the declared file whose name pattern fits it (`<...>` stands for any text; the most specific
pattern wins). Its header must hold every declared column without a `<...>` in the declared
order, and nothing that matches no declared column (a `<...>` column matches any name of its
shape, in any place: a sweep's columns come per mode). A CSV no pattern fits is an error too;
one under a folder named `inputs` is a run's input, not an output (scripts/variants.py's walks).
Each *.json whose name a program declares must hold no field its declaration lacks (a field's
dotted path, `<...>` any one key, `[]` a list's elements; a field the run did not need may be
absent); other JSON files (a script's, learned_fit.json) are not checked. Each difference is named on stderr, exit status 1; bad input (no RESULTS folder, no docs file):
one line, exit status 2.
"""
import json
import pathlib
import sys

try:
    from leglab.results.reader import (ArgumentParser, column_problems, declared_pattern,
                                       declared_tables, field_problems)
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"check_outputs.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

SOURCE_DIR = pathlib.Path(__file__).resolve().parent.parent

def header_of(path):
    """A CSV's column names (after a sweep shard's stamp line)."""
    with open(path, encoding="utf-8") as f:
        line = f.readline()
        if line.startswith("#"):
            line = f.readline()
    return line.rstrip("\r\n").split(",")


def main(argv):
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results")
    parser.add_argument("--docs", default=str(SOURCE_DIR / "docs" / "outputs.md"))
    args = parser.parse_args(argv)
    results, docs = pathlib.Path(args.results), pathlib.Path(args.docs)
    if not results.is_dir():
        print(f"check_outputs: error: no results folder '{results}'", file=sys.stderr)
        return 2
    if not docs.is_file():
        print(f"check_outputs: error: no outputs reference '{docs}'", file=sys.stderr)
        return 2
    tables = declared_tables(docs)
    problems, checked = [], 0
    for path in sorted(results.rglob("*.csv")):
        name = str(path.relative_to(results))
        if "inputs" in path.relative_to(results).parts[:-1]:
            continue
        pattern = declared_pattern(path.name, tables)
        if pattern is None:
            problems.append(f"{name}: no declared file has this name")
            continue
        problems += column_problems(name, header_of(path), tables[pattern])
        checked += 1
    # A JSON file a program declares: every field it holds is declared (a field the run did not
    # need, the test stand's say, may be absent). Others (learned_fit.json, a script's) are not
    # the programs'.
    for path in sorted(results.rglob("*.json")):
        pattern = declared_pattern(path.name, tables)
        if pattern is None:
            continue
        name = str(path.relative_to(results))
        try:
            with open(path, encoding="utf-8") as f:
                value = json.load(f)
        except (OSError, UnicodeDecodeError, ValueError) as e:
            problems.append(f"{name}: not JSON ({e})")
            continue
        problems += field_problems(name, value, tables[pattern])
        checked += 1
    for problem in problems:
        print(f"check_outputs: {problem}", file=sys.stderr)
    if problems:
        return 1
    print(f"outputs: {checked} CSV and JSON files have their declared columns and fields")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
