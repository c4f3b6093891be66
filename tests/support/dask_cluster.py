"""A real Dask cluster for the tests (a scheduler and worker processes on 127.0.0.1), and a
worker killed while it runs a task of a given function."""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from distributed import Client, LocalCluster


@contextmanager
def local_cluster(workers: int = 2) -> Iterator[LocalCluster]:
    # the dashboard on a free port too: None still tries 8787, which another worker's cluster may hold
    with LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
    ) as started:
        yield started


@contextmanager
def a_worker_killed_while_running(cluster: LocalCluster, function: str) -> Iterator[list[int]]:
    """While the block runs, SIGKILL the first worker seen holding a task of ``function``; the
    list given holds its pid once it is killed.  On the way out, wait for the nanny to start a
    new worker, so that the cluster is whole again for the next test."""
    killed: list[int] = []
    with Client(cluster.scheduler_address, set_as_default=False) as watcher:
        pids = watcher.run(os.getpid)  # worker address -> its process

        def kill_a_busy_worker() -> None:
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and not killed:
                for worker, keys in watcher.processing().items():
                    if any(function in str(key) for key in keys):
                        os.kill(pids[worker], signal.SIGKILL)
                        killed.append(pids[worker])
                        return
                time.sleep(0.005)

        killer = threading.Thread(target=kill_a_busy_worker)
        killer.start()
        try:
            yield killed
        finally:
            killer.join()
    if killed:
        cluster.wait_for_workers(len(cluster.workers), timeout=60)
