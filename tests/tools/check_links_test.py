#!/usr/bin/env python3
"""tools/check_links.py finds what it is for: a small repository written here, whose links
and paths are right, then broken one at a time by hand; each break is reported by file and line
and fails the check."""

import pathlib
import subprocess
import sys
import tempfile

SCRIPT = pathlib.Path(sys.argv[1]) / "tools" / "check_links.py"


def check(root):
    subprocess.run(["git", "-C", str(root), "add", "-A"], check=True)
    result = subprocess.run([sys.executable, str(SCRIPT), str(root)], capture_output=True,
                            text=True, check=False)
    return result.returncode, result.stdout.strip().splitlines()


def main():
    with tempfile.TemporaryDirectory() as scratch:
        root = pathlib.Path(scratch)
        subprocess.run(["git", "init", "-q", str(root)], check=True)
        (root / "docs" / "design").mkdir(parents=True)
        (root / "model" / "src").mkdir(parents=True)
        (root / "model" / "src" / "floor.cc").write_text("// See docs/design/floor.md.\n")
        (root / "docs" / "design" / "floor.md").write_text("# The floor\n\n## Why O(T)\n")
        readme = "See [the floor](docs/design/floor.md#why-ot) and `model/src/floor.cc`.\n"
        (root / "README.md").write_text(readme)
        status, lines = check(root)
        assert status == 0 and not lines, lines

        (root / "README.md").write_text(readme.replace("#why-ot", "#why-o-t"))
        status, lines = check(root)
        assert status == 1 and lines == [
            "README.md:1: link to 'docs/design/floor.md#why-o-t': no heading '#why-o-t' in "
            "docs/design/floor.md"], lines

        (root / "README.md").write_text(readme.replace("floor.md#", "flor.md#"))
        status, lines = check(root)
        assert status == 1 and lines == [
            "README.md:1: link to 'docs/design/flor.md#why-ot': no such file"], lines

        (root / "README.md").write_text(readme)
        (root / "model" / "src" / "floor.cc").write_text("// See docs/design/floors.md.\n")
        status, lines = check(root)
        assert status == 1 and lines == [
            "model/src/floor.cc:1: names 'docs/design/floors.md', which does not exist"], lines

        (root / "model" / "src" / "floor.cc").write_text("// See docs/design/floor.md.\n")
        (root / "CMakeLists.txt").write_text("project(leglab VERSION 0.2.0 LANGUAGES CXX)\n"
                                             "# find_package(leglab 0.2) gives leglab::model\n")
        status, lines = check(root)
        assert status == 0 and not lines, lines
        (root / "docs" / "install.md").write_text("find_package(leglab 0.1 REQUIRED)\n")
        status, lines = check(root)
        assert status == 1 and lines == [
            "docs/install.md:1: find_package(leglab 0.1), but this is leglab 0.2, which refuses "
            "it"], lines
    print("check_links: every hand-made break found")


if __name__ == "__main__":
    main()
