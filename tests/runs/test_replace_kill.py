"""A killed ``exscec ingest --replace`` leaves the old run or the new one, never a mix, never none.

The store holds a run of a bag analysed under a spec; the spec gains a metric; ``exscec ingest
--replace`` runs in a child process (the real command, through exscec's click group) and is
killed with SIGKILL before its write (while it imports and reads the bag), during it, and after
it.  Then the store is opened and must be, graph for graph, exactly the store before the replace
or exactly the store after an unkilled one; the run's metrics the old set or the old set and the
new metric.

To kill *during* the write honestly, the child prints a line when the store write that replaces
the run starts and one when it returns (a wrapper around the embedded store's own ``write``,
which it then calls: nothing is faked).  The write's length is measured on an unkilled replace
(tens of milliseconds for this bag's run: dropping its thirty-odd graphs and inserting a
thousand statements), and the child is killed at several fractions of it after the first line.
At least one kill must land between the two lines.
"""

from __future__ import annotations

import os
import queue
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import run_metric_values, runs

from tests.support.paths import EXAMPLES

CHILD = """
import sys, time
from exsce_dsl.store.embedded import EmbeddedStore

real = EmbeddedStore.write

def write(self, graphs, *, replace=False):
    if replace:
        print(f"writing {time.monotonic()}", flush=True)
    real(self, graphs, replace=replace)
    if replace:
        print(f"written {time.monotonic()}", flush=True)

EmbeddedStore.write = write
from exsce_dsl.cli.main import main
main(sys.argv[1:], prog_name="exscec")
"""

NEW_METRIC = """
metric mean_forward_speed for each robot {
  "mean forward speed"
  unit m/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"
  value mean(abs(vel.linear.x))
}
"""

State = tuple[dict[str, int], frozenset[str], int]
"""Each graph's size, the run's metrics, the number of runs."""


@pytest.fixture(scope="module")
def setting(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, Path]:
    """The spec's folder (with the new metric), a bag, and a store holding its run without it."""
    root = tmp_path_factory.mktemp("kill")
    project = root / "bc"
    shutil.copytree(EXAMPLES / "brsu_building_c", project)
    scenario = load_spec(project / "scenario_c.exsce").scenario()
    [run] = simulate(scenario, root / "bags", runs=1, seed=3)
    store_dir = root / "store"
    with EmbeddedStore(store_dir) as store:
        [result] = ingest_bags([run.bag], scenario, store)
        assert result.run_id is not None, result.message
    metrics = project / "metrics.exsce"
    metrics.write_text(metrics.read_text(encoding="utf-8") + NEW_METRIC, encoding="utf-8")
    (root / "child.py").write_text(CHILD, encoding="utf-8")
    return project, run.bag, store_dir


def _state(store_dir: Path) -> State:
    with EmbeddedStore(store_dir) as store:
        stored = runs(store)
        metrics = frozenset(v.metric for v in run_metric_values(store, [r.uuid for r in stored]))
        return store.graph_sizes(), metrics, len(stored)


class _Child:
    """``exscec ingest --replace`` in a child process; its lines as they come (a thread reads them)."""

    def __init__(self, setting: tuple[Path, Path, Path], store_dir: Path) -> None:
        project, bag, _ = setting
        args = ["ingest", "--replace", str(bag), "--scenario", str(project / "scenario_c.exsce")]
        self.process = subprocess.Popen(
            [sys.executable, str(project.parent / "child.py"), *args, "--store", str(store_dir)],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        self.lines: queue.Queue[str] = queue.Queue()
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.put(line)
        self.process.stdout.close()

    def line(self) -> str:
        return self.lines.get(timeout=120)

    def wait(self) -> int:
        code = self.process.wait(timeout=120)
        self.reader.join(timeout=30)
        return code

    def killed(self) -> tuple[str, bool]:
        """Kill the child (one that ended is a zombie until waited for: the kill is harmless);
        what it said after the kill's moment, and whether it had ended by itself (exit 0)."""
        os.kill(self.process.pid, signal.SIGKILL)
        code = self.wait()
        assert code in (-signal.SIGKILL, 0), code
        rest = []
        while not self.lines.empty():
            rest.append(self.lines.get())
        return "".join(rest), code == 0


def test_a_killed_replace_leaves_the_old_run_or_the_new_one(setting, tmp_path: Path) -> None:
    _, _, base = setting
    old = _state(base)
    assert "mean_forward_speed" not in old[1] and old[2] == 1

    # an unkilled replace: the new state, and how long its write takes
    whole = tmp_path / "whole"
    shutil.copytree(base, whole)
    started = time.monotonic()
    child = _Child(setting, whole)
    writing = float(child.line().split()[1])
    written = float(child.line().split()[1])
    assert child.wait() == 0
    new = _state(whole)
    assert new[1] == old[1] | {"mean_forward_speed"} and new[2] == 1
    assert set(old[0]) <= set(new[0]) and new[0] != old[0]
    duration = written - writing
    assert duration > 0.002, duration  # long enough to be hit

    seen: dict[str, set[str]] = {"before": set(), "during": set(), "after": set()}
    plans = [("start", 0.3), ("start", (writing - started) * 0.5)]
    plans += [("writing", duration * f) for f in (0.0, 0.2, 0.4, 0.6, 0.8, 0.95)]
    plans += [("written", 0.0)]
    for number, (wait_for, delay) in enumerate(plans):
        store_dir = tmp_path / f"store_{number}"
        shutil.copytree(base, store_dir)
        child = _Child(setting, store_dir)
        said = ""
        if wait_for != "start":
            said += child.line()
        if wait_for == "written":
            said += child.line()
        time.sleep(delay)
        after_kill, ended = child.killed()
        said += after_kill
        # a child that ended by itself before the kill (a loaded machine: the write took less than
        # the unkilled one's) said its write was done: the kill landed after it
        assert not ended or "written" in said, said
        # where the kill landed, by what the child said before it died
        when = "before" if "writing" not in said else "during" if "written" not in said else "after"
        state = _state(store_dir)
        assert state in (old, new), (
            f"killed {when} the write ({wait_for} +{delay * 1000:.1f} ms): a mixed store"
        )
        seen[when].add("old" if state == old else "new")
    assert seen["before"] == {"old"} and seen["after"] == {"new"}, seen
    assert seen["during"], f"no kill landed inside the write: {seen}"
