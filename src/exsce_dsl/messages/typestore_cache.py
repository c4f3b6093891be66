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
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from exsce_dsl.user_cache import cache_folder, read_cached, write_cached

FORMAT = 1
"""Bumped when the file's layout changes, so older files are not read."""


def standard_fielddefs(store: str) -> dict[str, Any]:
    """The ``fielddefs`` of rosbags' typestore ``store`` (``ros2_jazzy``, ``ros1_noetic``, ...),
    equal to ``get_typestore(Stores(store)).fielddefs``; kept in the user's cache folder
    (:func:`exsce_dsl.user_cache.cache_folder`) unless ``$EXSCE_CACHE`` is set empty."""
    try:
        rosbags = version("rosbags")
    except PackageNotFoundError:  # pragma: no cover - rosbags is a dependency
        rosbags = "unknown"
    folder = cache_folder()
    path = None if folder is None else folder / f"typestore-{store}-rosbags-{rosbags}-v{FORMAT}.json"
    data = None if path is None else read_cached(path)
    if data is not None:
        try:
            return _restored(json.loads(data))
        except (ValueError, TypeError, KeyError, IndexError):
            pass
    from rosbags.typesys import Stores, get_typestore

    fielddefs: dict[str, Any] = get_typestore(Stores(store)).fielddefs
    if path is not None:
        write_cached(path, json.dumps(fielddefs).encode())
    return fielddefs


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
