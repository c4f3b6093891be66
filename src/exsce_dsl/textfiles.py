"""Reading the files users give: regular files, at most :func:`max_file_bytes` long, as UTF-8 text
or bytes, or a clear error saying why not.

Every file a specification names (its imports, a map's YAML and image) is read here, so that
none of them can make a command, the language server or the MCP server read forever: the file
is opened without blocking (a FIFO would wait for a writer), the opened descriptor, not the
path, is checked to be a regular file (``/dev/zero`` is a device), and no more than the limit
plus one byte is read.

The language server and the MCP server read only inside their folder: within
:func:`reading_inside`, a file outside the folders given is refused with the
same words whether it exists or not.
"""

from __future__ import annotations

import contextlib
import os
import stat
from collections.abc import Iterator
from contextvars import ContextVar
from pathlib import Path

from exsce_dsl.errors import ExsceError, SourceLocation

MAX_FILE_MB = 64
"""The largest file read, in MiB, unless ``$EXSCE_MAX_FILE_MB`` says otherwise."""
MAX_FILE_VARIABLE = "EXSCE_MAX_FILE_MB"
UTF8_BOM = b"\xef\xbb\xbf"

_CHUNK = 1024 * 1024
_READABLE: ContextVar[tuple[str, ...] | None] = ContextVar("exsce_readable_folders", default=None)
"""The folders files may be read from (None: anywhere), set by :func:`reading_inside`."""


@contextlib.contextmanager
def reading_inside(*folders: str | Path) -> Iterator[None]:
    """Within the block (in this thread), :func:`read_bytes` and :func:`read_text` read only
    files inside ``folders`` (symbolic links followed before looking)."""
    token = _READABLE.set(tuple(os.path.realpath(f) for f in folders))
    try:
        yield
    finally:
        _READABLE.reset(token)


def is_inside(path: str | Path, folders: tuple[str, ...]) -> bool:
    """Whether ``path``, symbolic links followed, lies inside one of ``folders`` (real paths)."""
    try:
        real = os.path.realpath(path)
    except (OSError, ValueError):
        return False
    return any(real == f or real.startswith(f.rstrip(os.sep) + os.sep) for f in folders)


def max_file_bytes() -> int:
    """The largest file read, in bytes: ``$EXSCE_MAX_FILE_MB`` MiB (a positive number), else
    :data:`MAX_FILE_MB`."""
    given = os.environ.get(MAX_FILE_VARIABLE, "").strip()
    try:
        megabytes = float(given) if given else MAX_FILE_MB
    except ValueError:
        megabytes = MAX_FILE_MB
    if not 0 < megabytes < 1024 * 1024:  # not NaN, not infinite: a size
        megabytes = MAX_FILE_MB
    return int(megabytes * 1024 * 1024)


def read_bytes(path: str | Path, what: str = "file", limit: int | None = None) -> bytes:
    """The bytes of ``path``; an :class:`ExsceError` if it is missing, a folder, not a regular
    file (a FIFO, a device), unreadable, or longer than ``limit`` (:func:`max_file_bytes`)."""
    most = max_file_bytes() if limit is None else limit
    readable = _READABLE.get()
    if readable is not None and not is_inside(path, readable):
        shown = " or ".join(readable) or "no folder"
        raise ExsceError(f"{path} is outside the workspace ({shown}): only files inside it are read")
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        descriptor = os.open(path, flags)
    except OSError as exc:
        raise ExsceError(f"cannot read {path}: {exc.strerror or exc}") from None
    except ValueError:  # a NUL byte in the name
        raise ExsceError(f"cannot read {path!r}: no file has that name") from None
    try:
        mode = os.fstat(descriptor).st_mode
        if stat.S_ISDIR(mode):
            raise ExsceError(f"{path} is a folder, not a {what}")
        if not stat.S_ISREG(mode):
            raise ExsceError(f"{path} is not a regular file (a {what} is read from a file)")
        chunks: list[bytes] = []
        size = 0
        while size <= most:
            chunk = os.read(descriptor, min(_CHUNK, most + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as exc:
        raise ExsceError(f"cannot read {path}: {exc.strerror or exc}") from None
    finally:
        os.close(descriptor)
    if size > most:
        raise ExsceError(
            f"{path} is larger than {_megabytes(most)}, the most a {what} may be "
            f"(${MAX_FILE_VARIABLE} sets the limit, in MiB)"
        )
    return b"".join(chunks)


def read_text(path: str | Path, what: str = "file", limit: int | None = None) -> str:
    """The UTF-8 text of ``path`` (a byte order mark at its start left out), read as
    :func:`read_bytes` reads; an :class:`ExsceError` as it says, or if the file is not UTF-8 (with
    the line of the first bad byte)."""
    data = read_bytes(path, what, limit)
    if data.startswith(UTF8_BOM):
        data = data[len(UTF8_BOM) :]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ExsceError(
            f"the {what} is not UTF-8 text (byte 0x{data[exc.start]:02x})",
            SourceLocation(str(path), line, column, line, column + 1),
        ) from None


def without_bom(text: str) -> str:
    """``text`` without the byte order mark some editors write at the start of a file."""
    return text[1:] if text.startswith("\ufeff") else text


def _megabytes(size: int) -> str:
    megabytes = size / (1024 * 1024)
    return f"{megabytes:g} MiB" if megabytes >= 1 else f"{size} bytes"
