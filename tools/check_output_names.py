#!/usr/bin/python3
"""Finds output names spelled in more than one place: a CSV column or a JSON file's field (the
last key of its dotted path; docs/outputs.md, generated from the programs' declarations) or a
telemetry field (core/plant.h's TelemetryColumn declarations) written as a whole string literal
in more than one non-test source file besides the files that declare it. A column is declared once beside the code that fills it; a reader
takes it from there (leglab.results.reader's rows, the Python package's dicts), so a rename cannot
leave a reader behind.

A declaring file is one that holds the name as a declaration: a column {"name", "unit", ...}
(in Python, leglab.bus.outputs' Name("name", "unit", ...)) or a JSON field
{"path.to.name", "unit", ...},
a config key Key("name", ...) or a declared name, std::string_view field = "name" (a joint
model's values are its keys, named in joint_model.h). Names without
an underscore ("tick", "step", "mode", "joint") are words as much as names and are not
checked. Where one name still has several spellers they are listed in
tools/output_names.txt (name: file), a list that may only shrink: a finding not in it fails,
and so does an entry no longer found.

Usage: /usr/bin/python3 tools/check_output_names.py [SOURCE_DIR] [--list FILE] [--update]
Exit 0: nothing new; 1: a name spelled in one more place, or a stale entry, each on stderr.
"""
import os
import re
import sys

try:
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"check_output_names.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)
from shrinking_list import compare, read_entries, write_entries

FOLDERS = ("core", "model", "servo", "sim", "controller", "app", "experiments", "python",
           "scripts", "tools", "benchmarks", "examples")
SUFFIXES = (".cc", ".h", ".py", ".sh")
COLUMN = re.compile(r"^\| `([^`<>]+)` \|")
FIELD = re.compile(r"^\| `([^`]+)` \|")
TELEMETRY = re.compile(r'\{\{"(\w+)", "')
LITERAL = re.compile(r"\"([^\"\n\\\\]*)\"|'([^'\n\\\\]*)'")


def declared_names(source):
    """The CSV columns and the JSON fields' last keys (not a `<...>` or a list's `[]`) of
    docs/outputs.md and the telemetry fields of core/plant.h that hold an underscore."""
    names, in_columns = set(), False
    with open(os.path.join(source, "docs", "outputs.md"), encoding="utf-8") as f:
        for line in f:
            if line.startswith("| column |") or line.startswith("| field |"):
                in_columns = line.startswith("| column |")
            m = COLUMN.match(line)
            if m and in_columns:
                names.add(m.group(1))
            m = FIELD.match(line)
            if m and not in_columns:
                leaf = m.group(1).split(".")[-1]
                if "<" not in leaf and not leaf.endswith("[]"):
                    names.add(leaf)
    with open(os.path.join(source, "core", "include", "leglab", "core", "plant.h"),
              encoding="utf-8") as f:
        names.update(TELEMETRY.findall(f.read()))
    return {n for n in names if "_" in n}


def declares(text, name):
    """Whether a source declares `name`: a column's, a JSON field's, a config key's or a declared
    name's."""
    quoted = re.escape(f'"{name}"')
    dotted = re.escape(name)
    return re.search(rf"\{{\{{?{quoted}, \"|Key\({quoted},|std::string_view \w+ = {quoted};"
                     rf"|\{{\"[^\"]*\.{dotted}\", \"|Name\({quoted}, \"", text) is not None


def findings(source, names):
    """[(name, file)] of every name spelled in two or more non-declaring files, sorted."""
    spellers = {n: set() for n in names}
    for folder in FOLDERS:
        for root, dirs, files in os.walk(os.path.join(source, folder)):
            dirs[:] = sorted(d for d in dirs if d != "tests")
            for file in sorted(files):
                if not file.endswith(SUFFIXES):
                    continue
                path = os.path.join(root, file)
                rel = os.path.relpath(path, source)
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                spelled = {a or b for a, b in LITERAL.findall(text)} & names
                for name in spelled:
                    if not declares(text, name):
                        spellers[name].add(rel)
    return sorted((n, rel) for n, files in spellers.items() if len(files) > 1 for rel in files)


HEADER = """\
# Output names still spelled in more than one non-declaring source file
# (tools/check_output_names.py): name: file. This list may only shrink. Read the name from
# its declaration instead (leglab.results' reader, the package's dicts); then take its line out.
"""


def main(argv):
    parser = ArgumentParser(prog="check_output_names.py")
    parser.add_argument("source", nargs="?",
                        default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--list", help="the known ones (default: tools/output_names.txt)")
    parser.add_argument("--update", action="store_true", help="rewrite the list")
    args = parser.parse_args(argv)
    listed_path = args.list or os.path.join(args.source, "tools", "output_names.txt")
    found = findings(args.source, declared_names(args.source))
    if args.update:
        write_entries(listed_path, HEADER, found)
        print(f"output names: {len(found)} spellings listed in {listed_path}")
        return 0
    new, stale = compare(found, read_entries(listed_path))
    for name, rel in new:
        print(f"{rel}: spells the output name \"{name}\", which other sources spell too (read "
              f"it from its declaration: docs/outputs.md)", file=sys.stderr)
    for name, rel in stale:
        print(f"{listed_path}: \"{name}: {rel}\" is no longer found: take it out (--update)",
              file=sys.stderr)
    if new or stale:
        return 1
    print(f"output names: nothing new ({len(found)} spellings still listed)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
