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
With --installed PREFIX (a prefix `cmake --install` filled) or --build DIR (the build folder,
installed here into a temporary prefix with --cmake, default `cmake`), also what the build
installs against what the docs say it does:
- every install path docs/design/install.md's list of what is installed names
  (`include/leglab/{core,model}/`, `share/leglab/robots/`, `lib/cmake/leglab/`, the Python
  package's folder when the build made one) exists in the prefix, and its include/leglab/
  folders are all the installed ones;
- each list of the programs (install.md's `bin/...`, README.md's "The programs are ...",
  docs/results-page.md's programs whose folders the page reads) names exactly the programs
  installed in <prefix>/bin.
Prints one line per broken link or path (file:line: what) and exits 1 if there is any.
"""

import functools
import itertools
import pathlib
import re
import subprocess
import sys
import tempfile

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


INSTALL_PAGE = "docs/design/install.md"
# Where the docs list every program: (file, the list's text as a regex group). A program is a
# backquoted word (`track`) or a `bin/<program>` path in it.
PROGRAM_LISTS = ((INSTALL_PAGE, r"^- the programs (.*?);$"),
                 ("README.md", r"^The programs are (.*?); they are built"),
                 ("docs/results-page.md", r"\(`--out /tmp/x` of (.*?)\)"))
INSTALLED = re.compile(r"`(?:<prefix>/)?((?:include|bin|share|lib|\$\{LEGLAB_PYTHON_INSTALL_DIR\})"
                       r"/[^`]*)`")
PROGRAM = re.compile(r"`(?:bin/)?([a-z][a-z0-9_]*)`")


def paragraphs(path):
    """A .md file's paragraphs and list items, each joined into one line, with its first line's
    number."""
    found, lines, first = [], [], 0
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("- "):
            if lines:
                found.append((first, " ".join(lines)))
            lines, first = ([line.strip()], number) if line.strip() else ([], 0)
        else:
            lines, first = lines + [line.strip()], first or number
    if lines:
        found.append((first, " ".join(lines)))
    return found


def expand(path):
    """`include/leglab/{core,model}/` as the paths it stands for."""
    match = re.search(r"\{([^}]*)\}", path)
    if not match:
        return [path]
    return list(itertools.chain.from_iterable(
        expand(path[:match.start()] + part + path[match.end():])
        for part in match.group(1).split(",")))


def installed_list(root):
    """install.md's list of what is installed: (line, text) of each of its items."""
    items, listing = [], False
    for number, text in paragraphs(root / INSTALL_PAGE):
        if text == "installs":
            listing = True
        elif listing and text.startswith("- "):
            items.append((number, text))
        elif listing:
            break
    return items


def install_problems(root, prefix, python_dir=None):
    """What install.md and the program lists say against the prefix a build was installed
    into; `python_dir` is LEGLAB_PYTHON_INSTALL_DIR when the build made the Python package."""
    found = []
    items = installed_list(root)
    if not items:
        return [f"{INSTALL_PAGE}: no list of what `cmake --install` installs (\"installs\" and "
                "its items)"]
    for number, text in items:
        for written in INSTALLED.findall(text):
            if "${LEGLAB_PYTHON_INSTALL_DIR}" in written:
                if python_dir is None:
                    continue
                written = written.replace("${LEGLAB_PYTHON_INSTALL_DIR}", python_dir)
            for path in expand(written):
                if not (prefix / path).exists():
                    found.append(f"{INSTALL_PAGE}:{number}: names '{path}', which the build does "
                                 "not install")
            if written.startswith("include/leglab/{"):
                named = {pathlib.Path(p).name for p in expand(written)}
                folders = {p.name for p in (prefix / "include" / "leglab").iterdir()}
                for folder in sorted(folders - named):
                    found.append(f"{INSTALL_PAGE}:{number}: the build installs include/leglab/"
                                 f"{folder}/, which it does not name")
    programs = {p.name for p in (prefix / "bin").iterdir()} if (prefix / "bin").is_dir() else set()
    for file, pattern in PROGRAM_LISTS:
        lists = [(number, match.group(1)) for number, text in paragraphs(root / file)
                 for match in [re.search(pattern, text)] if match]
        if not lists:
            found.append(f"{file}: no list of the programs (/{pattern}/)")
        for number, text in lists:
            named = set(PROGRAM.findall(text))
            for program in sorted(named - programs):
                found.append(f"{file}:{number}: lists the program '{program}', which the build "
                             "does not install")
            for program in sorted(programs - named):
                found.append(f"{file}:{number}: the build installs the program '{program}', "
                             "which this list lacks")
    return found


def cache_value(build, name):
    """A CMakeCache.txt entry's value, or None."""
    cache = build / "CMakeCache.txt"
    for line in cache.read_text(encoding="utf-8").splitlines() if cache.is_file() else []:
        if line.startswith(name + ":"):
            return line.partition("=")[2]
    return None


def build_install_problems(root, build, cmake):
    """install_problems on `build` installed into a temporary prefix."""
    with tempfile.TemporaryDirectory() as prefix:
        subprocess.run([cmake, "--install", str(build), "--prefix", prefix], check=True,
                       stdout=subprocess.DEVNULL)
        python_dir = None
        if cache_value(build, "LEGLAB_PYTHON") in ("ON", "TRUE", "1"):
            python_dir = cache_value(build, "LEGLAB_PYTHON_INSTALL_DIR")
        return install_problems(root, pathlib.Path(prefix), python_dir)


def main():
    parser = ArgumentParser(prog="check_links.py", description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default=pathlib.Path(__file__).resolve().parents[1],
                        metavar="ROOT", help="the repository (default: this one)")
    against = parser.add_mutually_exclusive_group()
    against.add_argument("--installed", metavar="PREFIX",
                         help="also check the install page and the program lists against PREFIX")
    against.add_argument("--build", metavar="DIR",
                         help="the same against DIR installed into a temporary prefix")
    parser.add_argument("--python-dir", metavar="DIR",
                        help="with --installed: the Python package's folder in PREFIX")
    parser.add_argument("--cmake", default="cmake", help="with --build: the cmake to install with")
    args = parser.parse_args()
    root = pathlib.Path(args.root).resolve()
    found = problems(root)
    if args.installed:
        found += install_problems(root, pathlib.Path(args.installed).resolve(), args.python_dir)
    elif args.build:
        found += build_install_problems(root, pathlib.Path(args.build).resolve(), args.cmake)
    for line in found:
        print(line)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
