"""Debounced analysis, off the event loop.

Each change restarts a short timer; when it runs out, the documents changed
since the last analysis (and the open documents that read them) are analysed on
a thread of their own, one analysis at a time, while the event loop goes on
answering completion and the like.  Changes that arrive during an analysis wait
for the next one.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from exsce_dsl.lsp.project import OpenDocument, Project, RootAnalysis

logger = logging.getLogger(__name__)

DEBOUNCE = 0.15
"""Seconds of quiet after a change before the analysis starts."""


class Scheduler:
    def __init__(
        self,
        project: Project,
        documents: Callable[[], Mapping[str, OpenDocument]],
        done: Callable[[list[RootAnalysis]], None],
        delay: float = DEBOUNCE,
    ) -> None:
        self.project = project
        self.delay = delay
        self.executor = ThreadPoolExecutor(1, thread_name_prefix="exsce-analysis")
        self._documents = documents
        self._done = done
        self._changed: set[str] = set()
        self._timer: asyncio.TimerHandle | None = None
        self._task: asyncio.Task[None] | None = None
        self._idle: asyncio.Event | None = None

    def touch(self, path: str, delay: float | None = None) -> None:
        """``path`` changed: analyse it (and what reads it) after the delay."""
        self._changed.add(path)
        self._event().clear()
        if self._timer is not None:
            self._timer.cancel()
        self._timer = asyncio.get_running_loop().call_later(
            self.delay if delay is None else delay, self._fire
        )

    async def run(self, job: Callable[..., Any], *args: Any) -> Any:
        """Run ``job`` on the analysis thread (after the analysis under way, if any)."""
        return await asyncio.get_running_loop().run_in_executor(self.executor, job, *args)

    async def settled(self, timeout: float = 30.0) -> None:
        """Return once every change so far is analysed (without waiting for the timer)."""
        if self._timer is not None:
            self._timer.cancel()
            self._fire()
        await asyncio.wait_for(self._event().wait(), timeout)

    def _event(self) -> asyncio.Event:
        if self._idle is None:
            self._idle = asyncio.Event()
            self._idle.set()
        return self._idle

    def _fire(self) -> None:
        self._timer = None
        if self._task is None or self._task.done():
            self._task = asyncio.ensure_future(self._analyse())

    async def _analyse(self) -> None:
        try:
            while self._changed and self._timer is None:
                changed, self._changed = self._changed, set()
                documents = self._documents()
                for root in self.project.roots_to_analyse(changed, documents):
                    # the edited documents first: their diagnostics are published before the others'
                    read = dict(self._documents())
                    try:
                        result = await self.run(self.project.analyse, root, read)
                    except Exception as exc:  # a bug must not stop the analyses of the other documents
                        logger.exception("the analysis of %s failed", root)
                        result = self.project.failed(root, read, exc)  # and the editor is told
                    self._done([result])
        finally:
            if self._timer is None and not self._changed:
                self._event().set()

    def shutdown(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
        self.executor.shutdown(wait=False, cancel_futures=True)
