"""A bag's identity: the sha256 of its bytes, from which its run id follows
(:func:`~exsce_dsl.model.runs.run_uuid`).

Apart from :mod:`exsce_dsl.runs.analyse` (which uses it) because ingestion hashes
every bag before it reads any, and needs none of what reading takes for that.
"""

from __future__ import annotations

import hashlib
from pathlib import Path


def content_hash(path: Path) -> str:
    """sha256 of the bag's bytes (all files of a ROS 2 bag folder, in name order)."""
    digest = hashlib.sha256()
    files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    for file in files:
        with file.open("rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()
