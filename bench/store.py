"""Benchmark: the store at 10³, 10⁴ and 10⁵ runs against issue 52's targets, and against rdflib.

Builds N synthetic runs shaped like the method's (two robots, ten path segments
each, every metric per segment, per robot and for the mission, the bag's
topics, a few hotspots) and fills an embedded on-disk store with them, one of two ways:

* **end to end** (up to 10,000 runs, or ``--fill end-to-end``): as PROV documents through
  ``compile_run``, written through the batch write path
  (``exsce_dsl.store.batch_writing.RunWriter``: PROV → quads and the segment index → group
  commits through Oxigraph's bulk loader, each run wholly or not at all); for N ≤ 1,000 the same
  graphs into an rdflib in-memory ``Dataset`` too.  Its write rate is end to end, from the runs.
* **synthetic** (above 10,000 runs, or ``--fill synthetic``; said in the output): the same runs of
  the same seed as the same quads, from a template per run shape of ``compile_run``'s conversion
  (bench/store_fill.py), written as N-Quads by worker processes and bulk-loaded: about 1 ms a run
  instead of 27.  Before it fills, the bench writes its first 60 runs both ways and asserts that
  the graphs and every library query's answer are the same.  A whole run is ~0.5 MB on disk, so
  10⁵ of them do not fit on this machine: runs past ``--full-runs`` (10,000) hold only the graphs
  the scenario-wide queries read (no bag bundle, no value bundles of the segment metrics), said
  in the output, and the queries whose answers that changes are marked in the table.

Then it prints the store's bytes on disk per run (after ``flush``, and after ``optimize``:
RocksDB compacted), times the segment query (mean and standard deviation of distance_travelled on
one segment over every run of the scenario) on Oxigraph and rdflib, and on Oxigraph the same over a
list of 20 runs, and every library query the report and the oracles use (p50, p95) beside its
target (bench/store_targets.py): over the scenario's runs < 50 ms up to 10⁴ runs and < 250 ms up
to 10⁵, over a list of runs < 20 ms, ``run_ids`` < 5 ms.  Last, at each size, 100 more runs are
written three ways from PROV documents compiled beforehand (their conversion to RDF included):
one ``add_prov`` per run, the batch path, and pyoxigraph's own transactional insert of the same
quads (``Store.extend``, a run per transaction): the target is the batch path ≥ 1.5× that.

    python bench/store.py                 # N = 100, 1,000 and 10,000 (~30 min, ~10 GB of disk)
    python bench/store.py --sizes 1000,10000,100000 --folder /big/disk   # the issue's table:
                                          # 10⁵ filled synthetically, ~25 GB of disk
    python bench/store.py --sizes 20000 --fill synthetic --full-runs 10000   # the 10⁵ path, smaller

The default stays at 10⁴: a run of it ends in half an hour on two cores and fits any disk; 10⁵
takes over an hour and most of this machine's free disk, so it is asked for by name.

Prints figures; never a unit test.
"""

from __future__ import annotations

import argparse
import gc
import resource
import sys
import tempfile
import time
from pathlib import Path

from prov.model import ProvDocument
from pyoxigraph import BlankNode, NamedNode
from pyoxigraph import Literal as OxLiteral
from pyoxigraph import Store as OxStore
from rdflib import BNode, Dataset, Graph, URIRef
from rdflib import Literal as RdfLiteral
from rdflib.term import Node
from store_fill import Fill, synthetic_fill
from store_library import answers, percentile, time_library, timed
from store_synthetic import ROBOTS, synthetic_runs, synthetic_scenario
from store_targets import HEADER, WRITE_TARGET, folder_bytes, summary

from exsce_dsl.model import Scenario
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.identifiers import pose_name
from exsce_dsl.prov.run import compile_run
from exsce_dsl.store.batch_writing import RunWriter, Written
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import query as library_query
from exsce_dsl.store.queries import runs as list_runs
from exsce_dsl.store.queries import segment_metric
from exsce_dsl.store.sparql import bind
from exsce_dsl.store.writing import add_prov, stored_graphs

BATCH = 100
XSD_STRING = "http://www.w3.org/2001/XMLSchema#string"
"""Runs compiled and written before the next ones are made (memory stays flat)."""


# -- measuring ---------------------------------------------------------------------


def peak_memory_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def rdflib_quads(document: ProvDocument) -> list[tuple[Node, Node, Node, URIRef]]:
    """The quads ``add_prov`` writes of the document, as rdflib terms."""
    fresh: dict[str, BNode] = {}

    def term(t: object) -> Node:
        if isinstance(t, NamedNode):
            return URIRef(t.value)
        if isinstance(t, BlankNode):
            return fresh.setdefault(t.value, BNode())
        assert isinstance(t, OxLiteral)
        if t.language:
            return RdfLiteral(t.value, lang=t.language)
        if t.datatype.value == XSD_STRING:
            return RdfLiteral(t.value)  # as rdflib reads "..." in a query
        return RdfLiteral(t.value, datatype=URIRef(t.datatype.value))

    found: list[tuple[Node, Node, Node, URIRef]] = []
    for name, quads in stored_graphs(document).items():
        graph = URIRef(name)
        found.extend((term(q.subject), term(q.predicate), term(q.object), graph) for q in quads)
    return found


class Figures:
    def __init__(self) -> None:
        self.triples = 0
        self.compile = 0.0
        self.write = 0.0
        self.rdflib = 0.0


def write_runs(store: EmbeddedStore, dataset: Dataset | None, scenario: Scenario, size: int) -> Figures:
    """Compile and write ``size`` runs through the batch path (``RunWriter``: group commits through
    Oxigraph's bulk loader), ``BATCH`` at a time in memory; the rdflib dataset gets the same
    documents, timed apart."""
    figures = Figures()
    runs = synthetic_runs(scenario, size)
    with RunWriter(store, lambda done: _count(figures, done)) as writer:
        while batch := [run for _, run in zip(range(BATCH), runs, strict=False)]:
            t0 = time.perf_counter()
            documents = []
            for run in batch:
                t1 = time.perf_counter()
                document = compile_run(run, scenario)
                figures.compile += time.perf_counter() - t1
                writer.add(document)
                documents.append(document)
            writer.flush()
            figures.write += time.perf_counter() - t0
            if dataset is not None:
                t2 = time.perf_counter()
                for document in documents:
                    add_to_rdflib(dataset, document)
                figures.rdflib += time.perf_counter() - t2
            del batch, documents
            gc.collect()
            gc.freeze()  # what is left is the rdflib dataset: spare the collector walking it again and again
    return figures


def _count(figures: Figures, done: Written) -> None:
    if done.report is None:
        raise SystemExit(f"a write failed: {done.error}")
    figures.triples += done.report.statements


def add_to_rdflib(dataset: Dataset, document: ProvDocument) -> None:
    graphs: dict[URIRef, Graph] = {}
    quads = []
    for s, p, o, name in rdflib_quads(document):
        graph = graphs.get(name)
        if graph is None:
            graph = graphs[name] = dataset.graph(name)
        quads.append((s, p, o, graph))
    dataset.addN(quads)


def raw_oxigraph_insert(scenario: Scenario, folder: Path) -> float:
    """Quads/s of pyoxigraph's own transactional insert (``Store.extend``) into a folder, one
    run at a time: the floor under any atomic write path."""
    quads = [
        [q for graph in stored_graphs(compile_run(run, scenario)).values() for q in graph]
        for run in synthetic_runs(scenario, BATCH, seed=7)
    ]
    raw = OxStore(str(folder))
    t0 = time.perf_counter()
    for run_quads in quads:
        raw.extend(run_quads)
    raw.flush()
    return sum(map(len, quads)) / (time.perf_counter() - t0)


def write_rates_at_size(store: EmbeddedStore, scenario: Scenario, number: int) -> tuple[float, float, float]:
    """Triples/s of ``add_prov``, of the batch path (``RunWriter``) and of pyoxigraph's own
    ``Store.extend`` (a run per transaction), for ``BATCH`` more runs each (PROV documents
    compiled beforehand), into ``store`` as it is: the writes compared with their floor at the
    same size (a store of 10,000 runs takes any insert slower than an empty one)."""
    mine = [compile_run(run, scenario) for run in synthetic_runs(scenario, BATCH, seed=1000 + number)]
    grouped = [compile_run(run, scenario) for run in synthetic_runs(scenario, BATCH, seed=3000 + number)]
    raw_runs = [
        [q for graph in stored_graphs(compile_run(run, scenario)).values() for q in graph]
        for run in synthetic_runs(scenario, BATCH, seed=2000 + number)
    ]
    counted = Figures()
    t0 = time.perf_counter()
    with RunWriter(store, lambda done: _count(counted, done)) as writer:
        for document in grouped:
            writer.add(document)
    batch = counted.triples / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    triples = sum(add_prov(store, document).statements for document in mine)
    ours = triples / (time.perf_counter() - t0)
    raw = store._writer()  # the same RocksDB store, opened once
    t0 = time.perf_counter()
    for run_quads in raw_runs:
        raw.extend(run_quads)
    theirs = sum(map(len, raw_runs)) / (time.perf_counter() - t0)
    return ours, batch, theirs


SANITY_RUNS = 60
"""Runs written both ways (end to end, synthetic fill) and compared before a synthetic fill."""


def check_synthetic_fill(scenario: Scenario, folder: Path, full_share: bool) -> frozenset[str]:
    """Assert that the synthetic fill writes what the end-to-end path writes: the first
    :data:`SANITY_RUNS` runs of the seed, each way, give the same graphs (sizes) and the same
    answer to every library query (``runs``, ``run_metric_values``, ``run_segment_values``... among
    them).  With ``full_share`` (the fill writes some runs partly), the queries whose answers a
    store of partial runs changes: their figures at that size read fewer runs' values."""
    stores = {}
    for way in ("end to end", "synthetic", "partial"):
        if way == "partial" and not full_share:
            continue
        store = stores[way] = EmbeddedStore(folder / way.replace(" ", "-"))
        add_prov(store, compile_scenario(scenario))
        if way == "end to end":
            write_runs(store, None, scenario, SANITY_RUNS)
        else:
            synthetic_fill(store, SANITY_RUNS, full=SANITY_RUNS // 2 if way == "partial" else None)
    reference = stores["end to end"]
    some_runs = [run.uuid for run in list_runs(reference, scenario.id)[:20]]
    expected = answers(reference, scenario, some_runs)
    assert stores["synthetic"].graph_sizes() == reference.graph_sizes(), "the synthetic fill's graphs differ"
    made = answers(stores["synthetic"], scenario, some_runs)
    wrong = [name for name in expected if made[name] != expected[name]]
    assert not wrong, f"the synthetic fill answers differently: {wrong}"
    changed: frozenset[str] = frozenset()
    if full_share:
        partial = answers(stores["partial"], scenario, some_runs)
        changed = frozenset(name for name in expected if partial[name] != expected[name])
    for store in stores.values():
        store.close()
    return changed


def fill(
    store: EmbeddedStore, dataset: Dataset | None, scenario: Scenario, size: int, synthetic: bool, full: int
) -> Figures | Fill:
    """The store of ``size`` runs: end to end (``compile_run`` → ``RunWriter``), or synthetic."""
    if synthetic:
        return synthetic_fill(store, size, full=full)
    return write_runs(store, dataset, scenario, size)


def print_fill(done: Figures | Fill, size: int) -> None:
    if isinstance(done, Fill):
        partly = (
            f"; runs {done.full:,} to {size - 1:,} hold only the graphs store_fill.scenario_wide_graph keeps "
            "(no value bundles of the segment metrics, no bag bundle)"
            if done.full < size
            else ""
        )
        print(f"N = {size:,} runs, {done.quads:,} triples ({done.quads / size:,.0f} a run)")
        print(
            f"  fill: SYNTHETIC (bench/store_fill.py: each run's N-Quads from a template of compile_run's "
            f"conversion of one run of its shape, written by {done.jobs} worker processes, through "
            f"Oxigraph's bulk loader): {done.seconds:,.1f} s = {size / done.seconds:,.0f} runs/s, "
            f"{done.quads / done.seconds:,.0f} triples/s{partly}"
        )
        return
    rate = done.triples / done.write
    print(f"N = {size:,} runs, {done.triples:,} triples ({done.triples / size:,.0f} a run)")
    print(
        f"  fill, end to end: embedded Oxigraph on disk, batch path (RunWriter: Run → PROV → RDF + "
        f"segment index → group commits through the bulk loader): {done.write:,.1f} s = "
        f"{rate:,.0f} triples/s (compile_run's share: {done.compile:,.1f} s)"
    )
    if done.rdflib:
        print(
            f"  write, rdflib Dataset in memory (the same quads): {done.rdflib:,.1f} s = "
            f"{done.triples / done.rdflib:,.0f} triples/s"
        )


def print_disk(store: EmbeddedStore, folder: Path, size: int) -> None:
    """Bytes on disk per run: after ``flush`` (as a writer leaves the store), then after
    ``optimize`` (RocksDB's compaction, as the store settles)."""
    raw = store._writer()
    raw.flush()
    flushed = folder_bytes(folder)
    t0 = time.perf_counter()
    raw.optimize()
    optimized = folder_bytes(folder)
    print(
        f"  on disk: {flushed / 1e9:,.2f} GB = {flushed / size / 1e3:,.0f} kB a run after flush; "
        f"{optimized / 1e9:,.2f} GB = {optimized / size / 1e3:,.0f} kB a run after optimize "
        f"({time.perf_counter() - t0:,.0f} s)"
    )


def options_parsed() -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--sizes", default="100,1000,10000", help="numbers of runs, comma separated")
    parser.add_argument("--repeat", type=int, default=50, help="timed queries per store")
    parser.add_argument("--rdflib-max", type=int, default=1000, help="largest N also written to rdflib")
    parser.add_argument(
        "--rdflib-query-max",
        type=int,
        default=1000,
        help="largest N also queried on rdflib (it evaluates GRAPH ?g by visiting every named graph: "
        "seconds at N = 100, minutes at N = 1,000)",
    )
    parser.add_argument("--rdflib-repeat", type=int, default=3, help="timed rdflib queries (no warm-up)")
    parser.add_argument("--library-repeat", type=int, default=10, help="timed calls of each library query")
    parser.add_argument(
        "--query-budget",
        type=float,
        default=20.0,
        help="seconds of timed calls per library query at most (a slow one gets fewer calls, at least one)",
    )
    parser.add_argument(
        "--fill",
        choices=("auto", "end-to-end", "synthetic"),
        default="auto",
        help="how the store is filled: end to end (compile_run → RunWriter) or synthetic "
        "(bench/store_fill.py); auto: end to end up to 10,000 runs, synthetic above",
    )
    parser.add_argument(
        "--full-runs",
        type=int,
        default=10_000,
        help="a synthetic fill writes this many runs whole, the others with only the graphs the "
        "scenario-wide queries read (10⁵ whole runs take ~50 GB; this machine has ~30)",
    )
    parser.add_argument("--folder", help="where the stores are made (default: the system's temporary folder)")
    return parser.parse_args()


def main() -> None:
    options = options_parsed()
    sizes = [int(s) for s in options.sizes.split(",") if s]

    scenario = synthetic_scenario()
    start_pose = scenario.robots[0].start_pose
    first_task = scenario.task(scenario.mission.tasks_of(ROBOTS[0])[0])
    assert start_pose is not None and first_task is not None
    goal_pose = next(first_task.waypoints())
    query = library_query("segment_metric_of_scenario")
    given = {
        "metric": ["distance_travelled"],
        "start": [pose_name(start_pose)],
        "goal": [pose_name(goal_pose)],
        "scenario": [scenario.id],
    }
    bindings = query.bindings(given)
    rdflib_text = bind(query.sparql(), bindings)
    segment = f"{pose_name(start_pose)} -> {pose_name(goal_pose)}"
    print(f"segment {segment} (robot {ROBOTS[0]}), distance_travelled,")
    print(f"over every run of the scenario; python {sys.version.split()[0]}, batches of {BATCH} runs")
    print(
        "targets (p50): over the scenario's runs < 50 ms up to 10,000 runs, < 250 ms above; over a list "
        f"of runs < 20 ms; run_ids < 5 ms; writes ≥ {WRITE_TARGET}× Store.extend"
    )
    with tempfile.TemporaryDirectory(prefix="exsce-bench-", dir=options.folder) as folder:
        raw = raw_oxigraph_insert(scenario, Path(folder) / "raw")
    print(f"pyoxigraph's own on-disk insert (Store.extend, a run per transaction): {raw:,.0f} quads/s\n")

    for size in sizes:
        synthetic = options.fill == "synthetic" or (options.fill == "auto" and size > 10_000)
        with tempfile.TemporaryDirectory(prefix="exsce-bench-", dir=options.folder) as folder:
            partial: frozenset[str] = frozenset()
            if synthetic:
                t0 = time.perf_counter()
                partial = check_synthetic_fill(scenario, Path(folder) / "check", options.full_runs < size)
                print(
                    f"synthetic fill checked ({time.perf_counter() - t0:,.0f} s): "
                    f"its first {SANITY_RUNS} runs "
                    "give the graphs and every library query's answer that the end-to-end path gives"
                    + (
                        f"; partial runs change the answers of: {', '.join(sorted(partial))}"
                        if partial
                        else ""
                    )
                )
            store = EmbeddedStore(Path(folder) / "store")
            add_prov(store, compile_scenario(scenario))
            dataset = Dataset() if size <= options.rdflib_max and not synthetic else None
            if dataset is not None:
                add_to_rdflib(dataset, compile_scenario(scenario))
            done = fill(store, dataset, scenario, size, synthetic, options.full_runs)
            print_fill(done, size)
            print_disk(store, Path(folder) / "store", size)
            whole = min(size, options.full_runs) if synthetic else size
            query_figures(store, dataset, scenario, size, options, partial, rdflib_text, whole)
            ours, batch, theirs = write_rates_at_size(store, scenario, size)
            met = "met" if batch / theirs >= WRITE_TARGET else "NOT met"
            print(
                f"  write at this size, {BATCH} runs more each, from PROV documents: add_prov "
                f"{ours:,.0f} triples/s = {ours / theirs:.2f} × pyoxigraph's Store.extend "
                f"({theirs:,.0f} quads/s); batch path {batch:,.0f} triples/s = {batch / theirs:.2f} × "
                f"(target ≥ {WRITE_TARGET}×: {met})"
            )
            print(f"  peak memory so far: {peak_memory_mb():,.0f} MB\n", flush=True)
            store.close()
            del dataset
            gc.unfreeze()
            gc.collect()


def query_figures(
    store: EmbeddedStore,
    dataset: Dataset | None,
    scenario: Scenario,
    size: int,
    options: argparse.Namespace,
    partial: frozenset[str],
    rdflib_text: str,
    whole: int,
) -> None:
    """The segment query on Oxigraph (and rdflib), then every library query against its target."""
    start_pose = scenario.robots[0].start_pose
    first_task = scenario.task(scenario.mission.tasks_of(ROBOTS[0])[0])
    assert start_pose is not None and first_task is not None
    goal_pose = next(first_task.waypoints())

    def on_oxigraph() -> object:
        assert start_pose is not None
        return segment_metric(store, "distance_travelled", start_pose, goal_pose, scenario=scenario.id)

    answer = on_oxigraph()
    samples = timed(on_oxigraph, options.repeat)
    p50, p95 = percentile(samples, 0.5), percentile(samples, 0.95)
    print(f"  segment query, Oxigraph: p50 {p50 * 1e3:,.2f} ms, p95 {p95 * 1e3:,.2f} ms   {answer}")
    # the list queries read whole runs (those a synthetic fill writes first)
    some_runs = [run.uuid for run in list_runs(store, scenario.id)[:whole][:: max(1, whole // 20)][:20]]

    def on_some_runs() -> object:
        assert start_pose is not None
        return segment_metric(store, "distance_travelled", start_pose, goal_pose, runs=some_runs)

    listed = on_some_runs()
    samples = timed(on_some_runs, options.repeat)
    l50, l95 = percentile(samples, 0.5), percentile(samples, 0.95)
    print(
        f"  the same over a list of {len(some_runs)} runs, Oxigraph: "
        f"p50 {l50 * 1e3:,.2f} ms, p95 {l95 * 1e3:,.2f} ms   {listed}"
    )
    print(f"  every library query (Oxigraph; 'the scenario': over its {size:,} runs; n: timed calls):")
    print(HEADER)
    figures = time_library(store, scenario, some_runs, options.library_repeat, options.query_budget, partial)
    for figure in figures:
        print(figure.line())
    print(summary(figures), flush=True)
    if dataset is not None and size > options.rdflib_query_max:
        print(f"  segment query, rdflib:   not run above N = {options.rdflib_query_max} (--rdflib-query-max)")
    elif dataset is not None:
        found: list[object] = []

        def on_rdflib() -> object:
            found[:] = list(dataset.query(rdflib_text))
            return found

        rdf_samples = timed(on_rdflib, max(1, options.rdflib_repeat), warm_up=False)
        r50, r95 = percentile(rdf_samples, 0.5), percentile(rdf_samples, 0.95)
        shown = [tuple(str(v) for v in row) for row in found]  # type: ignore[attr-defined]
        print(f"  segment query, rdflib:   p50 {r50 * 1e3:,.2f} ms, p95 {r95 * 1e3:,.2f} ms   {shown}")
        print(f"  Oxigraph / rdflib: {r50 / p50:,.0f}× faster at p50")


if __name__ == "__main__":
    main()
