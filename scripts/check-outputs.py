#!/usr/bin/python3
"""Checks that every CSV table in a results folder has the columns docs/outputs.md declares for
its file: the page is generated from the programs' declarations (--list-outputs), so this finds
a writer that does not write what it declares.

Usage: /usr/bin/python3 scripts/check-outputs.py RESULTS [--docs FILE]

Each *.csv under RESULTS (recursively; a sweep shard's first line, its stamp, skipped) is matched
to the declared file whose name pattern fits it (`<...>` stands for any text; the most specific
pattern wins). Its header must hold every declared column without a `<...>` in the declared
order, and nothing that matches no declared column (a `<...>` column matches any name of its
shape, in any place: a sweep's columns come per mode). A CSV no pattern fits is an error too.
Each difference is named on stderr, exit status 1; bad input (no RESULTS folder, no docs file):
one line, exit status 2.
"""
import argparse
import pathlib
import re
import sys

SOURCE_DIR = pathlib.Path(__file__).resolve().parent.parent
HEADING = re.compile(r"^### `([^`]+)`$")
COLUMN = re.compile(r"^\| `([^`]+)` \|")


def shape(name):
    """A regular expression for a declared name: `<...>` is any text without a comma or slash."""
    return re.compile("".join("[^,/]+" if part.startswith("<") else re.escape(part)
                              for part in re.split(r"(<[^>]+>)", name) if part) + r"\Z")


def declared_tables(docs):
    """{file pattern: [column names]} of every declared file that has columns."""
    tables, current = {}, None
    for line in docs.read_text(encoding="utf-8").splitlines():
        heading = HEADING.match(line)
        if heading:
            current = heading.group(1)
            continue
        column = COLUMN.match(line)
        if column and current is not None:
            tables.setdefault(current, []).append(column.group(1))
    return tables


def header_of(path):
    """A CSV's column names (after a sweep shard's stamp line)."""
    with open(path, encoding="utf-8") as f:
        line = f.readline()
        if line.startswith("#"):
            line = f.readline()
    return line.rstrip("\r\n").split(",")


def problems_of(name, header, columns):
    """What is wrong with `header` for a file declared with `columns`."""
    problems = []
    literals = [c for c in columns if "<" not in c]
    found = [c for c in header if c in literals]
    if found != literals:
        missing = [c for c in literals if c not in header]
        problems.append(f"{name}: declared columns missing or out of order: "
                        f"{', '.join(missing) or 'order ' + ', '.join(found)}")
    shapes = [shape(c) for c in columns]
    for c in header:
        if c not in literals and not any(s.match(c) for s in shapes):
            problems.append(f"{name}: column '{c}' is not declared")
    return problems


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results")
    parser.add_argument("--docs", default=str(SOURCE_DIR / "docs" / "outputs.md"))
    args = parser.parse_args(argv)
    results, docs = pathlib.Path(args.results), pathlib.Path(args.docs)
    if not results.is_dir():
        print(f"check-outputs: error: no results folder '{results}'", file=sys.stderr)
        return 2
    if not docs.is_file():
        print(f"check-outputs: error: no outputs reference '{docs}'", file=sys.stderr)
        return 2
    tables = declared_tables(docs)
    problems, checked = [], 0
    for path in sorted(results.rglob("*.csv")):
        name = str(path.relative_to(results))
        fitting = [p for p in tables if shape(p).match(path.name)]
        if not fitting:
            problems.append(f"{name}: no declared file has this name")
            continue
        pattern = max(fitting, key=lambda p: len(re.sub(r"<[^>]+>", "", p)))
        problems += problems_of(name, header_of(path), tables[pattern])
        checked += 1
    for problem in problems:
        print(f"check-outputs: {problem}", file=sys.stderr)
    if problems:
        return 1
    print(f"outputs: {checked} CSV files have their declared columns")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
