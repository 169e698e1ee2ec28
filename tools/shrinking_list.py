"""The list of known findings a check keeps while they are being removed, a list that may only
shrink (tools/hand_ranges.txt for check_ranges.py, tools/output_names.txt for
check_output_names.py): a header of '#' lines, then one "first: second" entry a line.

Imported from the scripts' folder (Python puts a script's own folder first on its path).
"""


def read_entries(path):
    """[(first, second)] of the list at `path`, in order."""
    entries = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line and not line.startswith("#"):
                first, _, second = line.partition(": ")
                entries.append((first, second))
    return entries


def write_entries(path, header, entries):
    """Writes `header` (its '#' lines) and `entries` to `path`."""
    with open(path, "w", encoding="utf-8") as f:
        f.write(header + "".join(f"{first}: {second}\n" for first, second in entries))


def compare(found, listed):
    """(new, stale): what `found` holds beyond `listed`, and what `listed` holds that is no longer
    found, each entry counted as often as it occurs."""
    new = list(found)
    stale = []
    for entry in listed:
        if entry in new:
            new.remove(entry)
        else:
            stale.append(entry)
    return new, stale
