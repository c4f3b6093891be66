"""The store benchmark's fast synthetic fill (bench/store.py ``--fill synthetic``): the same runs as
the end-to-end fill (``store_synthetic.synthetic_runs``, same seed), as the same quads, without
running ``compile_run`` for each.

``compile_run`` and the conversion to quads (``exsce_dsl.store.writing.stored_graphs``) take about
27 ms a run here: 10⁵ runs would spend 45 min of CPU on them.  A synthetic run's quads differ from
another's of the same *shape* (its number of hotspots, 0 to 3) only in its values: the uuid, the
bag's name, the times, the metric values, the hotspots' positions and counts.  So for each shape
one run is converted the real way, its N-Quads become a template (each of those values a slot,
found by its text; blank-node labels a slot too, made unique per run), and every run of the fill
is its template with its own values written in: about 1 ms a run.  Whatever the conversion writes
(new graphs of the layout included) comes along, because the template is its output.

Worker processes draw the runs (each draws them all, from the seed, so run n is the same run as
the end-to-end fill's n-th) and write their share of chunks as N-Quads files; the parent hands each
file to Oxigraph's bulk loader as it arrives (at most a few files wait on disk).

:func:`check_templates` compares, for given runs, the templated N-Quads with the real conversion's
(bench/store.py asserts it, and that a store filled each way answers the same).
"""

from __future__ import annotations

import dataclasses
import datetime
import enum
import multiprocessing
import re
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from pyoxigraph import RdfFormat, serialize
from store_synthetic import synthetic_run, synthetic_runs, synthetic_scenario

from exsce_dsl.model import Scenario
from exsce_dsl.model.runs import Run
from exsce_dsl.prov.run import compile_run
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.run_summary import RUN_ID_BUCKET
from exsce_dsl.store.writing import stored_graphs

XSD_INT = "http://www.w3.org/2001/XMLSchema#int"
BLANK = -1
"""The slot of a blank node's label."""
BUCKET = -2
"""The slot of the run-id bucket's key (``summaries/run-ids/<the uuid's first characters>``)."""
CHUNK = 250
"""Runs per N-Quads file (about 120 MB)."""
WAITING = 2
"""Files a worker may have written that the loader has not taken yet (disk stays bounded)."""
GraphFilter = Callable[[str], bool]


def run_tokens(run: Run) -> list[str]:
    """Each value of ``run`` as its text in N-Quads, in a fixed order (two runs of one shape give
    lists of one length): floats and times as the lexical form of their literal (with its
    opening and closing quote), counts as an ``xsd:int`` literal, strings (uuid, bag) as they are."""
    found: list[str] = []

    def walk(value: object) -> None:
        if value is None or isinstance(value, bool | enum.Enum):
            return
        if isinstance(value, float):
            found.append(f'"{value!r}"')
        elif isinstance(value, int):
            found.append(f'"{value}"^^<{XSD_INT}>')
        elif isinstance(value, datetime.datetime):
            found.append(f'"{value.isoformat()}"')
        elif isinstance(value, str):
            found.append(value)
        elif isinstance(value, tuple):
            for item in value:
                walk(item)
        elif dataclasses.is_dataclass(value):
            for field in dataclasses.fields(value):
                walk(getattr(value, field.name))

    walk(run)
    return found


def real_nquads(run: Run, scenario: Scenario, keep: GraphFilter | None = None) -> str:
    """The run's quads as the store's write path makes them (``stored_graphs``), as N-Quads."""
    graphs = stored_graphs(compile_run(run, scenario))
    quads = [q for name, graph in graphs.items() if keep is None or keep(name) for q in graph]
    return (serialize(quads, format=RdfFormat.N_QUADS) or b"").decode()


@dataclass(frozen=True)
class Template:
    """One shape's N-Quads, cut at each value: ``chunks[0] value chunks[1] value ...``."""

    tokens: int
    chunks: tuple[str, ...]
    slots: tuple[int, ...]
    """For each cut, the index of the run's token that fills it (:data:`BLANK`: a blank node)."""

    def fill(self, run: Run, number: int) -> str:
        tokens = run_tokens(run)
        assert len(tokens) == self.tokens, "a run of another shape than its template's"
        blank = f"_:r{number}x"
        parts = [self.chunks[0]]
        bucket = f"run-ids/{run.uuid[:RUN_ID_BUCKET]}>"
        for slot, chunk in zip(self.slots, self.chunks[1:], strict=True):
            parts.append(blank if slot == BLANK else bucket if slot == BUCKET else tokens[slot])
            parts.append(chunk)
        return "".join(parts)


def shape(run: Run) -> int:
    return len(run.hotspots)


def make_template(one: Run, other: Run, scenario: Scenario, keep: GraphFilter | None = None) -> Template:
    """The template of ``one``'s shape; ``other`` (the same shape, other values) tells which of
    its tokens vary."""
    tokens, others = run_tokens(one), run_tokens(other)
    assert len(tokens) == len(others) and shape(one) == shape(other)
    index: dict[str, int] = {}
    for i, (token, its_other) in enumerate(zip(tokens, others, strict=True)):
        if token == its_other:
            continue  # a constant (a robot's name, a pose): part of the text
        if token in index:  # the same value twice (an action's end, the next one's start): twice again
            if others[index[token]] != its_other:
                raise ValueError(f"{token} stands for two values in this run")
        else:
            index[token] = i
    keys = sorted(index, key=len, reverse=True)
    bucket = f"run-ids/{one.uuid[:RUN_ID_BUCKET]}>"  # a part of the uuid: a slot of its own
    pattern = re.compile("|".join([re.escape(bucket), *map(re.escape, keys), r"_:"]))
    text = real_nquads(one, scenario, keep)
    chunks, slots, at = [], [], 0
    for found in pattern.finditer(text):
        chunks.append(text[at : found.start()])
        kind = found.group()
        slots.append(BLANK if kind == "_:" else BUCKET if kind == bucket else index[kind])
        at = found.end()
    chunks.append(text[at:])
    return Template(len(tokens), tuple(chunks), tuple(slots))


SAMPLES = 8
"""Runs of each shape drawn to make and try its template."""


def make_templates(scenario: Scenario, keep: GraphFilter | None = None) -> dict[int, Template]:
    """A template per shape, from runs drawn with a seed of their own: the first pair whose
    template gives the real conversion of the shape's other samples (a run whose hotspots have
    the same count twice, or a count that is also a constant's text, cannot be a template)."""
    samples: dict[int, list[Run]] = {}
    for run in synthetic_runs(scenario, 10_000, seed=999):
        samples.setdefault(shape(run), []).append(run)
        if len(samples) == 4 and all(len(r) >= SAMPLES for r in samples.values()):
            break
    return {s: _first_good(runs, scenario, keep) for s, runs in samples.items()}


def _first_good(runs: list[Run], scenario: Scenario, keep: GraphFilter | None) -> Template:
    for i in range(len(runs) - 1):
        try:
            template = make_template(runs[i], runs[i + 1], scenario, keep)
        except ValueError:
            continue
        others = [(n, r) for n, r in enumerate(runs) if n not in (i, i + 1)]
        if all(_same(template, run, n, scenario, keep) for n, run in others):
            return template
    raise SystemExit(
        f"no template for runs with {shape(runs[0])} hotspots: the synthetic fill cannot be used"
    )


def _same(template: Template, run: Run, number: int, scenario: Scenario, keep: GraphFilter | None) -> bool:
    return _normalised(template.fill(run, number)) == _normalised(real_nquads(run, scenario, keep))


def _normalised(text: str) -> list[str]:
    return sorted(re.sub(r"_:\w+", "_:b", line) for line in text.splitlines())


def check_templates(
    templates: dict[int, Template], scenario: Scenario, runs: Iterable[tuple[int, Run]]
) -> int:
    """Assert that each run's templated N-Quads are the real conversion's (blank nodes aside); the
    number of runs checked."""
    checked = 0
    for number, run in runs:
        made, real = (
            _normalised(templates[shape(run)].fill(run, number)),
            _normalised(real_nquads(run, scenario)),
        )
        if made != real:
            wrong = sorted(set(made) ^ set(real))[:6]
            raise AssertionError(f"the synthetic fill differs from compile_run for run {number}: {wrong}")
        checked += 1
    return checked


# -- the fill -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Fill:
    runs: int
    quads: int
    seconds: float
    jobs: int
    full: int
    """Runs written whole; those after it only with the graphs :data:`keep` names."""


def _worker(worker: int, jobs: int, count: int, seed: int, folder: str, full: int, queue: object) -> None:
    scenario = synthetic_scenario()
    templates = make_templates(scenario)
    partial = make_templates(scenario, scenario_wide_graph) if full < count else templates
    runs = synthetic_runs(scenario, count, seed)
    for chunk in range((count + CHUNK - 1) // CHUNK):
        first = chunk * CHUNK
        batch = [next(runs) for _ in range(min(CHUNK, count - first))]
        if chunk % jobs != worker:
            continue
        path = Path(folder) / f"chunk-{chunk:05d}.nq"
        lines = 0
        with path.open("w", encoding="utf-8") as out:
            for number, run in enumerate(batch, start=first):
                text = (templates if number < full else partial)[shape(run)].fill(run, number)
                lines += text.count("\n")
                out.write(text)
        queue.put((str(path), lines))  # type: ignore[attr-defined]
    queue.put(None)  # type: ignore[attr-defined]


DROPPED = re.compile(
    r"/run_[0-9a-f-]+/(task_duration|distance_travelled|distance_to_obstacles|max_velocity|bag)_bundle$"
)
"""The graphs a partial run leaves out: the bag's bundle and the value bundles of the four metrics
measured per path segment (1,206 of a run's 1,900 quads).  No scenario-wide query of the library
reads them (the segment index holds their segment values); bench/store.py checks which answers a
store of partial runs changes, and says so beside their figures."""


def scenario_wide_graph(name: str) -> bool:
    """Whether a partial run keeps graph ``name``."""
    return not DROPPED.search(name)


def synthetic_fill(
    store: EmbeddedStore, count: int, seed: int = 1, jobs: int = 2, full: int | None = None
) -> Fill:
    """Write runs 0..count-1 of ``synthetic_runs(seed)`` into ``store``: templated N-Quads written by
    ``jobs`` worker processes, bulk-loaded by this one as they come.  Runs from ``full`` on hold
    only the graphs :func:`scenario_wide_graph` keeps."""
    full = count if full is None else min(full, count)
    context = multiprocessing.get_context("spawn")
    started = time.perf_counter()
    quads = 0
    with tempfile.TemporaryDirectory(prefix="exsce-fill-", dir=Path(store.location).parent) as folder:
        queue = context.Queue(maxsize=WAITING)
        workers = [
            context.Process(target=_worker, args=(w, jobs, count, seed, folder, full, queue))
            for w in range(jobs)
        ]
        for process in workers:
            process.start()
        finished = 0
        raw = store._writer()
        while finished < jobs:
            item = queue.get()
            if item is None:
                finished += 1
                continue
            path, lines = item
            raw.bulk_load(path=path, format=RdfFormat.N_QUADS)
            Path(path).unlink()
            quads += lines
        for process in workers:
            process.join()
            if process.exitcode != 0:
                raise SystemExit(f"a fill worker failed (exit {process.exitcode})")
    return Fill(count, quads, time.perf_counter() - started, jobs, full)


def first_runs(scenario: Scenario, count: int, seed: int = 1) -> list[tuple[int, Run]]:
    return list(enumerate(synthetic_runs(scenario, count, seed)))


__all__ = ["Fill", "check_templates", "first_runs", "make_templates", "synthetic_fill", "synthetic_run"]
