"""Faults: an ingest killed at random points, readers during an ingest, a remote store going away.

In each case the store holds every run wholly or not at all: its graphs are
compared, graph by graph and quad count by quad count, with the states of a
store into which the same bags were ingested undisturbed, one after another
(runs share the graphs of the store's indexes, so a run is not a set of graphs
of its own).
"""

from __future__ import annotations

import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

from tests.support.paths import EXAMPLES
from tests.support.store_servers import oxigraph_server

EXSCEC = str(Path(sys.executable).with_name("exscec"))
SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
Sizes = dict[str, int]


def _sizes(path: Path) -> Sizes:
    with EmbeddedStore(path) as store:
        return store.graph_sizes()


def _ingest(bags: list[Path], store: str) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [EXSCEC, "ingest", *map(str, bags), "--scenario", str(SPEC), "--store", store],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.fixture(scope="module")
def setting(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    """Three bags; a store with the scenario only; the graph sizes after each bag, ingested in order."""
    folder = tmp_path_factory.mktemp("faults")
    scenario = load_spec(SPEC).scenario("scenario_c")
    bags = [run.bag for run in simulate(scenario, folder / "runs", 3, seed=4)]
    empty = folder / "scenario-only"
    with EmbeddedStore(empty) as store:
        add_prov(store, compile_scenario(scenario))
    states = [_sizes(empty)]
    reference = folder / "reference"
    shutil.copytree(empty, reference)
    seconds = 0.0
    for bag in bags:
        started = time.monotonic()
        done = _ingest([bag], str(reference))
        assert done.wait(timeout=120) == 0, done.communicate()
        seconds = max(seconds, time.monotonic() - started)
        states.append(_sizes(reference))
        assert states[-1] != states[-2]
    return {"folder": folder, "bags": bags, "empty": empty, "states": states, "seconds": seconds}


def _state(sizes: Sizes, states: list[Sizes]) -> int:
    """How many runs the store holds, wholly; fails if it holds part of a run."""
    assert sizes in states, (
        f"not a state of whole runs: {len(sizes)} graphs, {sum(sizes.values())} quads "
        f"(whole runs: {[(len(s), sum(s.values())) for s in states]})"
    )
    return states.index(sizes)


def test_an_ingest_killed_at_random_points_leaves_each_run_wholly_or_not_at_all(
    setting: dict[str, object],
) -> None:
    folder, empty = setting["folder"], setting["empty"]
    assert isinstance(folder, Path) and isinstance(empty, Path)
    bag: Path = setting["bags"][0]  # type: ignore[index]
    seconds: float = setting["seconds"]  # type: ignore[assignment]
    chance = random.Random(20)
    outcomes = []
    for attempt in range(20):
        store = folder / f"killed-{attempt}"
        shutil.copytree(empty, store)
        ingest = _ingest([bag], str(store))
        time.sleep(chance.uniform(0.05, seconds * 1.05))
        ingest.send_signal(signal.SIGKILL)
        ingest.communicate(timeout=30)
        runs = _state(_sizes(store), setting["states"][:2])  # type: ignore[index]
        outcomes.append(runs == 1)
        shutil.rmtree(store)
    print(f"killed 20 times: the run was stored {sum(outcomes)} times, absent {20 - sum(outcomes)} times")
    assert 0 < sum(outcomes) < 20, "the kills should fall both before and after the run's write"


def test_readers_during_an_ingest_see_whole_runs(setting: dict[str, object]) -> None:
    folder, empty = setting["folder"], setting["empty"]
    assert isinstance(folder, Path) and isinstance(empty, Path)
    store = folder / "read-during-ingest"
    shutil.copytree(empty, store)
    ingest = _ingest(list(setting["bags"]), str(store))  # type: ignore[call-overload]
    states: list[Sizes] = setting["states"]  # type: ignore[assignment]
    said: list[str] = []
    first_run = threading.Event()

    def listen() -> None:
        assert ingest.stderr is not None
        for line in ingest.stderr:
            said.append(line)
            first_run.set()

    listener = threading.Thread(target=listen, daemon=True)
    listener.start()
    # a reader that came first would hold the store read-write and the ingest could not open it:
    # read from when the ingest has written its first run (it holds the store from its start)
    while ingest.poll() is None and not first_run.wait(0.05):
        pass
    seen: list[int] = []
    while ingest.poll() is None:
        with EmbeddedStore(store) as reader:  # another process holds it: a read-only view
            seen.append(_state(reader.graph_sizes(), states))
        time.sleep(0.05)
    listener.join(timeout=30)
    assert ingest.returncode == 0, "".join(said)
    assert len(seen) >= 2 and seen == sorted(seen) and min(seen) < 3  # read while runs were still missing
    print(f"{len(seen)} reads during the ingest saw {sorted(set(seen))} runs")
    assert _state(_sizes(store), states) == 3
    # and a reader through the command line works while a writer holds the store
    holder = _ingest([setting["bags"][0]], str(store))  # type: ignore[index]
    listed = subprocess.run(
        [EXSCEC, "runs", "--store", str(store)], capture_output=True, text=True, timeout=60
    )
    holder.communicate(timeout=60)
    assert listed.returncode == 0 and "3 runs" in listed.stderr, listed.stderr


def test_a_remote_store_that_goes_away_gives_a_clear_error_and_no_partial_run(
    setting: dict[str, object], tmp_path: Path
) -> None:
    from exsce_dsl.store.remote import RemoteStore

    data = tmp_path / "oxigraph"
    bags: list[Path] = setting["bags"]  # type: ignore[assignment]
    with oxigraph_server(data) as server:
        url = f"{server.url}/query"
        watcher = RemoteStore(url)
        ingest = _ingest(bags, url)
        deadline = time.monotonic() + 120
        while not watcher.ask("ASK { GRAPH ?g { ?run a <https://www.sesame-project.org/scenarios/run> } }"):
            assert ingest.poll() is None and time.monotonic() < deadline, ingest.communicate()
            time.sleep(0.02)
        server.process.send_signal(signal.SIGKILL)  # the first run is in; the others are being read
        server.process.wait(timeout=10)
        _, err = ingest.communicate(timeout=120)
    assert ingest.returncode == 2 and "Traceback" not in err and "internal error" not in err, err
    assert "1 ingested, 0 skipped, 2 failed" in err and server.url.removeprefix("http://") in err, err
    with oxigraph_server(data) as again:  # the same data, served again
        store = RemoteStore(f"{again.url}/query")
        sizes = {g: len(store.graph(g)) for g in store.graph_names()}
    assert _state(sizes, setting["states"]) == 1  # type: ignore[arg-type]
