"""What the store holds of runs' coverage: the gaps ingestion found in their recordings, and how
densely each topic a metric reads was recorded (:mod:`exsce_dsl.prov.run_coverage` writes them)."""

from __future__ import annotations

from collections.abc import Sequence

from exsce_dsl.model.coverage import CoverageGap, Shortfall, TopicRate
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.terms import datetime_of, float_of, int_of, run_query, text_of


def run_coverage(
    store: Store, runs: Sequence[str], *, namespace: str = DEFAULT_NAMESPACE
) -> dict[str, list[CoverageGap]]:
    """Each of ``runs`` (uuids) → what its recording does not cover, in the order ingestion found
    it ([] for a run without gaps, or one the store lacks)."""
    found: dict[str, list[tuple[int, CoverageGap]]] = {run: [] for run in runs}
    if not found:
        return {}
    for row in run_query(store, "run_coverage", {"run": list(found)}, namespace):
        run, shortfall, reason = text_of(row["run"]), text_of(row["shortfall"]), text_of(row["reason"])
        if run not in found or shortfall is None or reason is None:
            continue
        gap = CoverageGap(
            Shortfall(shortfall),
            reason,
            text_of(row["robot"]),
            text_of(row["topic"]),
            _metrics(text_of(row["metrics"])),
            datetime_of(row["start"]),
            datetime_of(row["end"]),
        )
        found[run].append((_index(text_of(row["gap"])), gap))
    return {run: [gap for _, gap in sorted(gaps, key=lambda g: g[0])] for run, gaps in found.items()}


def run_topic_rates(
    store: Store, runs: Sequence[str], *, namespace: str = DEFAULT_NAMESPACE
) -> dict[str, list[TopicRate]]:
    """Each of ``runs`` (uuids) → the rate of each topic its metrics read, in the order ingestion
    found them ([] for a run the store holds none of)."""
    found: dict[str, list[tuple[int, TopicRate]]] = {run: [] for run in runs}
    if not found:
        return {}
    for row in run_query(store, "run_topic_rates", {"run": list(found)}, namespace):
        run, topic = text_of(row["run"]), text_of(row["topic"])
        if run not in found or topic is None:
            continue
        rate = TopicRate(
            topic,
            text_of(row["robot"]),
            int_of(row["messages"]),
            float_of(row["rate"]) or 0.0,
            _metrics(text_of(row["metrics"])),
        )
        found[run].append((_index(text_of(row["entity"])), rate))
    return {run: [rate for _, rate in sorted(rates, key=lambda r: r[0])] for run, rates in found.items()}


def _metrics(text: str | None) -> tuple[str, ...]:
    return tuple(text.split()) if text else ()


def _index(iri: str | None) -> int:
    """The NNN of ``.../coverage-NNN`` or ``.../rate-NNN`` (the order ingestion found them in)."""
    tail = (iri or "").rsplit("-", 1)[-1]
    return int(tail) if tail.isdigit() else 0
