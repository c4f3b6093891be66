"""Per-bag work on a Dask cluster (``exscec ingest --cluster ADDRESS``).

The workers do what ``--jobs`` processes do on one machine: hash each bag and read
it and compute its metrics.  The client (``exscec``) compiles each run's PROV and
writes it, one transaction per run, as it does with ``--jobs``: a store is written
by one process, whatever the store (an embedded store cannot be opened by two, and
a SPARQL endpoint's credentials stay on the client); the writes are not what limits
a campaign's speed (``docs/scaling.md``).  A killed worker therefore never leaves a
run half-written: its task is given to another worker by Dask's scheduler, and the
client writes the run when it comes back.  A task that raises is tried once more
(``retries=1``); a bag that cannot be used is a result, not an exception, and is
reported by name.

Bags are read where they are: the workers open the paths the client gives, so the
paths must name the same files on every worker (a shared filesystem: NFS, a mounted
bucket, the same machine).  A worker's working folder is its own, so a relative path
is made absolute first, against the client's working folder (:func:`shared_paths`).
URLs are not opened.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from exsce_dsl.errors import ExsceError
from exsce_dsl.remedies import INSTALL_DASK

DASK_SCHEDULER_ENV = "EXSCE_DASK_SCHEDULER"
"""The environment variable ``--cluster`` defaults to: the scheduler's address."""

CONNECT_SECONDS = 20.0


def dask_address(given: str | None) -> str | None:
    """The scheduler's address: ``given``, else $EXSCE_DASK_SCHEDULER, else None."""
    return given or os.environ.get(DASK_SCHEDULER_ENV) or None


def shared_paths(paths: Iterable[Path]) -> list[Path]:
    """``paths`` as a worker must be given them: from the root, a relative one taken from this
    process's working folder (``exscec ingest ../runs/*.bag`` names the caller's bags, not
    files under the worker's folder)."""
    return [path.absolute() for path in paths]


@contextmanager
def dask_map(address: str) -> Iterator[Callable[[Callable[[Any], Any], Iterable[Any]], Iterator[Any]]]:
    """A ``map`` whose calls run on the Dask cluster at ``address``, results in order; a task
    that failed on the cluster (twice, or killed its workers) gives an ExsceError in its place."""
    try:
        from distributed import Client
    except ImportError:
        raise ExsceError("a Dask cluster needs Dask's distributed package", remedy=INSTALL_DASK) from None
    try:
        client = Client(address, timeout=CONNECT_SECONDS, set_as_default=False)  # type: ignore[no-untyped-call]
    except (OSError, TimeoutError, ValueError) as exc:
        raise ExsceError(f"cannot reach the Dask scheduler at {address}: {exc}") from None

    def mapper(function: Callable[[Any], Any], items: Iterable[Any]) -> Iterator[Any]:
        futures = client.map(function, list(items), pure=False, retries=1)
        for future in futures:
            try:
                yield future.result()
            except Exception as exc:  # noqa: BLE001 - the task's own failure, reported as the bag's
                yield ExsceError(f"failed on the cluster: {type(exc).__name__}: {exc}")

    try:
        yield mapper
    finally:
        client.close()  # type: ignore[no-untyped-call]


__all__ = ["DASK_SCHEDULER_ENV", "dask_address", "dask_map", "shared_paths"]
