"""Values kept in the user's cache folder for as long as exsce's code is unchanged.

:func:`code_fingerprint` digests exsce's code and resources, Python's version and the libraries
that parsing and checking use; :func:`cached_by_code` keeps a value made by a function under
that digest (the parsed standard library, :func:`cached_standard_metrics`).  Below the builders
(``lang/builders``), which cache the standard library here; :mod:`.spec_cache`, above them, keeps
checked specifications under this fingerprint and the files they were made from.  Entries are
pickles, unpickled only after :func:`~exsce_dsl.user_cache.read_cached` has checked their HMAC
(see :mod:`.spec_cache`).
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import sys
from collections.abc import Callable
from importlib.util import find_spec
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar

from exsce_dsl.user_cache import cache_folder, read_cached, write_cached

if TYPE_CHECKING:
    from exsce_dsl.model.metrics import MetricDefinition

T = TypeVar("T")

FORMAT = b"exsce spec cache 1"
"""Changes whenever what an entry holds changes shape."""

LIBRARIES = ("textx", "arpeggio", "rosbags", "yaml")
"""Installed packages whose version changes what loading a specification gives."""

def cached_standard_metrics(make: Callable[[], tuple[MetricDefinition, ...]]) -> tuple[MetricDefinition, ...]:
    """The standard library's metrics, parsed by ``make`` once per installation of exsce (the
    library ships in the package, and its types are rosbags')."""
    return cached_by_code("stdlib-metrics", make)


def cached_by_code(name: str, make: Callable[[], T]) -> T:
    folder = cache_folder()
    if folder is None:
        return make()
    entry = folder / "specs" / f"{name}-{code_fingerprint().hex()[:32]}.pickle"
    data = read_cached(entry)
    if data is not None and data.startswith(FORMAT):
        try:
            value: T = pickle.loads(data[len(FORMAT) :])  # noqa: S301 - read_cached checked its HMAC
            return value
        except Exception:  # noqa: BLE001 - a damaged entry is made again
            pass
    value = make()
    write_cached(entry, FORMAT + pickle.dumps(value, pickle.HIGHEST_PROTOCOL))
    return value


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> bytes:
    """A digest of exsce's code and resources (each file's path, size and modification time, as
    Python decides whether a ``.pyc`` is current), exsce's and Python's versions, and where and
    when the libraries that parsing and checking use were installed."""
    from exsce_dsl import __version__

    digest = hashlib.sha256()
    add_parts(digest, FORMAT, __version__, sys.version)
    package = Path(__file__).resolve().parents[1]
    # the grammar ships in the package (a wheel) or beside it (a checkout: see exsce_dsl.resources)
    for root in (package, package.parents[1] / "grammar"):
        for dirpath, dirnames, filenames in os.walk(root):
            dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
            for name in sorted(filenames):
                if name.endswith((".pyc", ".tmp")):
                    continue
                stat = os.stat(os.path.join(dirpath, name))
                add_parts(digest, os.path.join(dirpath, name), str(stat.st_size), str(stat.st_mtime_ns))
    for library in LIBRARIES:
        spec = find_spec(library)
        origin = spec.origin if spec is not None else None
        stat_of = os.stat(origin) if origin else None
        add_parts(digest, library, str(origin), str(stat_of.st_mtime_ns if stat_of else None))
    return digest.digest()


def add_parts(digest: Any, *parts: str | bytes) -> None:
    """Each part into ``digest``, its length first (no two lists of parts digest alike)."""
    for part in parts:
        data = part.encode("utf-8", "surrogateescape") if isinstance(part, str) else part
        digest.update(len(data).to_bytes(8, "little") + data)
