"""The files a bus session writes, each all at once, into a folder the user names."""

import json
import math
import os
import tempfile

from .session import SessionError


def out_folder(path):
    """`path` as an output folder, checked before a session starts: a folder that can be
    written, or a new name in one (made when the first file is written, so that a session
    refused before it records leaves nothing behind). SessionError otherwise."""
    path = os.fspath(path)
    if not path:
        raise SessionError("--out: an empty path")
    if os.path.lexists(path) and not os.path.isdir(path):
        raise SessionError(f"--out '{path}': exists and is not a folder")
    parent = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(parent):
        raise SessionError(f"--out '{path}': its parent folder does not exist")
    writable = path if os.path.isdir(path) else parent
    if not os.access(writable, os.W_OK | os.X_OK):
        raise SessionError(f"--out '{path}': cannot be written")
    return path


def check_writable(path):
    """SessionError when `path` holds something a session must not replace: anything but a
    regular file (a link, a device, a pipe, a folder)."""
    if os.path.lexists(path) and (os.path.islink(path) or not os.path.isfile(path)):
        raise SessionError(f"'{path}': exists and is not a regular file; leglab replaces only "
                           "its own files")


def check_writable_all(folder, paths):
    """check_writable on every path a session will write into `folder`, before it starts:
    what it records is never lost at the end to a name it may not replace."""
    for path in paths:
        check_writable(path)


def write_text(path, text):
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


def write_json(path, value):
    """`value` as indented JSON (no NaN or infinity: those are written as null)."""
    write_text(path, json.dumps(_finite(value), indent=1) + "\n")


def _finite(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value


def number(value):
    """The shortest text that reads back as the same double."""
    return repr(float(value))
