"""The files the programs write, read one way for every reader (report, plot_figures, plot_logs,
plot_sweep, animate, compare_engines here; scripts/docs_numbers.py; tools/check_outputs.py): CSV
tables checked against their declaration and read as rows keyed by column name, JSON as parsed, a
Markdown table row as its cells. UTF-8 whatever the locale. Errors are the caller's to turn into
its one-line exit 2: OSError, UnicodeDecodeError and ValueError (a JSON syntax error, a CSV
whose columns are not its declared ones) as Python raises them, csv.Error for a malformed CSV.

A CSV's columns are declared once, beside the code that writes them; docs/outputs.md is
generated from those declarations (and checked against them by a test), and is what this module
reads them from. A row gives a column's cell as an attribute, row.carriage_z_mm, so that a
script names a column only by using it, and a name the declaration lacks fails there, naming
the table's columns.

The checks a script's bad input needs beyond the declarations are here too: every number of a
JSON file finite, every cell of a numeric CSV table a finite number, and a command line's usage
error one line (ArgumentParser).
"""
from __future__ import annotations

import argparse
import csv
import functools
import json
import math
import os
import pathlib
import re
import sys
from typing import Any, Mapping, NoReturn, Sequence, Union

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["OUTPUTS_MD", "ArgumentParser", "Row", "check_row_lengths", "column_problems",
           "declared_columns", "declared_pattern", "declared_tables", "field_problems",
           "finite_number", "json_fields", "non_finite_field", "one_line", "read_columns",
           "read_csv", "read_finite_columns", "read_json", "read_rows", "select", "shape",
           "split_row", "write_all_or_nothing"]


def _outputs_md() -> pathlib.Path:
    """docs/outputs.md: the source tree's (the package linked into a build, or python/ itself),
    else the copy installed with leglab's data (<prefix>/share/leglab/docs/outputs.md)."""
    source = pathlib.Path(__file__).resolve().parents[3] / "docs" / "outputs.md"
    if source.is_file() or "LEGLAB_DATA_DIR" not in os.environ:
        return source
    return pathlib.Path(os.environ["LEGLAB_DATA_DIR"]) / "docs" / "outputs.md"


OUTPUTS_MD = _outputs_md()
_HEADING = re.compile(r"^### `([^`]+)`$")
_COLUMN = re.compile(r"^\| `([^`]+)` \|")


def shape(name: str) -> re.Pattern:
    """A regular expression for a declared name.

    Parameters
    ----------
    name : str
        A declared file, column or field name; `<...>` stands for any text without a comma or
        slash.

    Returns
    -------
    re.Pattern
        The pattern, anchored at the end (use ``match``).
    """
    return re.compile("".join("[^,/]+" if part.startswith("<") else re.escape(part)
                              for part in re.split(r"(<[^>]+>)", name) if part) + r"\Z")


@functools.lru_cache(maxsize=None)
def declared_tables(docs: PathLike = OUTPUTS_MD) -> dict[str, list[str]]:
    """Every declared file with columns or fields in the outputs reference.

    Parameters
    ----------
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default. Read once per path (cached).

    Returns
    -------
    dict of str to list of str
        {file pattern: [column names or dotted field paths]}.

    Raises
    ------
    OSError, UnicodeDecodeError
        When `docs` cannot be read.
    """
    tables: dict[str, list[str]] = {}
    current: str | None = None
    for line in pathlib.Path(docs).read_text(encoding="utf-8").splitlines():
        heading = _HEADING.match(line)
        if heading:
            current = heading.group(1)
            continue
        column = _COLUMN.match(line)
        if column and current is not None:
            tables.setdefault(current, []).append(column.group(1))
    return tables


def declared_pattern(file_name: str, tables: Mapping[str, list[str]]) -> str | None:
    """The declared file pattern a file's name fits.

    Parameters
    ----------
    file_name : str
        A file's base name (``trace_direct.csv``).
    tables : mapping
        declared_tables()'s result.

    Returns
    -------
    str or None
        The most specific fitting pattern (the most literal text), or None when none fits.
    """
    fitting = [p for p in tables if shape(p).match(file_name)]
    if not fitting:
        return None
    return max(fitting, key=lambda p: len(re.sub(r"<[^>]+>", "", p)))


def column_problems(name: str, header: Sequence[str], columns: Sequence[str]) -> list[str]:
    """What is wrong with a CSV header for a file declared with `columns`.

    Every declared column without a `<...>` must be there in the declared order, and nothing
    that matches no declared column (a `<...>` column matches any name of its shape, in any
    place).

    Parameters
    ----------
    name : str
        The file, as the messages name it.
    header : sequence of str
        The file's column names.
    columns : sequence of str
        The declared columns, `<...>` patterns included.

    Returns
    -------
    list of str
        One message per problem, each starting with `name`; empty when the header is right.
    """
    problems = []
    literals = [c for c in columns if "<" not in c]
    found = [c for c in header if c in literals]
    if found != literals:
        missing = [c for c in literals if c not in header]
        problems.append(f"{name}: declared columns missing or out of order: "
                        f"{', '.join(missing) or 'order ' + ', '.join(found)}")
    shapes = [shape(c) for c in columns]
    for c in header:
        if c not in literals and not any(s.match(c) for s in shapes):
            problems.append(f"{name}: column '{c}' is not declared")
    return problems


def json_fields(value: Any, path: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """The leaf fields of a parsed JSON value, each as its path of keys.

    The elements of a list of objects share one path, the list's key with `[]` appended
    ("logs[]"); a list of numbers or text is a leaf, an empty list none (it holds no field:
    identify's folds without cross-validation).

    Parameters
    ----------
    value : object
        A value as json.load gives it.
    path : tuple of str
        The keys leading to `value` (empty at the top).

    Returns
    -------
    list of tuple of str
        Each leaf's path, in the order met, repeated once per list element.
    """
    if isinstance(value, list) and not value:
        return []
    if isinstance(value, dict):
        return [field for key, v in value.items() for field in json_fields(v, path + (key,))]
    if isinstance(value, list) and any(isinstance(v, dict) for v in value):
        listed = path[:-1] + (path[-1] + "[]",)
        return [field for v in value for field in json_fields(v, listed)]
    return [path]


def field_problems(name: str, value: Any, fields: Sequence[str]) -> list[str]:
    """What is wrong with a JSON file's parsed value for a file declared with `fields`.

    Parameters
    ----------
    name : str
        The file, as the messages name it.
    value : object
        The file's content as json.load gives it.
    fields : sequence of str
        The declared fields, dotted paths (`<...>` any one key, `[]` a list's elements).

    Returns
    -------
    list of str
        One message per leaf field no declared field matches (once each), or one message when
        `value` is not an object; empty when every field is declared.
    """
    declared = [tuple(f.split(".")) for f in fields]

    def matches(pattern: tuple[str, ...], path: tuple[str, ...]) -> bool:
        return len(pattern) == len(path) and all(
            p == k or (p.startswith("<") and not k.endswith("[]")) for p, k in zip(pattern, path))
    if not isinstance(value, dict):
        return [f"{name}: expected a JSON object, got {type(value).__name__}"]
    problems = []
    for path in dict.fromkeys(json_fields(value)):
        if any(matches(pattern, path) for pattern in declared):
            continue
        inner = [p for p in declared if len(p) > len(path) and matches(p[:len(path)], path)]
        if inner:
            problems.append(f"{name}: field '{'.'.join(path)}' is not an object (declared: "
                            f"{'.'.join(inner[0])})")
        else:
            problems.append(f"{name}: field '{'.'.join(path)}' is not declared")
    return problems


class Row(dict):
    """One row of a CSV table (column name -> cell text) or one object of a JSON file (field ->
    value).

    A name that is an identifier is also an attribute (row.tick,
    table1.joints.rotator.theta0_deg); others (a swept key's column "servo.delay_ms", a Table 2
    row "L2(Des,Dir)") are items. An attribute the row lacks raises AttributeError naming the
    names it has.
    """

    __slots__ = ()

    def __getattr__(self, name: str) -> Any:
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no '{name}' here (there are {', '.join(self)})") from None


def _with_attributes(value: Any) -> Any:
    """A parsed JSON value with each object a Row, nested."""
    if isinstance(value, dict):
        return Row({k: _with_attributes(v) for k, v in value.items()})
    if isinstance(value, list):
        return [_with_attributes(v) for v in value]
    return value


def read_csv(path: PathLike, docs: PathLike = OUTPUTS_MD) -> tuple[list[str], list[Row]]:
    """A CSV table a program wrote, its header checked against its declaration first.

    Parameters
    ----------
    path : str or os.PathLike
        The table; its base name selects its declaration.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    header : list of str
        The column names.
    rows : list of Row
        Each row, column name -> cell text (a short row's missing cells None, a long row's
        extra cells under None, as csv.DictReader gives them).

    Raises
    ------
    ValueError
        Naming the file and the column, when the file is not declared or its columns are not the
        declared ones.
    OSError, UnicodeDecodeError, csv.Error
        When the file cannot be read as UTF-8 CSV.
    """
    columns = declared_columns(path, docs)
    with open(path, encoding="utf-8", newline="") as f:
        reader = csv.DictReader(f)
        rows = [Row(row) for row in reader]
        header = list(reader.fieldnames or [])
    problems = column_problems(str(path), header, columns)
    if problems:
        raise ValueError(problems[0])
    return header, rows


def _declaration(path: PathLike, docs: PathLike) -> list[str] | None:
    """The columns or fields declared for the file at `path` (by its name), `<...>` patterns
    included, or None when no declared file has its name."""
    tables = declared_tables(pathlib.Path(docs))
    pattern = declared_pattern(pathlib.Path(path).name, tables)
    return None if pattern is None else tables[pattern]


def declared_columns(path: PathLike, docs: PathLike = OUTPUTS_MD) -> list[str]:
    """The columns declared for a file, by its name.

    Parameters
    ----------
    path : str or os.PathLike
        The file (it need not exist); its base name selects the declaration.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    list of str
        The declared columns, `<...>` patterns included.

    Raises
    ------
    ValueError
        When no declared file has its name.
    """
    columns = _declaration(path, docs)
    if columns is None:
        raise ValueError(f"{path}: no declared output has this name ({pathlib.Path(docs).name})")
    return columns


def read_columns(path: PathLike, docs: PathLike = OUTPUTS_MD) -> Row:
    """A CSV table of numbers as columns, its header checked as read_csv checks it.

    Parameters
    ----------
    path : str or os.PathLike
        The table.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    Row
        Column name -> its cells as floats; empty when the table has no row.

    Raises
    ------
    ValueError
        As read_csv, and when a cell is not a number.
    """
    header, rows = read_csv(path, docs)
    return Row({name: [float(r[name]) for r in rows] for name in header} if rows else {})


def _cell(text: Any) -> Any:
    try:
        return float(text)
    except (TypeError, ValueError):
        return text


def select(rows: Sequence[Row], **where: Any) -> Row:
    """The rows whose cells equal `where`'s values, as columns.

    Parameters
    ----------
    rows : sequence of Row
        read_rows()'s rows.
    **where
        Column name -> value, compared as text (step=0 matches "0").

    Returns
    -------
    Row
        Column name -> the chosen rows' cells in order, numbers as floats, other text as it
        is: select(rows, step=0, joint="rotator").actual_deg.
    """
    chosen = [r for r in rows if all(r[k] == str(v) for k, v in where.items())]
    names = list(rows[0]) if rows else []
    return Row({name: [_cell(r[name]) for r in chosen] for name in names})


def read_rows(path: PathLike, docs: PathLike = OUTPUTS_MD) -> list[Row]:
    """read_csv's rows alone.

    Parameters
    ----------
    path : str or os.PathLike
        The table.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    list of Row
        As read_csv.

    Raises
    ------
    ValueError, OSError, UnicodeDecodeError, csv.Error
        As read_csv.
    """
    return read_csv(path, docs)[1]


def read_json(path: PathLike, docs: PathLike = OUTPUTS_MD) -> Any:
    """A JSON file, parsed, each object a Row (its fields also attributes).

    One a program declares field by field (table1.json, log_fit.json, ...) is checked against
    its declaration first; others (a script's own, learned_fit.json) are read as they are.

    Parameters
    ----------
    path : str or os.PathLike
        The file; its base name selects its declaration.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    object
        The parsed value, every object a Row.

    Raises
    ------
    ValueError
        A JSON syntax error, or naming the file and the first field its declaration lacks.
    OSError, UnicodeDecodeError
        When the file cannot be read as UTF-8.
    """
    with open(path, encoding="utf-8") as f:
        value = json.load(f)
    fields = _declaration(path, docs)
    if fields is not None:
        problems = field_problems(pathlib.Path(path).name, value, fields)
        if problems:
            raise ValueError(problems[0])
    return _with_attributes(value)


def split_row(line: str) -> list[str]:
    """The cells of a Markdown table row.

    Parameters
    ----------
    line : str
        A row, '| a | b |'.

    Returns
    -------
    list of str
        Its cells, stripped, with '\\|' kept as a literal bar.
    """
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    cells = re.split(r"(?<!\\)\|", line)
    return [c.strip().replace("\\|", "|") for c in cells]


def one_line(text: object) -> str:
    """A message kept on one line.

    Parameters
    ----------
    text : object
        Anything; str() of it is taken.

    Returns
    -------
    str
        The text with control and undecodable characters escaped.
    """
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class ArgumentParser(argparse.ArgumentParser):
    """argparse, with a usage error reported as every other bad input: `<prog>: error:
    <message>`, one line on stderr, exit status 2 (not argparse's usage block)."""

    def error(self, message: str) -> NoReturn:
        """Reports a usage error on one line and exits.

        Parameters
        ----------
        message : str
            argparse's message.

        Raises
        ------
        SystemExit
            Always, status 2, after `<prog>: error: <message>` on stderr.
        """
        print(f"{self.prog}: error: {one_line(message)}", file=sys.stderr)
        sys.exit(2)


def non_finite_field(value: Any) -> str | None:
    """The first number of a parsed JSON value that is not finite.

    Walked without recursion: any depth json parsed is fine.

    Parameters
    ----------
    value : object
        A value as json.load gives it.

    Returns
    -------
    str or None
        The dotted path (a list's element as [i]; "the value" for the top) of the first number
        that is NaN, infinite or an integer beyond a double's range; None when every number is
        finite.
    """
    pending = [("", value)]
    while pending:
        path, item = pending.pop()
        if (isinstance(item, float) and not math.isfinite(item) or isinstance(item, int)
                and not isinstance(item, bool) and abs(item) > sys.float_info.max):
            return path or "the value"
        if isinstance(item, dict):
            pending += [(f"{path}.{k}" if path else str(k), v) for k, v in reversed(item.items())]
        elif isinstance(item, list):
            pending += [(f"{path}[{i}]", v) for i, v in reversed(list(enumerate(item)))]
    return None


def finite_number(text: str | None, where: str) -> float:
    """A CSV cell's text as a finite float.

    Parameters
    ----------
    text : str or None
        The cell (None for a short row's missing cell).
    where : str
        The file, row and column, as the message names them.

    Returns
    -------
    float
        The number.

    Raises
    ------
    ValueError
        Naming `where`, when the cell is empty, not a number, NaN or infinite.
    """
    shown = repr(text if text is None or len(text) <= 40 else text[:40] + "...")
    if text is None:  # float(None) is a TypeError: the empty cell's message
        raise ValueError(f"{where}: empty, expected a number")
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {shown} is not a number" if text else
                         f"{where}: empty, expected a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: {shown} is not a finite number")
    return value


def check_row_lengths(path: PathLike, header: Sequence[str], rows: Sequence[Row]) -> None:
    """Checks that every row of a CSV table has as many cells as its header has columns.

    Parameters
    ----------
    path : str or os.PathLike
        The table, as the message names it.
    header : sequence of str
        Its column names.
    rows : sequence of Row
        read_csv()'s rows.

    Raises
    ------
    ValueError
        Naming the file and the row (1: the first below the header) of the first row with
        fewer or more cells.
    """
    for number, row in enumerate(rows, 1):
        if None in row or None in row.values():  # csv.DictReader's marks of a long, short row
            cells = sum(row.get(name) is not None for name in header) + len(row.get(None) or ())
            raise ValueError(f"{path}: row {number}: {cells} cells, the header has "
                             f"{len(header)} columns")


def read_finite_columns(path: PathLike, docs: PathLike = OUTPUTS_MD) -> Row:
    """read_columns for a table of numbers, every cell checked.

    Parameters
    ----------
    path : str or os.PathLike
        The table.
    docs : str or os.PathLike
        The outputs reference, docs/outputs.md by default.

    Returns
    -------
    Row
        Column name -> its cells as floats; empty when the table has no row.

    Raises
    ------
    ValueError
        As read_csv, and naming the file, the row (1: the first below the header) and the
        column of a missing, extra, empty, non-numeric, NaN or infinite cell.
    """
    header, rows = read_csv(path, docs)
    check_row_lengths(path, header, rows)
    columns = Row({name: [] for name in header} if rows else {})
    for number, row in enumerate(rows, 1):
        for name in header:
            columns[name].append(finite_number(row[name], f"{path}: row {number}, column {name}"))
    return columns


def write_all_or_nothing(texts: Mapping[PathLike, str]) -> None:
    """Writes several files, all or none.

    Each is written beside its place first (a hidden name with this process's id) and renamed
    into place once all are written, making the folders it needs.

    Parameters
    ----------
    texts : mapping
        Path -> its text (written as UTF-8).

    Raises
    ------
    OSError
        When one cannot be written: none is then written, and no partial file is left behind.
    """
    staged = {pathlib.Path(path): pathlib.Path(path).with_name(
        f".{pathlib.Path(path).name}.{os.getpid()}") for path in texts}
    try:
        for path, partial in staged.items():
            path.parent.mkdir(parents=True, exist_ok=True)
            partial.write_text(texts[path], encoding="utf-8")
        for path, partial in staged.items():
            os.replace(partial, path)
    finally:
        for partial in staged.values():
            if partial.is_file():
                partial.unlink()
