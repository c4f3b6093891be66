"""The fixtures every test folder may ask for, and the one hook that sizes the run; helpers that
tests import live in tests/support/."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario, Task

from tests.support.paths import EXAMPLES


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """``-n auto`` (the README's command): one worker more than this machine has cores.  Many
    tests wait on processes of their own (a roscore coming up, a server starting, a mission on
    simulated time) and leave a core idle meanwhile: with two workers on two cores 12 % of the
    workers' time went to waiting; a third worker takes it (CI: 18 min -> 15 min)."""
    return (os.cpu_count() or 1) + 1


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="session")
def spec_c() -> tuple[Scenario, dict[str, Task]]:
    """The shipped scenario_c and the tasks its specification declares (loaded once)."""
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    return spec.scenario("scenario_c"), {t.id: t for t in spec.tasks}
