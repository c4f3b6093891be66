"""Reading the text files users give: regular files of UTF-8 text, or a clear error saying why not."""

from __future__ import annotations

import stat
from pathlib import Path

from exsce_dsl.errors import ExsceError, SourceLocation


def read_text(path: str | Path, what: str = "file") -> str:
    """The UTF-8 text of ``path``; an :class:`ExsceError` if it is missing, a folder, not a regular
    file (a FIFO would block forever), unreadable, or not UTF-8 (with the line of the first bad byte)."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except OSError as exc:
        raise ExsceError(f"cannot read {path}: {exc.strerror or exc}") from None
    if stat.S_ISDIR(mode):
        raise ExsceError(f"{path} is a folder, not a {what}")
    if not stat.S_ISREG(mode):
        raise ExsceError(f"{path} is not a regular file (a {what} is read from a file)")
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ExsceError(f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ExsceError(
            f"the {what} is not UTF-8 text (byte 0x{data[exc.start]:02x})",
            SourceLocation(str(path), line, column, line, column + 1),
        ) from None
