#!/usr/bin/python3
"""Finds ranges written by hand: a message in the sources that states a value's range ("must be
positive", "must be in [0, 50]", ">= 1", "from 0 to 200") instead of deriving it from a
declaration (a KeyDoc, checked by CheckKeys, KeysProblem or KeyValueProblem, whose messages
say the declared range). A range declared once is documented (docs/configuration.md), checked
alike by the programs, the Python package and the constructors, and cannot drift between them.

The ranges still written by hand are listed in tools/hand_ranges.txt (file and message
text), a list that may only shrink: a finding not in it fails the check (declare the value
instead: docs/design/config-keys.md), and so does an entry no longer found (take it out).

Usage: /usr/bin/python3 tools/check_ranges.py [SOURCE_DIR] [--list FILE] [--update]
  --update rewrites the list with what is found now (for taking entries out).
Exit 0: nothing new; 1: a new hand-written range or a stale entry, each named on stderr.
"""
import os
import re
import sys

try:
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"check_ranges.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)
from shrinking_list import compare, read_entries, write_entries

FOLDERS = ("core", "model", "servo", "sim", "controller", "app", "experiments", "python/src")
# The declarations' own machinery, which turns a KeyDoc into these words.
EXEMPT = {"core/include/leglab/core/config_keys.h"}
LITERAL = re.compile(r'"((?:[^"\\]|\\.)*)"')
RANGE_WORDS = re.compile(
    r"must be\b[^\"]*?(?:\bin [\[(]|\bpositive\b(?! definite)|\bnon-negative\b|>=|<=|"
    r"[<>] ?-?\d|\bat least\b|\bat most\b|\bfrom -?\d|\bbetween\b|\bwithin\b)|"
    r"expected an integer from")


def findings(source):
    """[(path, message literal)] of every hand-written range in the library and program
    sources, in file order."""
    found = []
    for folder in FOLDERS:
        for root, dirs, files in os.walk(os.path.join(source, folder)):
            dirs.sort()
            for name in sorted(files):
                if not name.endswith((".cc", ".h")):
                    continue
                path = os.path.join(root, name)
                rel = os.path.relpath(path, source)
                if rel in EXEMPT:
                    continue
                with open(path, encoding="utf-8") as f:
                    for line in f:
                        if line.lstrip().startswith("//"):
                            continue
                        for literal in LITERAL.findall(line):
                            if RANGE_WORDS.search(literal):
                                found.append((rel, literal.strip()))
    return found


HEADER = """\
# Ranges still written by hand in the sources (tools/check_ranges.py): file: message text.
# This list may only shrink. Declare a value's range once (a KeyDoc beside its struct's
# VisitKeys) and check it through the declaration instead; then take its line out.
"""


def main(argv):
    parser = ArgumentParser(prog="check_ranges.py")
    parser.add_argument("source", nargs="?",
                        default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--list", help="the list of known ones (default: tools/hand_ranges.txt)")
    parser.add_argument("--update", action="store_true", help="rewrite the list")
    args = parser.parse_args(argv)
    listed_path = args.list or os.path.join(args.source, "tools", "hand_ranges.txt")
    found = findings(args.source)
    if args.update:
        write_entries(listed_path, HEADER, found)
        print(f"ranges: {len(found)} written by hand, listed in {listed_path}")
        return 0
    new, stale = compare(found, read_entries(listed_path))
    for rel, literal in new:
        print(f"{rel}: a range written by hand: \"{literal}\" (declare it once, a KeyDoc, and "
              f"check through the declaration: docs/design/config-keys.md)", file=sys.stderr)
    for rel, literal in stale:
        print(f"{listed_path}: \"{rel}: {literal}\" is no longer in the sources: take it out "
              f"(--update)", file=sys.stderr)
    if new or stale:
        return 1
    print(f"ranges: nothing new ({len(found)} still written by hand, listed)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
