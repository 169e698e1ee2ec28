#!/usr/bin/env python3
"""tools/check_links.py finds what it is for: a small repository written here, whose links
and paths are right, then broken one at a time by hand; each break is reported by file and line
and fails the check. The same for its --installed check of the install page and the program
lists against a prefix made by hand."""

import pathlib
import subprocess
import sys
import tempfile

SCRIPT = pathlib.Path(sys.argv[1]) / "tools" / "check_links.py"


def check(root, *args):
    subprocess.run(["git", "-C", str(root), "add", "-A"], check=True)
    result = subprocess.run([sys.executable, str(SCRIPT), str(root), *args], capture_output=True,
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
        (root / "docs" / "install.md").unlink()
        check_install(root)
    print("check_links: every hand-made break found")


INSTALL_PAGE = """# Installing

```sh
cmake --install build --prefix ~/.local
```

installs

- the static libraries and their headers
  (`include/leglab/{core,model}/`);
- the programs `bin/identify` and `bin/track`;
- a CMake package in `lib/cmake/leglab/`.

Another project uses it.
"""


def check_install(root):
    """--installed: install.md's paths and the three program lists against a prefix."""
    (root / "docs" / "design" / "install.md").write_text(INSTALL_PAGE)
    readme = (root / "README.md").read_text()
    (root / "README.md").write_text(
        readme + "\nThe programs are `identify` (Table 1) and `track` (Table 2); they are built\n"
        "into `build/bin/`.\n")
    (root / "docs" / "results-page.md").write_text(
        "Any folder works (`--out /tmp/x` of `identify`, `track`).\n")
    with tempfile.TemporaryDirectory() as scratch:
        prefix = pathlib.Path(scratch)
        for folder in ("bin", "include/leglab/core", "include/leglab/model", "lib/cmake/leglab"):
            (prefix / folder).mkdir(parents=True)
        for program in ("identify", "track"):
            (prefix / "bin" / program).write_text("")
        status, lines = check(root, "--installed", str(prefix))
        assert status == 0 and not lines, lines

        (prefix / "bin" / "plan").write_text("")
        (prefix / "include" / "leglab" / "sim").mkdir()
        (prefix / "lib" / "cmake" / "leglab").rmdir()
        status, lines = check(root, "--installed", str(prefix))
        assert status == 1 and lines == [
            "docs/design/install.md:9: the build installs include/leglab/sim/, which it does "
            "not name",
            "docs/design/install.md:12: names 'lib/cmake/leglab/', which the build does not "
            "install",
            "docs/design/install.md:11: the build installs the program 'plan', which this list "
            "lacks",
            "README.md:3: the build installs the program 'plan', which this list lacks",
            "docs/results-page.md:1: the build installs the program 'plan', which this list "
            "lacks"], lines

        (prefix / "bin" / "plan").unlink()
        (prefix / "include" / "leglab" / "sim").rmdir()
        (prefix / "lib" / "cmake" / "leglab").mkdir()
        (prefix / "bin" / "track").unlink()
        status, lines = check(root, "--installed", str(prefix))
        assert status == 1 and lines == [
            "docs/design/install.md:11: names 'bin/track', which the build does not install",
            "docs/design/install.md:11: lists the program 'track', which the build does not "
            "install",
            "README.md:3: lists the program 'track', which the build does not install",
            "docs/results-page.md:1: lists the program 'track', which the build does not "
            "install"], lines


if __name__ == "__main__":
    main()
