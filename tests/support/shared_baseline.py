"""One project with scenario_c's baseline, made once per test run and copied by each test that
needs one: three runs simulated, ingested and baselined by the real ``exscec``, as a user would.

Three live tests judge their runs against such a baseline and never change it; making it cost
each of them three simulations, an ingest and a baseline (about 9 CPU seconds).  The xdist
workers of one run share the run's temporary root, so the first worker to ask makes it, under a
lock, and the others wait for it and copy it.
"""

from __future__ import annotations

import fcntl
import os
import shutil
from pathlib import Path

import pytest

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES

SPEC = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
_MADE = ".made"


def copy_of_baseline_project(tmp_path_factory: pytest.TempPathFactory, into: Path) -> Path:
    """``into`` holding a copy of the run's baseline project: ``sim/`` (three simulated runs of
    scenario_c) and ``.exsce/store`` (them ingested, and the baseline built from them)."""
    made = _made_once(tmp_path_factory)
    shutil.copytree(made, into, dirs_exist_ok=True, ignore=shutil.ignore_patterns(_MADE))
    return into


def _made_once(tmp_path_factory: pytest.TempPathFactory) -> Path:
    base = tmp_path_factory.getbasetemp()
    root = base.parent if "PYTEST_XDIST_WORKER" in os.environ else base  # the run's, shared
    folder = root / "scenario_c-baseline"
    with open(root / "scenario_c-baseline.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / _MADE).exists():
            shutil.rmtree(folder, ignore_errors=True)  # a try that failed half-way
            folder.mkdir()
            _make(folder)
            (folder / _MADE).touch()
    return folder


def _make(folder: Path) -> None:
    done = run_exscec("simulate", SPEC, "--runs", "3", "-o", "sim", cwd=folder)
    assert done.returncode == 0, done.stderr
    bags = sorted(str(p.relative_to(folder)) for p in (folder / "sim").glob("*.bag"))
    done = run_exscec("ingest", *bags, "--scenario", SPEC, cwd=folder)
    assert done.returncode == 0, done.stderr
    done = run_exscec("baseline", SPEC, cwd=folder)
    assert done.returncode == 0, done.stderr
