"""Ingest bags: metrics and run provenance into the store, each run wholly or not at all.

A bag that cannot be used (unreadable, truncated, empty, from another
scenario) is reported and nothing of it is written; the other bags of the
same call still ingest.  A bag the store holds as a run of the scenario already
(same content, hence the same run id) is skipped, unless ``replace`` is given:
then it is analysed again and its run replaced in one write
(:mod:`exsce_dsl.store.run_replacing`).  A bag may be a run of several scenarios
(:mod:`exsce_dsl.runs.bag_runs`).
"""

from __future__ import annotations

import dataclasses
import importlib
import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, cast

from exsce_dsl.errors import ExsceError, IngestFailed, Remedied
from exsce_dsl.model import Scenario
from exsce_dsl.parallel.workers import workers
from exsce_dsl.prov import DEFAULT_NAMESPACE, compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.remedies import REPLACE_THE_RUN, VERIFY_AGAIN
from exsce_dsl.runs.bag_identity import content_hash
from exsce_dsl.runs.bag_runs import BagRun, bag_runs
from exsce_dsl.store import RunWriter, Store, WriteReport, Written, add_prov, replace_run, verdict_graphs
from exsce_dsl.wording import counted

if TYPE_CHECKING:
    from exsce_dsl.runs.analyse import AnalysedRun

ANALYSIS = "exsce_dsl.runs.analyse"
"""What reads a bag and computes its metrics (numpy, rosbags, the monitors): imported while the
bags are hashed, when this process reads them itself."""


class IngestStatus(str, Enum):
    """What became of a bag."""

    INGESTED = "ingested"
    SKIPPED = "skipped"
    """Its content is a run of the scenario the store holds already."""
    REPLACED = "replaced"
    """Its run was analysed again and replaced (``replace``)."""
    FAILED = "failed"
    """Nothing of it was written; the message says why."""

    def __str__(self) -> str:
        return self.value


@dataclass(frozen=True)
class IngestResult:
    bag: Path
    status: IngestStatus
    message: str
    run_id: str | None = None
    problems: tuple[str, ...] = field(default_factory=tuple)
    statements: int = 0
    picked: tuple[str, ...] = field(default_factory=tuple)
    """What ingestion picked for the run: conventions detected, a simulated timeline."""
    clocks: tuple[str, ...] = field(default_factory=tuple)
    """Which clock each of the bag's sources was timed by (``exscec ingest -v``)."""
    remedied: Remedied | None = None
    """The message as a problem and its remedy, when it has one (:meth:`said`)."""

    @property
    def failed(self) -> bool:
        return self.status is IngestStatus.FAILED

    def said(self, wording: Mapping[str, str] | None = None) -> str:
        """The message, its remedy in ``wording`` (the command line's: ``cli.common.REMEDIES``)."""
        return self.remedied.said(wording) if self.remedied else self.message

    def failure(self) -> IngestFailed:
        """This result as the error of what needed its run (with the remedy, if it has one)."""
        cause = self.remedied
        if cause is None:
            return IngestFailed(self.message)
        return IngestFailed(cause.problem, remedy=cause.remedy, about=cause.about)


def _analyse(args: tuple[Path, Scenario, str | None, str | None, bool]) -> AnalysedRun | ExsceError:
    from exsce_dsl.runs.analyse import analyse_bag

    try:
        return analyse_bag(*args)
    except ExsceError as exc:
        return exc


def _digest(path: Path) -> str | None:
    return content_hash(path) if path.exists() else None


def stored_bag_run_id(
    path: Path, store: Store, scenario_id: str, namespace: str = DEFAULT_NAMESPACE
) -> str | None:
    """The uuid of the run of ``scenario_id`` that ``path`` holds when the store has it already
    (same content), else None."""
    (found,) = bag_runs(store, [_digest(path)], scenario_id, namespace)
    return found.run_id if found is not None and found.stored else None


@dataclass(frozen=True)
class _Todo:
    """A bag to analyse, and what its run is in the store."""

    path: Path
    digest: str | None
    run: BagRun | None
    replacing: bool

    @property
    def run_id(self) -> str | None:
        return self.run.run_id if self.run is not None else None


def ingest_bags(
    paths: Sequence[Path],
    scenario: Scenario,
    store: Store,
    jobs: int = 1,
    progress: Callable[[IngestResult], None] | None = None,
    namespace: str = DEFAULT_NAMESPACE,
    dask_address: str | None = None,
    replace: bool = False,
    strict: bool = False,
) -> list[IngestResult]:
    """Ingest each bag as a run of ``scenario``; the scenario itself is added to the store first.

    With ``jobs`` > 1, worker processes hash the bags, then read them and compute their metrics;
    with ``dask_address`` (a Dask scheduler's address) the cluster's workers do, and ``jobs`` is not
    used (see :mod:`exsce_dsl.parallel.dask_client`).  This process alone compiles each run's PROV and
    writes it, each run wholly or not at all, in group commits when the runs come faster than the
    store takes them one by one (:mod:`exsce_dsl.store.batch_writing`).  With ``replace``, a bag
    the store holds as a run of ``scenario`` is analysed again and its run's graphs replaced in
    one write, its verdicts dropped (:func:`~exsce_dsl.store.run_replacing.replace_run`).

    ``strict``: a bag whose run would lack a metric value fails (nothing of it is written), its
    message saying which values and why.
    """
    add_prov(store, compile_scenario(scenario, namespace))
    results: list[IngestResult] = []

    def told(result: IngestResult) -> None:
        results.append(result)
        if progress:
            progress(result)

    in_process = dask_address is None and (jobs <= 1 or len(paths) <= 1)
    # what the workers open: on a cluster, from the root (a worker's working folder is its own);
    # messages name the paths as given
    opened = dict(zip(paths, _shared_paths(paths) if dask_address is not None else paths, strict=True))
    # in this process, what reads the bags is imported while they are hashed (hashing lets go of
    # Python's lock); for worker processes, before they start (forked, they have it)
    importing = _Importing(ANALYSIS) if in_process else None
    if importing is None:
        importlib.import_module(ANALYSIS)
    with workers(jobs, len(paths), dask_address) as mapper:
        # a digest the cluster could not compute is None: the bag's analysis then says what is wrong
        digests = [d if isinstance(d, str) else None for d in mapper(_digest, [opened[p] for p in paths])]
        if importing is not None:
            importing.wait()
        todo = _to_analyse(store, paths, digests, scenario.id, namespace, replace, told)
        outcomes = mapper(_analyse, [(opened[t.path], scenario, t.digest, t.run_id, strict) for t in todo])
        _write_runs(store, scenario, namespace, todo, outcomes, told)
    return results


def _to_analyse(
    store: Store,
    paths: Sequence[Path],
    digests: Sequence[str | None],
    scenario_id: str,
    namespace: str,
    replace: bool,
    told: Callable[[IngestResult], None],
) -> list[_Todo]:
    """The bags to analyse; each other one (its run is stored, or an earlier bag has its content)
    is told as skipped."""
    todo: list[_Todo] = []
    seen: dict[str, Path] = {}
    stored = bag_runs(store, digests, scenario_id, namespace)
    for path, digest, run in zip(paths, digests, stored, strict=True):
        skipped = _skipped(path, digest, run, seen, scenario_id, replace)
        if digest is not None:
            seen.setdefault(digest, path)
        if skipped is not None:
            told(skipped)
        else:
            todo.append(_Todo(path, digest, run, replace and run is not None and run.stored))
    return todo


def _write_runs(
    store: Store,
    scenario: Scenario,
    namespace: str,
    todo: Sequence[_Todo],
    outcomes: Iterable[AnalysedRun | ExsceError],
    told: Callable[[IngestResult], None],
) -> None:
    """Each analysed run's PROV, written as the analyses come (in group commits; a replaced run
    in a write of its own), and each bag's result told in order once its run is written."""

    def written(done: Written) -> None:
        bag, analysed = cast("tuple[_Todo, AnalysedRun | None]", done.key)
        told(_result(bag, analysed, done))

    with RunWriter(store, written) as writer:
        for bag, outcome in zip(todo, outcomes, strict=True):
            if isinstance(outcome, ExsceError):
                writer.flush()  # the bags before it are told first
                written(Written((bag, None), None, outcome))
                continue
            try:
                document = compile_run(outcome.run, scenario, namespace)
                if bag.replacing:
                    writer.flush()
                    report = replace_run(store, document, outcome.run.uuid, namespace)
                    written(Written((bag, outcome), report))
                    continue
            except ExsceError as exc:
                writer.flush()
                written(Written((bag, outcome), None, exc))
                continue
            writer.add(document, (bag, outcome))


def _shared_paths(paths: Sequence[Path]) -> list[Path]:
    from exsce_dsl.parallel.dask_client import shared_paths

    return shared_paths(paths)


class _Importing:
    """Import a module on a thread of its own; :meth:`wait` for it (an import error is raised
    there, as the import would have raised it)."""

    def __init__(self, name: str) -> None:
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, args=(name,), daemon=True)
        self._thread.start()

    def _run(self, name: str) -> None:
        try:
            importlib.import_module(name)
        except BaseException as exc:  # noqa: BLE001 - raised again by wait()
            self._error = exc

    def wait(self) -> None:
        self._thread.join()
        if self._error is not None:
            raise self._error


def _skipped(
    path: Path, digest: str | None, run: BagRun | None, seen: dict[str, Path], scenario_id: str, replace: bool
) -> IngestResult | None:
    """The result of a bag that is not analysed (its run is stored, or an earlier bag of the call
    has its content), else None."""
    if digest is None or run is None:
        return None
    if digest in seen:
        message = f"{path}: same content as {seen[digest]} (run {run.run_id}); skipped"
        return IngestResult(path, IngestStatus.SKIPPED, message, run.run_id)
    if not run.stored or replace:
        return None
    remedied = Remedied(
        f"{path}: already a run of scenario '{scenario_id}' (run {run.run_id})", REPLACE_THE_RUN
    )
    return IngestResult(path, IngestStatus.SKIPPED, remedied.said(), run.run_id, remedied=remedied)


def _result(bag: _Todo, analysed: AnalysedRun | None, done: Written) -> IngestResult:
    """What became of a bag, once its run was written (or not)."""
    path = bag.path
    if done.error is not None or done.report is None or analysed is None:
        message = done.error.message if done.error is not None else "not written"
        prefix = "" if str(path) in message else f"{path}: "
        cause = done.error.remedied if done.error is not None else None
        remedied = dataclasses.replace(cause, problem=prefix + cause.problem) if cause else None
        return IngestResult(path, IngestStatus.FAILED, prefix + message, remedied=remedied)
    said, dropped, others = _what_was_done(bag, len(analysed.run.metrics), done.report)
    done_text, rest = f"{path}: run {analysed.run.uuid} {said}", others + _uncovered(analysed)
    remedied = Remedied(done_text, VERIFY_AGAIN, rest) if dropped else None
    return IngestResult(
        path,
        IngestStatus.REPLACED if bag.replacing else IngestStatus.INGESTED,
        remedied.said() if remedied else done_text + rest,
        analysed.run.uuid,
        tuple(analysed.problems),
        done.report.statements,
        tuple(analysed.picked()),
        tuple(analysed.clocks()),
        remedied=remedied,
    )


def _uncovered(analysed: AnalysedRun) -> str:
    """``; its recording does not cover all of it: 2 gaps (cut short)``, or nothing."""
    gaps = analysed.run.coverage
    if not gaps:
        return ""
    kinds = ", ".join(dict.fromkeys(g.kind.value.replace("_", " ") for g in gaps))
    return f"; its recording does not cover all of it: {counted(len(gaps), 'gap')} ({kinds})"


def _what_was_done(bag: _Todo, values: int, report: WriteReport) -> tuple[str, bool, str]:
    """``(51 metric values)``; whether a replaced run's verdicts were dropped (the remedy, to
    verify it again, goes after that); then what else a reader should know of the run."""
    said, dropped = f"({values} metric values)", False
    if bag.replacing:
        said = f"analysed again {said}, in place of the stored one"
        if verdict_graphs(report.replaced):
            said, dropped = f"{said}; its verdicts were dropped", True
    others = ""
    if bag.run is not None and bag.run.others:
        others = f"; the bag is also a run of scenario {', '.join(repr(s) for s in bag.run.others)}"
    return said, dropped, others
