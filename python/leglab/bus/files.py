"""The files a bus session writes, each all at once, into a folder the user names."""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Iterable
from typing import Any, Union

from .session import SessionError


def out_folder(path: Union[str, os.PathLike[str]]) -> str:
    """`path` as an output folder, checked before a session starts: a folder (not a link to
    one) that a file can be made in, or a new name in one (made when the first file is
    written, so that a session refused before it records leaves nothing behind). The check
    makes and removes a file there: permission bits do not bind root, and /proc or /sys take
    no file. SessionError otherwise."""
    path = os.fspath(path)
    if not path:
        raise SessionError("--out: an empty path")
    name = path.rstrip("/") or "/"
    if os.path.islink(name):
        raise SessionError(f"--out '{path}': is a symbolic link; give the folder itself")
    if os.path.lexists(name) and not os.path.isdir(name):
        raise SessionError(f"--out '{path}': exists and is not a folder")
    if not os.path.isdir(os.path.dirname(os.path.abspath(name))):
        raise SessionError(f"--out '{path}': its parent folder does not exist")
    made = not os.path.isdir(name)
    try:
        if made:
            os.mkdir(name)
        fd, probe = tempfile.mkstemp(prefix=".leglab-probe.", dir=name)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise SessionError(f"--out '{path}': cannot be written: {e.strerror}") from None
    finally:
        if made and os.path.isdir(name):
            os.rmdir(name)
    return name


def check_inputs_apart(outputs: Iterable[str], inputs: Iterable[str]) -> None:
    """SessionError when an output path is one of the session's input files."""
    real = {os.path.realpath(p): p for p in inputs if p}
    for path in outputs:
        if os.path.realpath(path) in real:
            raise SessionError(f"'{path}': is the input file '{real[os.path.realpath(path)]}'; "
                               "write the outputs elsewhere")


def check_input_file(path: str, what: str) -> None:
    """SessionError unless `path` is a regular file (a pipe would block the session)."""
    if not os.path.isfile(path):
        reason = "no such file" if not os.path.lexists(path) else "is not a regular file"
        raise SessionError(f"{what} '{path}': {reason}")


def check_writable(path: str) -> None:
    """SessionError when `path` holds something a session must not replace: anything but a
    regular file (a link, a device, a pipe, a folder)."""
    if os.path.lexists(path) and (os.path.islink(path) or not os.path.isfile(path)):
        raise SessionError(f"'{path}': exists and is not a regular file; leglab replaces only "
                           "its own files")


def check_writable_all(folder: str, paths: Iterable[str]) -> None:
    """check_writable on every path a session will write into `folder`, before it starts:
    what it records is never lost at the end to a name it may not replace."""
    for path in paths:
        check_writable(path)


def write_text(path: str, text: str) -> None:
    """Writes `text` to `path` all at once, with the permissions the umask gives a new file: a
    failure leaves no file, or the old one as it was (SessionError naming it)."""
    check_writable(path)
    folder = os.path.dirname(os.path.abspath(path))
    staging = None
    try:
        os.makedirs(folder, exist_ok=True)
        fd, staging = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=folder)
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as out:
            out.write(text)
        os.replace(staging, path)
    except OSError as e:
        if staging and os.path.exists(staging):
            os.unlink(staging)
        raise SessionError(f"'{path}': cannot be written: {e.strerror}") from None
    except BaseException:
        if staging and os.path.exists(staging):
            os.unlink(staging)
        raise


def write_json(path: str, value: Any) -> None:
    """`value` as indented JSON (no NaN or infinity: those are written as null)."""
    write_text(path, json.dumps(_finite(value), indent=1) + "\n")


def _finite(value: Any) -> Any:
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def number(value: float) -> str:
    """The shortest text that reads back as the same double."""
    return repr(float(value))
