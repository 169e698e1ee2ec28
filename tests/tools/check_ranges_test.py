#!/usr/bin/python3
"""tools/check_ranges.py: the sources hold no hand-written range beyond its list, and the
check finds one added by hand, and a listed one that is gone.

Usage: check_ranges_test.py SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile

SOURCE = sys.argv[1]
SCRIPT = os.path.join(SOURCE, "tools", "check_ranges.py")


def check(*args):
    return subprocess.run(["/usr/bin/python3", SCRIPT, *args], capture_output=True, text=True,
                          check=False)


def main():
    failures = []
    result = check(SOURCE)
    if result.returncode != 0:
        failures.append(f"the sources have a range written by hand:\n{result.stderr}")
    with tempfile.TemporaryDirectory() as tree:
        os.makedirs(os.path.join(tree, "model", "src"))
        with open(os.path.join(tree, "model", "src", "spring.cc"), "w", encoding="utf-8") as f:
            f.write('// "stiffness must be positive" in a comment is not a check\n'
                    'if (k <= 0) throw std::invalid_argument("stiffness must be positive");\n'
                    'if (n > 9) Fail("count must be in [1, 9], got " + Text(n));\n'
                    'Fail("inertia must be positive definite");\n')
        listed = os.path.join(tree, "listed.txt")
        with open(listed, "w", encoding="utf-8") as f:
            f.write("# known\nmodel/src/spring.cc: stiffness must be positive\n")
        result = check(tree, "--list", listed)
        if result.returncode != 1 or 'model/src/spring.cc: a range written by hand: "count must ' \
                'be in [1, 9], got"' not in result.stderr or result.stderr.count("\n") != 1:
            failures.append(f"a new hand-written range is not the one finding:\n{result.stderr}")
        with open(listed, "a", encoding="utf-8") as f:
            f.write("model/src/spring.cc: count must be in [1, 9], got\n"
                    "model/src/gone.cc: gain must be >= 0\n")
        result = check(tree, "--list", listed)
        if result.returncode != 1 or "gone.cc: gain must be >= 0\" is no longer" not in result.stderr:
            failures.append(f"a stale entry is not named:\n{result.stderr}")
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
