"""How long each store query took (``exscec --timings``): a collector that the stores' reads and
updates and the library's queries report to while it is on.

Off (the default), a query pays one look-up of a context variable.  On, every SELECT, ASK and
update a store runs is timed once: a library query under its name (the store's own timing of the
same call is not counted again), any other text under its first words.  Writes of graphs are not
queries and are not timed here.
"""

from __future__ import annotations

import functools
import re
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, TypeVar, cast

Answer = TypeVar("Answer")
Method = TypeVar("Method", bound=Callable[..., Any])

AD_HOC_WORDS = 6
"""Words of an ad-hoc query's text that name it in the table."""


@dataclass
class QueryTime:
    """One query's calls: the seconds each took, and the rows they answered in all."""

    name: str
    seconds: list[float] = field(default_factory=list)
    rows: int = 0

    @property
    def calls(self) -> int:
        return len(self.seconds)

    @property
    def total(self) -> float:
        return sum(self.seconds)

    @property
    def longest(self) -> float:
        return max(self.seconds, default=0.0)


@dataclass
class QueryTimes:
    """The queries timed while the collector was on, by name."""

    by_name: dict[str, QueryTime] = field(default_factory=dict)
    _running: bool = False

    def add(self, name: str, seconds: float, rows: int) -> None:
        found = self.by_name.get(name)
        if found is None:
            found = self.by_name[name] = QueryTime(name)
        found.seconds.append(seconds)
        found.rows += rows

    def slowest_first(self) -> list[QueryTime]:
        return sorted(self.by_name.values(), key=lambda t: (-t.total, t.name))

    @property
    def total(self) -> float:
        return sum(t.total for t in self.by_name.values())

    @property
    def calls(self) -> int:
        return sum(t.calls for t in self.by_name.values())

    def lines(self) -> list[str]:
        """The table ``exscec --timings`` prints: one line per query, slowest in total first, then
        the sum."""
        header = ("query", "calls", "total ms", "max ms", "rows")
        body = [
            (t.name, f"{t.calls:,d}", f"{t.total * 1e3:,.2f}", f"{t.longest * 1e3:,.2f}", f"{t.rows:,d}")
            for t in self.slowest_first()
        ]
        rows = [header, *body, ("all", f"{self.calls:,d}", f"{self.total * 1e3:,.2f}", "", "")]
        width = [max(len(row[i]) for row in rows) for i in range(len(header))]
        return [
            "  ".join(
                [row[0].ljust(width[0]), *(cell.rjust(w) for cell, w in zip(row[1:], width[1:], strict=True))]
            ).rstrip()
            for row in rows
        ]


_TIMES: ContextVar[QueryTimes | None] = ContextVar("exsce_query_times", default=None)


@contextmanager
def timing_queries() -> Iterator[QueryTimes]:
    """Time every store query run inside the block (in this thread or task), into the collector
    it yields."""
    times = QueryTimes()
    token = _TIMES.set(times)
    try:
        yield times
    finally:
        _TIMES.reset(token)


def measured(
    text: str, run: Callable[[], Answer], rows: Callable[[Answer], int], name: str | None = None
) -> Answer:
    """``run()``'s answer, timed under ``name`` (a library query's) or the first words of the query
    ``text``, if the collector is on and no outer call is being timed already."""
    times = _TIMES.get()
    if times is None or times._running:
        return run()
    times._running = True
    answered = 0  # a query that fails is timed too, with no rows
    started = time.perf_counter()
    try:
        answer = run()
        answered = rows(answer)
        return answer
    finally:
        seconds = time.perf_counter() - started
        times._running = False
        times.add(name or ad_hoc_name(text), seconds, answered)


def timed_query(rows: Callable[[Any], int]) -> Callable[[Method], Method]:
    """A store's method ``(self, text, ...)`` that runs query ``text``, timed by :func:`measured`."""

    def decorate(method: Method) -> Method:
        @functools.wraps(method)
        def timed(self: object, text: str, *args: Any, **kwargs: Any) -> Any:
            return measured(text, lambda: method(self, text, *args, **kwargs), rows)

        return cast(Method, timed)

    return decorate


def one(_: object) -> int:
    """The rows of an ASK's answer."""
    return 1


def none(_: object) -> int:
    """The rows of an update's answer."""
    return 0


_PROLOGUE = re.compile(r"\s*(?:(?:PREFIX\s+[^:\s]*:\s*<[^>]*>|BASE\s+<[^>]*>|#[^\n]*)\s*)*", re.IGNORECASE)


def ad_hoc_name(text: str) -> str:
    """``SPARQL "SELECT DISTINCT ?g WHERE { GRAPH…"``: a query that is not the library's, by the
    first words after its prefixes."""
    body = text[_PROLOGUE.match(text).end() :]  # type: ignore[union-attr]  # the pattern matches ""
    words = body.split()
    shown = " ".join(words[:AD_HOC_WORDS])
    return f'SPARQL "{shown}{"…" if len(words) > AD_HOC_WORDS else ""}"'
