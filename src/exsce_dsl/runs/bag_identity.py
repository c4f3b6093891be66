"""A bag's identity: the sha256 of its bytes, and the run id that follows from it.

Apart from :mod:`exsce_dsl.runs.analyse` (which uses it) because ingestion hashes
every bag before it reads any, and needs none of what reading takes for that.
"""

from __future__ import annotations

import hashlib
import uuid
from pathlib import Path

_RUN_NAMESPACE = uuid.UUID("5b8f9a52-3f0c-4a8e-8f0e-2d6c1b7e4a90")


def content_hash(path: Path) -> str:
    """sha256 of the bag's bytes (all files of a ROS 2 bag folder, in name order)."""
    digest = hashlib.sha256()
    files = [path] if path.is_file() else sorted(p for p in path.rglob("*") if p.is_file())
    for file in files:
        with file.open("rb") as stream:
            for block in iter(lambda: stream.read(1 << 20), b""):
                digest.update(block)
    return digest.hexdigest()


def run_uuid(digest: str) -> str:
    """A run's id follows from its bag's content, so ingesting a bag twice is recognised."""
    return str(uuid.uuid5(_RUN_NAMESPACE, digest))


def scenario_run_uuid(digest: str, scenario_iri: str) -> str:
    """The id of a bag's run under a scenario other than the one the store first held it as: the
    bag's content and the scenario's IRI (:func:`run_uuid` stays the bag's first run's)."""
    return str(uuid.uuid5(_RUN_NAMESPACE, f"{digest} {scenario_iri}"))
