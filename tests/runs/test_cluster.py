"""``exscec ingest --cluster``: bags analysed on a real Dask cluster (a scheduler and two
worker processes on 127.0.0.1, started here), runs written by the client.

What must hold: the store holds the same quads as after ``--jobs 1``; a bag that cannot be used
is reported by name; a worker killed in the middle of a bag loses no run; and a client killed
in the middle of a batch leaves every run wholly stored or not at all, and the same command
then finishes the batch; and bags named relative to the caller's folder are found, though the
workers' working folder is another.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import Client, LocalCluster
from pyoxigraph import CanonicalizationAlgorithm, Dataset

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.ingest import IngestStatus, ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore

from tests.support.cli import exscec_here, run_exscec
from tests.support.dask_cluster import a_worker_killed_while_running, local_cluster
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

BAGS = 6


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    with local_cluster() as started:
        yield started


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path], Path]:
    """The project folder, its bags, and a store of them ingested with --jobs 1 (the reference)."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    bags = [run.bag for run in simulate(scenario, folder / "runs", BAGS, seed=3)]
    done = run_exscec(
        "ingest", *map(str, bags), "--scenario", "spec.exsce", "--jobs", "1", "--store", "reference", cwd=folder
    )
    assert done.returncode == 0, done.stderr
    return folder, bags, folder / "reference"


def canonical(folder: Path) -> Dataset:
    with EmbeddedStore(folder) as store:
        dataset = Dataset(store.quads())
    dataset.canonicalize(CanonicalizationAlgorithm.UNSTABLE)
    return dataset


def test_the_cluster_stores_what_one_job_stores_and_names_a_bad_bag(
    cluster: LocalCluster, yard: tuple[Path, list[Path], Path]
) -> None:
    folder, bags, reference = yard
    broken = folder / "broken.bag"
    broken.write_bytes(bags[0].read_bytes()[:5000])  # a truncated copy
    done = run_exscec(
        "ingest", *map(str, bags), str(broken), "--scenario", "spec.exsce",
        "--cluster", cluster.scheduler_address, "--store", "on-cluster", cwd=folder,
    )  # fmt: skip
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"error: {broken}" in done.stderr  # reported by name
    assert f"{BAGS} ingested, 0 skipped, 1 failed" in done.stderr
    assert canonical(folder / "on-cluster") == canonical(reference)  # nothing of the broken bag
    # the environment variable does as --cluster; a second time, every bag is known
    again = subprocess.run(
        [str(Path(sys.executable).with_name("exscec")), "ingest", *map(str, bags),
         "--scenario", "spec.exsce", "--store", "on-cluster"],
        cwd=folder, capture_output=True, text=True, timeout=120,
        env={**os.environ, "EXSCE_DASK_SCHEDULER": cluster.scheduler_address},
    )  # fmt: skip
    assert again.returncode == 0 and f"0 ingested, {BAGS} skipped, 0 failed" in again.stderr


def test_ingest_on_a_cluster_takes_paths_relative_to_the_callers_folder(
    cluster: LocalCluster, yard: tuple[Path, list[Path], Path]
) -> None:
    """``exscec ingest ../runs/*.bag --cluster`` failed with 'no such bag' for every bag: the
    workers opened the relative paths in their own working folder."""
    folder, bags, reference = yard
    caller = folder / "caller"
    caller.mkdir()
    relative = [os.path.relpath(bag, caller) for bag in bags]
    assert all(name.startswith("../runs/") for name in relative)
    with Client(cluster.scheduler_address, set_as_default=False) as watcher:
        worker_folders = set(watcher.run(os.getcwd).values())
    assert str(caller) not in worker_folders
    assert not any((Path(where) / name).exists() for where in worker_folders for name in relative)
    done = run_exscec(
        "ingest", *relative, "--scenario", "../spec.exsce",
        "--cluster", cluster.scheduler_address, "--store", "store", cwd=caller,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert f"{BAGS} ingested, 0 skipped, 0 failed" in done.stderr
    assert "no such bag" not in done.stderr and relative[0] in done.stderr  # named as given
    assert canonical(caller / "store") == canonical(reference)
    # the values, by hand: r1 drives field-a (1,1) -> field-b (1,8) -> field-e (4.5,4.5) in the
    # open yard, r2 field-d (8,1) -> field-c (8,8); each reaches all its waypoints
    runs = [a for run in _run_ids(done.stderr) for a in ("-p", f"run={run}")]
    assert len(runs) == 2 * BAGS
    values = exscec_here("query", "run_metric_values", *runs, "-f", "json", "--store", "store", cwd=caller)
    assert values.returncode == 0, values.stderr
    found: dict[tuple[str, str], list[float]] = {}
    for row in json.loads(values.stdout)["results"]["bindings"]:
        if "robot" in row and row["metric"]["value"] in ("distance_travelled", "waypoints_visited"):
            key = (row["robot"]["value"], row["metric"]["value"])
            found.setdefault(key, []).append(float(row["value"]["value"]))
    assert found[("r1", "distance_travelled")] == pytest.approx([7 + 3.5 * math.sqrt(2)] * BAGS, rel=1e-6)
    assert found[("r2", "distance_travelled")] == pytest.approx([7.0] * BAGS, rel=1e-6)
    assert found[("r1", "waypoints_visited")] == [2.0] * BAGS
    assert found[("r2", "waypoints_visited")] == [1.0] * BAGS


def _run_ids(said: str) -> list[str]:
    return re.findall(r": run ([0-9a-f-]{36}) ", said)


def test_a_worker_killed_in_the_middle_of_a_bag_loses_no_run(
    cluster: LocalCluster, yard: tuple[Path, list[Path], Path], tmp_path: Path
) -> None:
    folder, bags, reference = yard
    scenario = load_spec(folder / "spec.exsce").scenario()
    with a_worker_killed_while_running(cluster, "_analyse") as killed:
        with EmbeddedStore(tmp_path / "store") as store:
            results = ingest_bags(bags, scenario, store, dask_address=cluster.scheduler_address)
    assert killed, "no worker was seen analysing a bag"
    assert [r.status for r in results] == [IngestStatus.INGESTED] * BAGS, [r.message for r in results]
    assert canonical(tmp_path / "store") == canonical(reference)


def test_a_client_killed_in_the_middle_of_a_batch_stores_whole_runs(
    cluster: LocalCluster, yard: tuple[Path, list[Path], Path], tmp_path: Path
) -> None:
    folder, bags, reference = yard
    store = tmp_path / "store"
    command = [
        str(Path(sys.executable).with_name("exscec")), "ingest", *map(str, bags), "--scenario", "spec.exsce",
        "--cluster", cluster.scheduler_address, "--store", str(store),
    ]  # fmt: skip
    client = subprocess.Popen(command, cwd=folder, stderr=subprocess.PIPE, text=True)
    assert client.stderr is not None
    for line in client.stderr:  # killed as soon as it says it wrote a run: the next one is on its way
        if "run " in line and "metric values" in line:
            client.send_signal(signal.SIGKILL)
            break
    client.wait(timeout=60)
    with EmbeddedStore(store) as partial, EmbeddedStore(reference) as whole:
        stored = partial.graph_names()
        assert stored and stored <= whole.graph_names()
        assert len(stored) < len(whole.graph_names())  # killed before the end
        for name in stored:  # each graph written is the whole graph
            assert canonical_graph(partial.graph(name)) == canonical_graph(whole.graph(name)), name
        runs = {name.split("/run_")[1][:36] for name in stored if "/run_" in name}
        assert runs, "no run was stored before the kill"
        for run in runs:  # and each run stored has every graph of its
            assert {n for n in stored if run in n} == {n for n in whole.graph_names() if run in n}, run
    finished = subprocess.run(command, cwd=folder, capture_output=True, text=True, timeout=180)
    assert finished.returncode == 0, finished.stderr
    assert canonical(store) == canonical(reference)
    shutil.rmtree(store)


def canonical_graph(quads: list[object]) -> Dataset:
    dataset = Dataset(quads)  # type: ignore[arg-type]
    dataset.canonicalize(CanonicalizationAlgorithm.UNSTABLE)
    return dataset
