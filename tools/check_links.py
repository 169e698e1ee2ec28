#!/usr/bin/env python3
"""Fails when a relative link or a repository path named in the docs or the sources does not
exist.

    /usr/bin/python3 tools/check_links.py [ROOT]

Checked:
- every relative Markdown link `[text](target)` in a .md file (README.md, CHANGELOG.md, docs/,
  every folder's README.md): the target file or folder exists, and an `#anchor` into a .md file
  names one of its headings (GitHub's slug: lower case, punctuation dropped, spaces to '-');
- every `find_package(leglab X.Y` written anywhere (docs, comments, CMake code) asks for the
  version the top-level CMakeLists.txt's project() declares (its major.minor): the package
  accepts only that (SameMinorVersion);
- every repository path written in a .md file, or in a comment of a source file (C++, Python,
  shell, CMake, YAML): a word starting with one of the top-level folders (`model/src/floor.cc`,
  `docs/design/floor.md`) must exist. Paths with a placeholder (`<name>`, `*`, `...`, `{`), the
  outputs' folders (results/, build/) and CHANGELOG.md's paths (history: files as they were
  then) are not checked.
Prints one line per broken link or path (file:line: what) and exits 1 if there is any.
"""

import functools
import pathlib
import re
import subprocess
import sys

try:
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"check_links.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)

TOP = ("core", "model", "servo", "sim", "controller", "app", "experiments", "python", "tests",
       "benchmarks", "scripts", "tools", "docs", "robots", "data", "examples", "cmake")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
PATH = re.compile(r"(?<![\w./-])((?:" + "|".join(TOP) + r")/[\w./+-]*[\w/])")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
FIND_PACKAGE = re.compile(r"find_package\(leglab (\d+\.\d+)")
PROJECT_VERSION = re.compile(r"project\(leglab VERSION (\d+\.\d+)")
# Where another version is written on purpose: history, and the check's own test.
HISTORY_AND_TESTS = {"CHANGELOG.md", "check_links_test.py"}
# Words that look like paths and are not: the sim benchmark's ratio label.
NOT_PATHS = {"sim/ode"}
SOURCE_SUFFIXES = {".h", ".cc", ".py", ".sh", ".yaml", ".yml", ".txt", ".cmake", ".in"}
COMMENT = {".h": "//", ".cc": "//", ".py": "#", ".sh": "#", ".yaml": "#", ".yml": "#",
           ".txt": "#", ".cmake": "#", ".in": "#"}


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading).strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


@functools.lru_cache(maxsize=None)
def anchors(path):
    """The #anchors of a .md file's headings (outside code blocks), repeats numbered as GitHub
    numbers them."""
    found, seen = set(), {}
    fenced = False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fenced = not fenced
        match = None if fenced else HEADING.match(line)
        if match:
            base = slug(match.group(1))
            count = seen.get(base, 0)
            found.add(base if count == 0 else f"{base}-{count}")
            seen[base] = count + 1
    return found


def tracked_files(root):
    listed = subprocess.run(["git", "-C", str(root), "ls-files"], capture_output=True, text=True,
                            check=True).stdout.split("\n")
    return [root / f for f in listed if f and (root / f).is_file()]


def placeholder(text):
    return any(mark in text for mark in ("<", "*", "...", "{", "$"))


def check_link(root, file, target):
    """None if the link resolves, else what is wrong."""
    if re.match(r"^[a-z]+:", target) or target.startswith("//"):
        return None  # a web address
    path_part, _, anchor = target.partition("#")
    resolved = (file.parent / path_part).resolve() if path_part else file
    if not resolved.exists():
        return f"link to '{target}': no such file"
    if anchor and resolved.suffix == ".md" and anchor not in anchors(resolved):
        return f"link to '{target}': no heading '#{anchor}' in {resolved.relative_to(root)}"
    return None


def check_path(root, word):
    if placeholder(word) or word in NOT_PATHS:
        return None
    if (root / word).exists():
        return None
    return f"names '{word}', which does not exist"


def project_version(root):
    """The major.minor of the top-level CMakeLists.txt's project(leglab VERSION ...), or None."""
    cmake = root / "CMakeLists.txt"
    match = PROJECT_VERSION.search(cmake.read_text(encoding="utf-8")) if cmake.is_file() else None
    return match.group(1) if match else None


def problems(root):
    found = []
    version = project_version(root)
    for file in tracked_files(root):
        if file.suffix != ".md" and file.suffix not in SOURCE_SUFFIXES:
            continue
        if "fuzz_regressions" in file.parts or file.name == "check_links.py":
            continue
        try:
            lines = file.read_text(encoding="utf-8").splitlines()
        except UnicodeDecodeError:
            continue
        for number, line in enumerate(lines, 1):
            where = f"{file.relative_to(root)}:{number}"
            for asked in FIND_PACKAGE.findall(line):
                if version and asked != version and file.name not in HISTORY_AND_TESTS:
                    found.append(f"{where}: find_package(leglab {asked}), but this is leglab "
                                 f"{version}, which refuses it")
            if file.suffix == ".md":
                for target in LINK.findall(line):
                    problem = check_link(root, file, target)
                    if problem:
                        found.append(f"{where}: {problem}")
                text = "" if file.name == "CHANGELOG.md" else LINK.sub("", line)
            else:
                marker = COMMENT[file.suffix]
                if marker not in line:
                    continue
                text = line[line.index(marker):]
            for word in PATH.findall(text):
                problem = check_path(root, word)
                if problem:
                    found.append(f"{where}: {problem}")
    return found


def main():
    parser = ArgumentParser(prog="check_links.py", description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default=pathlib.Path(__file__).resolve().parents[1],
                        metavar="ROOT", help="the repository (default: this one)")
    root = pathlib.Path(parser.parse_args().root).resolve()
    found = problems(root)
    for line in found:
        print(line)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
