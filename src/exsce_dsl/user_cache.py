"""The user's cache folder: what is pure and expensive to make, kept between processes.

Like ``__pycache__``, an entry is only ever found under a digest of everything
it was made from, so it cannot go stale: a change to any of its inputs gives
another name, and the old entry is simply not found again.  Entries are
written whole or not at all (a reader never sees half a file), and a cache
that cannot be read or written only makes exsce slower.

``$EXSCE_CACHE`` names the folder; set empty, nothing is cached.  Otherwise it
is ``$XDG_CACHE_HOME/exsce``, else ``~/.cache/exsce``.
"""

from __future__ import annotations

import os
from pathlib import Path


def cache_folder() -> Path | None:
    """``$EXSCE_CACHE``, else ``$XDG_CACHE_HOME/exsce`` (``~/.cache/exsce``); empty: no cache."""
    configured = os.environ.get("EXSCE_CACHE")
    if configured is not None:
        return Path(configured) if configured else None
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "exsce"


def read_cached(path: Path) -> bytes | None:
    """The entry at ``path``, or None when there is none (or it cannot be read)."""
    try:
        return path.read_bytes()
    except OSError:
        return None


def write_cached(path: Path, data: bytes) -> None:
    """Write an entry whole (a reader never sees half a file); a folder that cannot be written
    is no error, only no cache."""
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
        partial = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        partial.write_bytes(data)
        partial.replace(path)
    except OSError:
        pass
