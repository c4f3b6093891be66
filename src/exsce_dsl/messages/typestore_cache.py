"""rosbags' standard typestores' definitions, kept in a small file between runs.

Importing a rosbags typestore module builds a dataclass for each of its types, and ROS 2 Jazzy's
store builds on Iron's, Humble's and every one before: a quarter of a second that every command
reading messages paid before doing anything.  Only the definitions are needed (``fielddefs``:
40 kB of JSON for Jazzy), so they are written once per rosbags version under the user's cache
folder and read back from there.  Anything wrong with the cache (missing, unreadable, another
shape) falls back to rosbags itself; a cache that cannot be written is simply not kept.
"""

from __future__ import annotations

import json
import os
import tempfile
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

FORMAT = 1
"""Bumped when the file's layout changes, so older files are not read."""


def cache_folder() -> Path:
    """``$EXSCE_CACHE_DIR``, else ``$XDG_CACHE_HOME/exsce``, else ``~/.cache/exsce``."""
    if os.environ.get("EXSCE_CACHE_DIR"):
        return Path(os.environ["EXSCE_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "exsce"


def standard_fielddefs(store: str) -> dict[str, Any]:
    """The ``fielddefs`` of rosbags' typestore ``store`` (``ros2_jazzy``, ``ros1_noetic``, ...),
    equal to ``get_typestore(Stores(store)).fielddefs``."""
    try:
        rosbags = version("rosbags")
    except PackageNotFoundError:  # pragma: no cover - rosbags is a dependency
        rosbags = "unknown"
    path = cache_folder() / f"typestore-{store}-rosbags-{rosbags}-v{FORMAT}.json"
    try:
        return _restored(json.loads(path.read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError, KeyError, IndexError):
        pass
    from rosbags.typesys import Stores, get_typestore

    fielddefs: dict[str, Any] = get_typestore(Stores(store)).fielddefs
    _write(path, json.dumps(fielddefs))
    return fielddefs


def _write(path: Path, text: str) -> None:
    """Write atomically (a reader never sees half a file), or not at all."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", encoding="utf-8", dir=path.parent, delete=False) as f:
            f.write(text)
        os.replace(f.name, path)
    except OSError:
        pass


def _restored(data: Any) -> dict[str, Any]:
    """The JSON's lists back into rosbags' shapes: (constants, fields) per type, constants
    ``(name, type, value)``, fields ``(name, description)``, descriptions tuples of Nodetype."""
    if not isinstance(data, dict):
        raise ValueError("not a mapping of types")
    return {
        str(name): (
            [(str(c), str(t), v) for c, t, v in constants],
            [(str(field), _description(desc)) for field, desc in fields],
        )
        for name, (constants, fields) in data.items()
    }


def _description(desc: list[Any]) -> tuple[Any, Any]:
    from rosbags.interfaces import Nodetype

    kind = Nodetype(desc[0])
    detail = desc[1]
    if kind == Nodetype.NAME:
        return kind, str(detail)
    if kind == Nodetype.BASE:
        return kind, (str(detail[0]), int(detail[1]))
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return kind, (_description(detail[0]), int(detail[1]))
    raise ValueError(f"unknown node type {desc[0]!r}")
