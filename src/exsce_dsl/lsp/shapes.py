"""SHACL checks for the server, in a process of their own.

Compiling a scenario to PROV-O and validating it takes a tenth of a second for
scenario_c but seconds for a 2,000-line specification, and it is pure Python:
on a thread it would hold the interpreter while the next keystroke waits.  So
it runs in a worker process at a lower priority, once the editing pauses (the fast
checks are published at once), one specification at a time; a root edited
meanwhile is checked again only in its latest state, and results for an older
state are dropped by the caller.
"""

from __future__ import annotations

import asyncio
import logging
import multiprocessing
import os
from collections.abc import Callable
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from exsce_dsl.errors import Diagnostic
from exsce_dsl.model.document import Specification

logger = logging.getLogger(__name__)

IDLE = 0.5
"""Seconds without a new analysis before the SHACL checks start."""

Done = Callable[[str, int, list[Diagnostic]], None]
"""Called with the root, the generation of its analysis, and the SHACL diagnostics."""


def _background() -> None:
    """The worker runs at a lower priority than the server that waits for keystrokes."""
    if hasattr(os, "nice"):
        os.nice(10)


def check_shapes(spec: Specification) -> list[Diagnostic]:
    """Every scenario of ``spec`` against the packaged shapes (as ``exscec check`` does)."""
    from exsce_dsl.rdf.shacl import check_spec_shapes

    return check_spec_shapes(spec)


class ShapeChecks:
    """Runs :func:`check_shapes` for the latest analysis of each root, one at a time, once
    the editing has paused for :data:`IDLE` seconds."""

    def __init__(self, done: Done, idle: float = IDLE) -> None:
        self._done = done
        self._idle = idle
        self._pending: dict[str, tuple[int, Specification]] = {}
        self._timer: asyncio.TimerHandle | None = None
        self._task: asyncio.Task[None] | None = None
        self._executor: Executor | None = None

    def request(self, root: str, generation: int, spec: Specification) -> None:
        self._pending[root] = (generation, spec)
        if self._timer is not None:
            self._timer.cancel()
        self._timer = asyncio.get_running_loop().call_later(self._idle, self._start)

    def _start(self) -> None:
        self._timer = None
        if self._task is None or self._task.done():
            self._task = asyncio.ensure_future(self._drain())

    def forget(self, root: str) -> None:
        self._pending.pop(root, None)

    async def _drain(self) -> None:
        loop = asyncio.get_running_loop()
        while self._pending:
            root, (generation, spec) = self._pending.popitem()
            try:
                found = await loop.run_in_executor(self._pool(), check_shapes, spec)
            except BrokenProcessPool:  # the worker died: go on in a thread
                logger.exception("the SHACL worker process stopped; checking in a thread from now on")
                self._executor = ThreadPoolExecutor(1, thread_name_prefix="exsce-shacl")
                self._pending.setdefault(root, (generation, spec))
                continue
            except Exception:  # a bug in a check must not take the server down
                logger.exception("SHACL check of %s failed", root)
                continue
            self._done(root, generation, found)

    def _pool(self) -> Executor:
        if self._executor is None:
            try:
                context = multiprocessing.get_context("spawn")
                self._executor = ProcessPoolExecutor(1, mp_context=context, initializer=_background)
            except (OSError, ValueError):  # no processes here: a thread, then
                self._executor = ThreadPoolExecutor(1, thread_name_prefix="exsce-shacl")
        return self._executor

    def shutdown(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
        if self._executor is not None:
            self._executor.shutdown(wait=False, cancel_futures=True)
            self._executor = None
