"""``exscec simulate --cluster`` and ``exscec explore --cluster``: runs played on a real Dask
cluster (a scheduler and two worker processes on 127.0.0.1, started here), whose workers write
the bags into the output folder.

What must hold: the cluster writes the files a local ``simulate`` of the same scenario, seed and
runs writes, byte for byte (same run ids, same bags); a run that fails on the cluster is named by
its index, the others written, and exscec exits 1 without a traceback; a worker killed in the
middle of a run loses no bag and leaves none half-written; and a campaign explored on the cluster
is the campaign explored here.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from distributed import Client, LocalCluster, get_task_stream

from exsce_dsl.api import commands
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns

from tests.support.cli import run_exscec
from tests.support.dask_cluster import a_worker_killed_while_running, local_cluster
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

RUNS = 4
SEED = 3
EXSCEC = str(Path(sys.executable).with_name("exscec"))


@pytest.fixture(scope="module")
def cluster() -> Iterator[LocalCluster]:
    with local_cluster() as started:
        yield started


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, str]]:
    """The project folder (spec.exsce and its map), and the files of a local ``simulate`` of it
    (relative path → sha256): the reference."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(YARD_SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    list(simulate(scenario, folder / "here", RUNS, seed=SEED))
    return folder, hashes(folder / "here")


def hashes(folder: Path) -> dict[str, str]:
    """Every file below ``folder``, hidden ones too: its path from ``folder`` → its sha256."""
    return {
        p.relative_to(folder).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def test_the_cluster_writes_the_bytes_a_local_simulate_writes(
    cluster: LocalCluster, yard: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    folder, reference = yard
    done = run_exscec(
        "simulate", "spec.exsce", "-n", str(RUNS), "--seed", str(SEED), "-o", "there",
        "--cluster", cluster.scheduler_address, cwd=folder,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert len(reference) == 2 * RUNS  # a bag and its .prov.json per run
    assert hashes(folder / "there") == reference  # same run ids (names), same bytes, nothing else
    for name in reference:
        if name.endswith(".bag"):
            assert f"wrote {Path('there') / name}" in done.stderr  # as given, not the worker's path
    # the library does the same, in another format: ROS 2 bags are folders
    spec = load_spec(folder / "spec.exsce")
    local = commands.simulate(spec, tmp_path / "here", 2, format="ros2", seed=SEED)
    remote = commands.simulate(
        spec, tmp_path / "there", 2, format="ros2", seed=SEED, dask_address=cluster.scheduler_address
    )
    assert [r.run_id for r in remote] == [r.run_id for r in local]
    assert [r.bag.relative_to(tmp_path / "there") for r in remote] == [
        r.bag.relative_to(tmp_path / "here") for r in local
    ]
    assert hashes(tmp_path / "there") == hashes(tmp_path / "here")


def test_a_run_that_fails_on_the_cluster_is_named_by_its_index(
    cluster: LocalCluster, yard: tuple[Path, dict[str, str]]
) -> None:
    folder, reference = yard
    out = folder / "blocked"
    records = sorted(name for name in reference if name.endswith(".prov.json"))  # in run order
    (out / records[1] / "in-the-way").mkdir(parents=True)  # a folder where run 1's record goes
    done = subprocess.run(
        [EXSCEC, "simulate", "spec.exsce", "-n", str(RUNS), "--seed", str(SEED), "-o", "blocked"],
        cwd=folder, capture_output=True, text=True, timeout=120,
        env={**os.environ, "EXSCE_DASK_SCHEDULER": cluster.scheduler_address},
    )  # fmt: skip
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"1 of {RUNS} runs of scenario 'yard_run' was not written on the cluster" in done.stderr
    assert f"run 1 (seed {SEED * 1000 + 1}): failed on the cluster" in done.stderr
    written = hashes(out)
    run_1 = records[1].removesuffix(".prov.json")
    assert run_1 + ".bag" not in written and not any(".partial" in name for name in written)
    assert written == {n: h for n, h in reference.items() if not n.startswith(run_1)}  # the others, whole
    shutil.rmtree(out)


def test_a_worker_killed_in_the_middle_of_a_run_loses_no_bag(
    cluster: LocalCluster, yard: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    folder, reference = yard
    scenario = load_spec(folder / "spec.exsce").scenario()
    with a_worker_killed_while_running(cluster, "_play_task") as killed:
        played = list(simulate(scenario, tmp_path / "runs", RUNS, seed=SEED, dask_address=cluster.scheduler_address))
    assert killed, "no worker was seen playing a run"
    assert [r.bag.name for r in played] == sorted(n for n in reference if n.endswith(".bag"))
    assert hashes(tmp_path / "runs") == reference  # each bag once and whole, nothing half-written left


def test_a_campaign_explored_on_the_cluster_is_the_campaign_explored_here(
    cluster: LocalCluster, yard: tuple[Path, dict[str, str]], tmp_path: Path
) -> None:
    folder, _ = yard
    arguments = [
        "explore", "spec.exsce", "-n", "2", "-k", "1", "--max-steps", "1", "-t", "remove_robot",
        "--fault", "overspeed-many-tasks:1", "-o", "campaign",
    ]  # fmt: skip
    outcomes = {}
    for where in ("here", "there"):
        project = tmp_path / where
        project.mkdir()
        for name in ("spec.exsce", "map.yaml", "map.pgm"):
            shutil.copy(folder / name, project / name)
        env = {k: v for k, v in os.environ.items() if not k.startswith("EXSCE_") or k == "EXSCE_CACHE"}
        on_cluster = ["--cluster", cluster.scheduler_address] if where == "there" else []
        with Client(cluster.scheduler_address, set_as_default=False) as watcher, get_task_stream(watcher) as ran:
            outcomes[where] = subprocess.run(
                [EXSCEC, *arguments, *on_cluster, "--store", str(project / "store")],
                cwd=project, capture_output=True, text=True, timeout=300, env=env,
            )  # fmt: skip
        keys = {str(task["key"]) for task in ran.data}  # the tasks the cluster ran meanwhile
        played, analysed = any("_play_task" in k for k in keys), any("_analyse" in k for k in keys)
        assert (played, analysed) == ((True, True) if on_cluster else (False, False)), where
    here, there = outcomes["here"], outcomes["there"]
    assert here.returncode == 1, here.stderr  # the planted fault is found ...
    assert there.returncode == 1 and "Traceback" not in there.stderr, there.stderr
    assert there.stdout == here.stdout  # ... the same relations, the same smallest derivations
    records = []
    for where in ("here", "there"):
        with open_store(str(tmp_path / where / "store")) as store:
            (plan,) = campaigns(store)
            records.append(campaign_record(store, plan.id))
    mine, theirs = records
    assert mine is not None and theirs is not None
    assert mine.trials and any(t.violated for t in mine.trials)
    assert theirs.plan.id == mine.plan.id  # the same campaign: where runs are played is not in its id
    assert theirs.trials == mine.trials  # derivations, runs (uuids of the bags' bytes), verdicts
    assert [(s.relation, s.minimal, s.minimal_steps) for s in theirs.shrinkings] == [
        (s.relation, s.minimal, s.minimal_steps) for s in mine.shrinkings
    ]
    assert hashes(tmp_path / "there" / "campaign" / "runs") == hashes(tmp_path / "here" / "campaign" / "runs")
