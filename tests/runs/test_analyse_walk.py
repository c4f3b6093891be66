"""A bag's walk through analysis goes straight down the steps of ``runs`` (issue 49, item 1): the
bag opened once, then its signals, segments, metrics and coverage, each step entered once from the
top of ``runs`` and none called back from a step below (``bench/ingest_walk.py`` prints the same
walk with its figures)."""

from __future__ import annotations

import functools
import sys
from pathlib import Path
from types import FrameType
from typing import Any

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.paths import ROOT

RUNS = Path(analyse_bag.__code__.co_filename).resolve().parent
"""Where ``runs`` is imported from: ``src/`` in a checkout, site-packages where exsce is installed."""
STEPS = ("bags", "signals", "segments", "metrics", "coverage", "recorded_execution")
"""The steps of ``runs``, bottom to top; every other module of ``runs`` is its top."""


def _step(frame: FrameType | None) -> str | None:
    """The step of ``runs`` whose code ``frame`` runs (``top``: analysis; None: outside ``runs``)."""
    return None if frame is None else _step_of(frame.f_code.co_filename)


@functools.cache
def _step_of(file: str) -> str | None:
    try:
        inside = Path(file).resolve().relative_to(RUNS)
    except ValueError:
        return None
    name = inside.with_suffix("").parts[0]
    return name if name in STEPS else "top"


@pytest.fixture(scope="module")
def calls(tmp_path_factory: pytest.TempPathFactory) -> list[tuple[str, str]]:
    """(caller's step, callee's step) of every call between two steps while one run of scenario_c
    is analysed (a second time: the first fills the caches)."""
    scenario = load_spec(ROOT / "examples" / "brsu_building_c" / "scenario_c.exsce").scenario()
    (run,) = simulate(scenario, tmp_path_factory.mktemp("walk"), fmt="ros1", seed=7)
    analyse_bag(run.bag, scenario)
    found: list[tuple[str, str]] = []

    def traced(frame: FrameType, event: str, arg: Any) -> None:
        if event != "call":
            return
        callee, caller = _step(frame), _step(frame.f_back)
        if callee is not None and caller is not None and callee != caller:
            found.append((caller, callee))

    sys.setprofile(traced)
    try:
        analyse_bag(run.bag, scenario)
    finally:
        sys.setprofile(None)
    return found


def test_the_walk_of_a_bag_enters_each_step_once(calls: list[tuple[str, str]]) -> None:
    entered = [callee for caller, callee in calls if caller == "top"]
    walk = [step for i, step in enumerate(entered) if i == 0 or entered[i - 1] != step]
    # the monitors are compiled from the specification (exsce_dsl.monitor_code, below runs) before
    # the bag is opened: the read reduces the scans' arrays per block with their code
    assert walk == list(STEPS)


def test_no_step_of_the_walk_calls_back_up(calls: list[tuple[str, str]]) -> None:
    rank = {step: n for n, step in enumerate((*STEPS, "top"))}
    climbs = sorted({(a, b) for a, b in calls if rank[b] > rank[a]})
    assert climbs == []
