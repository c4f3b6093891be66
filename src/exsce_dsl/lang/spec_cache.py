"""Checked specifications and the parsed standard library, kept in the user's cache folder.

Parsing and checking a specification needs textX, whose metamodel of the
grammar takes longer to build than the rest of a short ingest; the result, a
:class:`~exsce_dsl.model.Specification` of plain frozen dataclasses, is pure
and pickles.  So :func:`load_spec_cached` keeps it in the user's cache folder
(:mod:`exsce_dsl.user_cache`) and reuses it only while everything it was made
from is unchanged:

- exsce's code and resources (every file of the package and its grammar,
  by size and modification time, and its version), Python's version, and the
  installed textX, Arpeggio, rosbags (whose typestores are the standard message
  types) and PyYAML (which reads maps) — :func:`code_fingerprint`;
- the working folder (diagnostics and locations name files relative to it)
  and the root file's path;
- the content (sha256) of every ``.exsce`` file read, the root and all it
  imports, and of every map the checks read (the map_server YAML and its image);
- ``$EXSCE_MSG_PATH``: its folders, the list of definition files below
  them, and the content of each.

The first three name the entry; the last two are recorded in it and
compared, file by file, each time it is found.  Only a specification that
loads without errors is kept (an error is always reported afresh); with an
overlay (an editor's unsaved text) nothing is cached.  ``$EXSCE_CACHE`` set
empty turns the cache off.

The entries are pickles, and unpickling runs code, so an entry is unpickled only
after :func:`~exsce_dsl.user_cache.read_cached` has checked it: a file of the
user's own, in a private folder, whose HMAC under the user's ``0600`` key matches
(issue 46).  Anyone who could forge that code could already read the user's key,
hence run code as the user.  A data format instead would mean a serialiser for
every class of the semantic model, kept in step with it.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from collections.abc import Iterator
from dataclasses import fields, is_dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from exsce_dsl.lang.code_cache import FORMAT, add_parts, code_fingerprint
from exsce_dsl.user_cache import cache_folder, read_cached, write_cached

if TYPE_CHECKING:
    from exsce_dsl.model import Specification

T = TypeVar("T")
Dependencies = tuple[tuple[str, str | None], ...]
"""(path, sha256 of its content, None when it did not exist) of each file an entry was made from."""


def load_spec_cached(path: str | Path) -> Specification:
    """:func:`~exsce_dsl.lang.builders.load_spec`, from the user's cache folder when nothing it
    depends on has changed (see the module's description); raises the same errors."""
    folder = cache_folder()
    if folder is None:
        from exsce_dsl.lang.builders.specification import load_spec

        return load_spec(path)
    entry = folder / "specs" / f"{_entry_name(path)}.pickle"
    found = _valid_entry(read_cached(entry))
    if found is not None:
        return found
    from exsce_dsl.lang.builders.specification import load_spec_reading

    spec, read = load_spec_reading(path)
    dependencies = tuple((p, _digest(p)) for p in [*read, *_map_files(spec)])
    definitions = _msg_path_dependencies()
    write_cached(entry, FORMAT + pickle.dumps((dependencies, definitions, spec), pickle.HIGHEST_PROTOCOL))
    return spec


def _entry_name(path: str | Path) -> str:
    digest = hashlib.sha256()
    add_parts(digest, code_fingerprint().hex(), os.getcwd(), str(path), os.path.abspath(path))
    return digest.hexdigest()[:40]


def _valid_entry(data: bytes | None) -> Specification | None:
    """The specification an entry holds, if every file it depends on is as it was."""
    if data is None or not data.startswith(FORMAT):
        return None
    try:
        dependencies, definitions, spec = pickle.loads(data[len(FORMAT) :])  # noqa: S301 - HMAC checked
    except Exception:  # noqa: BLE001 - a damaged entry is made again
        return None
    if definitions != _msg_path_dependencies():
        return None
    if any(_digest(p) != digest for p, digest in dependencies):
        return None
    found: Specification = spec
    return found


def _msg_path_dependencies() -> tuple[tuple[str, ...], Dependencies]:
    """``$EXSCE_MSG_PATH``'s folders, and each definition file below them with its digest."""
    from exsce_dsl.messages.msg_path import msg_path_files, msg_path_folders

    folders = tuple(str(f) for f in msg_path_folders())
    return folders, tuple((str(p), _digest(str(p))) for p in msg_path_files())


def _digest(path: str) -> str | None:
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError:
        return None


def _map_files(spec: Specification) -> list[str]:
    """The files the map checks read: each map_server YAML and the image it names."""
    from exsce_dsl.maps.grid import map_image
    from exsce_dsl.model import MapModel

    found: list[str] = []
    for map_model in _instances(spec, MapModel):
        if map_model.file is None or map_model.file in found:
            continue
        found.append(map_model.file)
        image = map_image(Path(map_model.file))
        if image is not None:
            found.append(str(image))
    return found


def _instances(root: object, kind: type[T]) -> Iterator[T]:
    """Every ``kind`` inside ``root``, a tree of dataclasses, tuples, lists and dicts."""
    seen: set[int] = set()
    pending: list[Any] = [root]
    while pending:
        item = pending.pop()
        if id(item) in seen or isinstance(item, (str, bytes, int, float, bool, type(None))):
            continue
        seen.add(id(item))
        if isinstance(item, kind):
            yield item
        if is_dataclass(item) and not isinstance(item, type):
            pending.extend(getattr(item, f.name) for f in fields(item))
        elif isinstance(item, (tuple, list, set, frozenset)):
            pending.extend(item)
        elif isinstance(item, dict):
            pending.extend(item.values())
