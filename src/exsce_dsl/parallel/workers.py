"""Where work runs: in this process, over a pool of processes on this machine (``--jobs``), or on a
Dask cluster (``--cluster``, :mod:`exsce_dsl.parallel.dask_client`), behind one ``map``."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any

Mapper = Callable[[Callable[[Any], Any], Iterable[Any]], Iterator[Any]]
"""``map``, a process pool's or a Dask cluster's (results in order)."""


@contextmanager
def workers(jobs: int, tasks: int, dask_address: str | None = None) -> Iterator[Mapper]:
    """``map`` on the Dask cluster at ``dask_address``, in this process (one job), or over a pool of
    ``jobs`` processes (no more than ``tasks`` and this machine's cores) kept for every call."""
    if dask_address is not None:
        from exsce_dsl.parallel.dask_client import dask_map

        with dask_map(dask_address) as mapper:
            yield mapper
        return
    if jobs <= 1 or tasks <= 1:
        yield map
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # forkserver, not fork: this process may hold threads (rclpy's and Fast DDS's after a live run
    # in the same process, as the demo's steps are), and a child forked from them can crash
    context = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=min(jobs, tasks, os.cpu_count() or 1), mp_context=context) as pool:
        yield pool.map


__all__ = ["Mapper", "workers"]
