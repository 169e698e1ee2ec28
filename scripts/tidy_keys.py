"""Keys for scripts/check-tidy.sh's cache of files clang-tidy found clean.

Usage: {clang-tidy --version; cat .clang-tidy;} | tidy_keys.py BUILD_DIR FILE...
Prints "<key> <file>" for each FILE, where the key is a SHA-256 of the standard input (the
checker and its configuration), the file's compile commands in BUILD_DIR/compile_commands.json,
and the contents of every file the build recorded as the object's dependencies (ninja -t deps:
the source and every header it includes, system headers too). A file without a compile command
or without recorded dependencies gets the key "-" (always checked).
"""
import collections
import hashlib
import json
import os
import subprocess
import sys


def main():
    build, files = sys.argv[1], sys.argv[2:]
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

    for name in files:
        entries = by_file.get(os.path.realpath(name), [])
        h = hashlib.sha256(salt)
        complete = bool(entries)
        for entry in sorted(entries, key=lambda e: e.get("output", "")):
            h.update(json.dumps(entry, sort_keys=True).encode())
            output = entry.get("output")
            if output is None or output not in deps:
                complete = False
                break
            for dep in deps[output]:
                path = os.path.normpath(os.path.join(build, dep))
                h.update(path.encode() + b"\0" + digest(path))
        print(f"{h.hexdigest() if complete else '-'} {name}")


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
