"""Benchmark: ingesting many runs in parallel, then querying the store that holds them.

Simulates N runs of scenario_c with the kinematic executor (about 31k messages
and 2.7 minutes of robot time each; written by two processes), then ingests all
of them into a fresh embedded store with 1, 2 and os.cpu_count() jobs (bag
reading and metrics in worker processes, one writer), printing bags/s and the
speed-up over 1 job measured in the same run.  Then it runs every query of the
library (`exscec query --list`) against the store holding the N runs, 20 times
each, and prints p50 and p95 per query.

With --cluster it compares instead `ingest --jobs 1`, `--jobs 2` and `ingest
--cluster` on a Dask LocalCluster it starts on 127.0.0.1 with 1, then 2 worker
processes (one thread each), on the same bags: bags/s and the speed-up over
1 job measured in the same run (the cluster's start is not timed; connecting
to it and its workers' first imports are, as a pool's are for --jobs).

    python bench/scale.py [--bags 200] [--keep DIR] [--cluster]   (a kept DIR's bags are reused)
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

SPEC = Path(__file__).resolve().parents[1] / "examples" / "brsu_building_c" / "scenario_c.exsce"


def _simulate(folder: Path, runs: int, seed: int) -> list[Path]:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.sim.run import simulate

    scenario = load_spec(SPEC).scenario("scenario_c")
    return [run.bag for run in simulate(scenario, folder, runs, seed=seed)]


def make_bags(folder: Path, count: int) -> list[Path]:
    """``count`` bags in ``folder``: those of an earlier run kept with --keep, or new ones."""
    kept = sorted(folder.glob("*/*.bag"))
    if len(kept) >= count:
        return kept[:count]
    shutil.rmtree(folder, ignore_errors=True)
    halves = [count // 2, count - count // 2]
    with ProcessPoolExecutor(max_workers=2) as pool:
        parts = pool.map(_simulate, [folder / "a", folder / "b"], halves, [1, 100_001])
        return sorted(p for part in parts for p in part)


def ingest(bags: list[Path], store_path: Path, jobs: int, dask_address: str | None = None) -> float:
    from exsce_dsl.lang import load_spec
    from exsce_dsl.runs.ingest import ingest_bags
    from exsce_dsl.store.embedded import EmbeddedStore

    scenario = load_spec(SPEC).scenario("scenario_c")
    shutil.rmtree(store_path, ignore_errors=True)
    started = time.perf_counter()
    with EmbeddedStore(store_path) as store:
        results = ingest_bags(bags, scenario, store, jobs, dask_address=dask_address)
    seconds = time.perf_counter() - started
    failed = [r.message for r in results if r.failed]
    if failed:
        sys.exit(f"ingest failed: {failed[:3]}")
    return seconds


def _parameters(store: object, runs: list[str]) -> dict[str, list[str]]:
    from exsce_dsl.store import queries

    segment = queries.path_segments(store, "scenario_c")[0]  # type: ignore[arg-type]
    return {
        "scenario": ["scenario_c"],
        "base": ["scenario_c"],
        "robot": ["tiago1"],
        "run": runs,
        "start": [segment.start],
        "goal": [segment.goal],
        "pose": [segment.start, segment.goal],
        "point": [segment.start.rsplit("-R", 1)[0]],
        "a": [segment.start],
        "b": [segment.goal],
        "distance": ["1.0"],
        "radius": ["1.0"],
        "tolerance": ["1.0"],
    }


def _metric_for(name: str) -> str:
    if name.startswith(("hotspot", "violation")):
        return "max_velocity"
    if "mission" in name:
        return "mission_duration"
    return "distance_travelled"


def query_latencies(store_path: Path, repeats: int = 20) -> list[tuple[str, float, float, int]]:
    from exsce_dsl.store.embedded import EmbeddedStore
    from exsce_dsl.store.queries import query, query_names, run_query, runs

    found = []
    with EmbeddedStore(store_path) as store:
        uuids = [r.uuid for r in runs(store, "scenario_c")]
        values = _parameters(store, uuids)
        for name in query_names():
            q = query(name)
            if q.is_update:
                continue
            given: dict[str, str | list[str]] = {}
            for p in q.parameters:
                if p.kind in ("metric", "metric_property"):
                    given[p.name] = _metric_for(name)
                elif p.name in values:
                    chosen = values[p.name]
                    given[p.name] = chosen if p.many else chosen[0]
                elif p.kind == "double":
                    given[p.name] = "1.0"
                elif not p.optional:
                    given[p.name] = "scenario_c"
            times, rows = [], 0
            for _ in range(repeats):
                started = time.perf_counter()
                rows = len(run_query(store, name, given))
                times.append(time.perf_counter() - started)
            times.sort()
            found.append((name, statistics.median(times), times[int(0.95 * (len(times) - 1))], rows))
    return found


def compare_with_cluster(bags: list[Path], folder: Path, size: float) -> None:
    """--jobs 1 and 2 against a local Dask cluster of 1 and 2 worker processes, on ``bags``."""
    from distributed import LocalCluster

    seconds: dict[str, float] = {}

    def show(label: str) -> None:
        took = seconds[label]
        print(
            f"{label:22} {took:6.1f} s  {len(bags) / took:5.2f} bags/s  {size / took:5.1f} MB/s  "
            f"speed-up {seconds['ingest --jobs 1'] / took:.2f}×"
        )

    for jobs in (1, 2):
        label = f"ingest --jobs {jobs}"
        seconds[label] = ingest(bags, folder / f"store-jobs-{jobs}", jobs)
        show(label)
    for workers in (1, 2):
        with LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
        ) as cluster:
            label = f"cluster, {workers} worker{'s' if workers > 1 else ''}"
            seconds[label] = ingest(bags, folder / f"store-cluster-{workers}", 1, cluster.scheduler_address)
        show(label)


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--bags", type=int, default=200)
    parser.add_argument("--keep", type=Path, help="Keep the bags and stores in this folder.")
    parser.add_argument(
        "--cluster", action="store_true", help="Compare --jobs 1/2 with a local Dask cluster of 1, 2 workers."
    )
    args = parser.parse_args()
    folder = args.keep or Path(tempfile.mkdtemp(prefix="exsce-scale-"))
    folder.mkdir(parents=True, exist_ok=True)
    try:
        started = time.perf_counter()
        bags = make_bags(folder / "bags", args.bags)
        size = sum(b.stat().st_size for b in bags) / 2**20
        took = time.perf_counter() - started
        cpus = os.cpu_count()
        print(f"{len(bags)} bags of scenario_c, {size:.0f} MB, simulated in {took:.0f} s ({cpus} CPUs)")
        if args.cluster:
            compare_with_cluster(bags, folder, size)
            return
        jobs_list = sorted({1, 2, os.cpu_count() or 1})
        seconds = {}
        for jobs in jobs_list:
            seconds[jobs] = ingest(bags, folder / f"store-{jobs}", jobs)
            print(
                f"ingest with {jobs} job{'s' if jobs > 1 else ''}: {seconds[jobs]:6.1f} s  "
                f"{len(bags) / seconds[jobs]:5.2f} bags/s  {size / seconds[jobs]:5.1f} MB/s  "
                f"speed-up {seconds[1] / seconds[jobs]:.2f}×"
            )
        largest = folder / f"store-{jobs_list[-1]}"
        print(f"\nthe query library against the store of {len(bags)} runs (20 runs each):")
        print(f"{'query':32} {'p50 ms':>8} {'p95 ms':>8} {'rows':>7}")
        for name, p50, p95, rows in query_latencies(largest):
            print(f"{name:32} {p50 * 1000:8.1f} {p95 * 1000:8.1f} {rows:7d}")
    finally:
        if args.keep is None:
            shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
