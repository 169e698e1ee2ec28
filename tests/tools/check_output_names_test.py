#!/usr/bin/python3
"""tools/check_output_names.py: no output name is spelled in more non-declaring sources than
its list holds, and the check finds a name a second reader spells (a CSV column's, and a JSON
field's whose writer and reader both spell it), leaves alone one reader, the four forms of a
declaration and a plain word, and names a stale entry.

Usage: check_output_names_test.py SOURCE_DIR
"""
import os
import subprocess
import sys
import tempfile

SOURCE = sys.argv[1]
SCRIPT = os.path.join(SOURCE, "tools", "check_output_names.py")

FILES = {
    "docs/outputs.md": "| column | unit | description |\n|---|---|---|\n"
                       "| `foot_mm` | mm | declared |\n| `tick` |  | a word |\n\n"
                       "| field | unit | description |\n|---|---|---|\n"
                       "| `stand.<mode>.slip_mm` | mm | a JSON field |\n",
    "core/include/leglab/core/plant.h": 'inline constexpr TelemetryColumn kX{{"force_n", "N", '
                                        '"the force"}, nullptr};\n',
    "experiments/include/writers.h": 'inline constexpr ColumnDoc kFoot{"foot_mm", "mm", "x"};\n'
                                     'inline constexpr FieldDoc kS{"stand.<mode>.slip_mm", "mm", '
                                     '"x"};\n',
    "experiments/src/writers.cc": 'entry["slip_mm"] = slip;  // the JSON field\'s writer\n',
    "experiments/src/config.cc": 'v.Key("foot_mm", c.foot, kDoc);  // a key of that name\n',
    "model/include/names.h": 'struct Names { std::string_view foot = "foot_mm"; };  // declared\n',
    "scripts/first.py": 'x = [float(r["foot_mm"]) for r in rows]\nt = r["tick"]\n'
                        's = stand["slip_mm"]\n',
    "scripts/second.py": "y = row['foot_mm']\nt = row['tick']\n",
    "scripts/tests/third.py": 'z = row["foot_mm"]  # a test folder is not a source\n',
    "python/src/plant.cc": 'out["force_n"] = force;  // its one reader\n',
}


def check(*args):
    return subprocess.run(["/usr/bin/python3", SCRIPT, *args], capture_output=True, text=True,
                          check=False)


def main():
    failures = []
    result = check(SOURCE)
    if result.returncode != 0:
        failures.append(f"the sources spell an output name beyond the list:\n{result.stderr}")
    with tempfile.TemporaryDirectory() as tree:
        for rel, text in FILES.items():
            os.makedirs(os.path.dirname(os.path.join(tree, rel)), exist_ok=True)
            with open(os.path.join(tree, rel), "w", encoding="utf-8") as f:
                f.write(text)
        listed = os.path.join(tree, "listed.txt")
        with open(listed, "w", encoding="utf-8") as f:
            f.write("# known\n")
        result = check(tree, "--list", listed)
        lines = result.stderr.splitlines()
        want = ('scripts/first.py: spells the output name "foot_mm"',
                'scripts/second.py: spells the output name "foot_mm"',
                'experiments/src/writers.cc: spells the output name "slip_mm"',
                'scripts/first.py: spells the output name "slip_mm"')
        if (result.returncode != 1 or len(lines) != len(want) or
                not all(line.startswith(w) for line, w in zip(lines, want))):
            failures.append(f"two readers of foot_mm and slip_mm's writer and reader are not the "
                            f"four findings:\n{result.stderr}")
        with open(listed, "a", encoding="utf-8") as f:
            f.write("foot_mm: scripts/first.py\nfoot_mm: scripts/second.py\n"
                    "slip_mm: experiments/src/writers.cc\nslip_mm: scripts/first.py\n"
                    "gone_mm: scripts/old.py\n")
        result = check(tree, "--list", listed)
        if result.returncode != 1 or result.stderr.count("\n") != 1 or \
                '"gone_mm: scripts/old.py" is no longer found' not in result.stderr:
            failures.append(f"a stale entry is not the one finding:\n{result.stderr}")
        result = check(tree, "--list", listed.replace("listed", "none"), "--update")
        result = check(tree, "--list", listed.replace("listed", "none"))
        if result.returncode != 0 or "nothing new (4 spellings still listed)" not in result.stdout:
            failures.append(f"--update does not list what it finds:\n{result.stdout}"
                            f"{result.stderr}")
    for failure in failures:
        print("FAIL:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
