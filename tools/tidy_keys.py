"""Keys for tools/check_tidy.sh's cache of files clang-tidy found clean.

Usage, from the source tree's root:
  {clang-tidy --version; cat .clang-tidy;} | tidy_keys.py BUILD_DIR FILE...
Prints "<key> <file>" for each FILE, where the key is a SHA-256 of the standard input (the
checker and its configuration), the file's compile commands in BUILD_DIR/compile_commands.json,
and the contents of every file the build recorded as the object's dependencies (ninja -t deps:
the source and every header it includes, system headers too). A file without a compile command
or without recorded dependencies gets the key "-" (always checked). The source tree's own path
is replaced by a placeholder first, so that two clones of one commit have the same keys.
"""
import collections
import hashlib
import json
import os
import shlex
import subprocess
import sys

try:
    from leglab.results.reader import ArgumentParser
except ImportError as _error:  # leglab is found through PYTHONPATH
    print(f"tidy_keys.py: {_error}: set PYTHONPATH=<build>/python", file=sys.stderr)
    sys.exit(2)


def main():
    parser = ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build", metavar="BUILD_DIR")
    parser.add_argument("files", nargs="*", metavar="FILE")
    args = parser.parse_args()
    build, files = args.build, args.files
    salt = sys.stdin.buffer.read()
    with open(os.path.join(build, "compile_commands.json")) as f:
        commands = json.load(f)
    by_file = collections.defaultdict(list)
    for entry in commands:
        path = os.path.realpath(os.path.join(entry["directory"], entry["file"]))
        by_file[path].append(entry)

    deps = parse_deps(subprocess.run(["ninja", "-C", build, "-t", "deps"], check=True,
                                     capture_output=True, text=True).stdout)
    content = {}

    def digest(path):
        if path not in content:
            try:
                with open(path, "rb") as f:
                    content[path] = hashlib.sha256(f.read()).digest()
            except OSError:
                content[path] = b"missing"
        return content[path]

    # The clone's own folder is left out of the key, so that a clone elsewhere shares it.
    root = os.getcwd()

    def relative(text):
        return text.replace(root, "<root>")

    for name in files:
        entries = by_file.get(os.path.realpath(name), [])
        h = hashlib.sha256(salt)
        complete = bool(entries)
        for entry in sorted(entries, key=output_of):
            h.update(relative(json.dumps(entry, sort_keys=True)).encode())
            output = output_of(entry)
            if output is None or output not in deps:
                complete = False
                break
            for dep in deps[output]:
                path = os.path.normpath(os.path.join(build, dep))
                h.update(relative(path).encode() + b"\0" + digest(path))
        print(f"{h.hexdigest() if complete else '-'} {name}")


def output_of(entry):
    """The object a compile command writes: its "output", or the argument of its -o."""
    if "output" in entry:
        return entry["output"]
    args = entry.get("arguments") or shlex.split(entry["command"])
    return args[args.index("-o") + 1] if "-o" in args else ""


def parse_deps(text):
    """ninja -t deps: "<output>: #deps N, deps mtime M (VALID)" then indented paths."""
    deps, current = {}, None
    for line in text.splitlines():
        if not line.strip():
            current = None
        elif line.startswith(" "):
            if current is not None:
                deps[current].append(line.strip())
        else:
            output, _, rest = line.partition(": #deps")
            current = output if "(VALID)" in rest else None
            if current is not None:
                deps[current] = []
    return deps


if __name__ == "__main__":
    main()
