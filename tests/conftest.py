"""The fixtures every test folder may ask for, and the one hook that sizes the run; helpers that
tests import live in tests/support/."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

from tests.support.paths import EXAMPLES

if TYPE_CHECKING:  # exsce is imported once the run's cache folder is set (pytest_configure)
    from exsce_dsl.model import Scenario, Task


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto`` (the README's command): one worker more than this machine has cores.  Many
    tests wait on processes of their own (a roscore coming up, a server starting, a mission on
    simulated time) and leave a core idle meanwhile: with two workers on two cores 12 % of the
    workers' time went to waiting; a third worker takes it (CI: 18 min -> 15 min)."""
    return (os.cpu_count() or 1) + 1


LONGEST_FIRST = (
    "explore/test_explore_ros2.py",  # live
    "cli/test_help_examples_runs.py",
    "api/test_python_api.py",
    "runs/test_ros1_graph.py",  # live
    "execute/test_ros1_execute.py",
    "execute/test_live_loop.py",  # live
    "mcp_server/test_mcp_server.py",
    "cli/test_root_namespace_nav2.py",
    "runs/signals/test_timeline.py",
    "explore/test_figures.py",
    "cli/test_init_from_bag.py",
    "cli/test_demo_remote.py",
    "report/test_report.py",
    "store/test_same_answers.py",
    "execute/test_stand_in.py",
    "project/test_docs_examples.py",
    "project/test_static_checks.py",
    "explore/test_campaign.py",
    "cli/test_help_examples_live.py",  # live
    "cli/test_help_examples_explore.py",  # live
    "cli/test_help_examples_language.py",
    "execute/test_ros2_live_loop.py",  # live
    "store/test_server_writes.py",
)
"""Test files that take longest (20-270 s each on two cores under the suite's load), handed out
first: xdist hands out files in collection order (``--no-loadscope-reorder``; its default puts
the files with most tests first, and so these, of one or two tests each, last, where one worker
went on alone for a minute after the others had finished).  A worker whose file has two tests or
fewer left is sent the next file at once, so the order is not simply longest first: this one was
found by replaying xdist's scheduling with each test's seconds in a whole run (three workers),
for the files on a live ROS graph (``# live``) to run one after another, mostly on one worker,
while the other two take the rest.  Two live files at once had the recorders of both off the
cores for long enough to leave gaps over 0.5 s in their runs (an inconclusive run, a baseline
refused); with the ROS 2 live loop (~200 s, not listed before) at the start beside the ROS 1 one,
the live files overlapped for ~600 s of a run, in the order before it ~250 s, in this one none."""


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files of :data:`LONGEST_FIRST` first, in its order; the others after, as collected."""
    root = Path(__file__).parent
    rank = {root / name: i for i, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path, len(LONGEST_FIRST)))


def pytest_configure(config: pytest.Config) -> None:
    """The run's own cache folder (``$EXSCE_CACHE``) for the tests and every ``exscec`` they start,
    shared by the xdist workers, which inherit it: the suite leaves the user's ``~/.cache/exsce``
    alone (it wrote an entry there for every scenario in every temporary folder, 130 MB)."""
    if hasattr(config, "workerinput"):  # an xdist worker: its controller chose the folder
        return
    folder = tempfile.mkdtemp(prefix="exsce-test-cache-")
    config.stash[_CACHE] = folder
    os.environ["EXSCE_CACHE"] = folder


def pytest_unconfigure(config: pytest.Config) -> None:
    folder = config.stash.get(_CACHE, None)
    if folder is not None:
        shutil.rmtree(folder, ignore_errors=True)


_CACHE = pytest.StashKey[str]()


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="session")
def spec_c() -> tuple[Scenario, dict[str, Task]]:
    """The shipped scenario_c and the tasks its specification declares (loaded once)."""
    from exsce_dsl.lang import load_spec

    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    return spec.scenario("scenario_c"), {t.id: t for t in spec.tasks}


@pytest.fixture
def ros2_env(monkeypatch: pytest.MonkeyPatch) -> Iterator[dict[str, str]]:
    """A ROS 2 domain of this test's own (``tests.support.ros2_graph``), set in ``os.environ``
    too: for rclpy in the test's process and the processes it starts."""
    from tests.support.ros2_graph import ros2_domain

    with ros2_domain() as env:
        for name, value in env.items():
            monkeypatch.setenv(name, value)
        monkeypatch.delenv("ROS_LOCALHOST_ONLY", raising=False)
        yield env
