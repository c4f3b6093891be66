"""Ingest bags: metrics and run provenance into the store, one transaction per run.

A bag that cannot be used (unreadable, truncated, empty, from another
scenario) is reported and nothing of it is written; the other bags of the
same call still ingest.  A bag already in the store (same content, hence the
same run id) is skipped.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from pyoxigraph import Literal

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag, content_hash, run_uuid
from exsce_dsl.store.base import Store
from exsce_dsl.store.writing import add_prov

_RUN_ID = "https://www.sesame-project.org/scenarios/run"
_KNOWN = f"ASK WHERE {{ GRAPH ?g {{ ?run <{_RUN_ID}> ?id }} }}"


@dataclass(frozen=True)
class IngestResult:
    bag: Path
    status: str  # ingested | skipped | failed
    message: str
    run_id: str | None = None
    problems: tuple[str, ...] = field(default_factory=tuple)
    statements: int = 0

    @property
    def failed(self) -> bool:
        return self.status == "failed"


def _analyse(args: tuple[Path, Scenario]) -> AnalysedRun | ExsceError:
    try:
        return analyse_bag(*args)
    except ExsceError as exc:
        return exc


def analyse_all(
    paths: Sequence[Path], scenario: Scenario, jobs: int = 1
) -> Iterator[AnalysedRun | ExsceError]:
    """Analyse bags in order, in ``jobs`` processes (bag reading and metrics are the costly part)."""
    work = [(p, scenario) for p in paths]
    if jobs <= 1 or len(paths) <= 1:
        yield from map(_analyse, work)
        return
    with ProcessPoolExecutor(max_workers=min(jobs, len(paths), os.cpu_count() or 1)) as pool:
        yield from pool.map(_analyse, work)


def ingest_bags(
    paths: Sequence[Path],
    scenario: Scenario,
    store: Store,
    jobs: int = 1,
    progress: Callable[[IngestResult], None] | None = None,
) -> list[IngestResult]:
    """Ingest each bag as a run of ``scenario``; the scenario itself is added to the store first."""
    add_prov(store, compile_scenario(scenario))
    results: list[IngestResult] = []
    todo: list[Path] = []
    seen: set[str] = set()
    for path in paths:
        digest = content_hash(path) if path.exists() else None
        known = digest is not None and (
            digest in seen or store.ask(_KNOWN, {"id": Literal(run_uuid(digest))})
        )
        if digest is not None:
            seen.add(digest)
        if known:
            assert digest is not None
            result = IngestResult(
                path, "skipped", f"{path}: already ingested (same content)", run_uuid(digest)
            )
            results.append(result)
            if progress:
                progress(result)
        else:
            todo.append(path)
    for path, outcome in zip(todo, analyse_all(todo, scenario, jobs), strict=True):
        if isinstance(outcome, ExsceError):
            result = IngestResult(
                path,
                "failed",
                outcome.message if str(path) in outcome.message else f"{path}: {outcome.message}",
            )
        else:
            try:
                report = add_prov(store, compile_run(outcome.run, scenario))
            except ExsceError as exc:
                result = IngestResult(path, "failed", f"{path}: {exc.message}")
            else:
                result = IngestResult(
                    path,
                    "ingested",
                    f"{path}: run {outcome.run.uuid} ({len(outcome.run.metrics)} metric values)",
                    outcome.run.uuid,
                    tuple(outcome.problems),
                    report.statements,
                )
        results.append(result)
        if progress:
            progress(result)
    return results
