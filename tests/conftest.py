"""The fixtures every test folder may ask for; helpers that tests import live in tests/support/."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario, Task

from tests.support.paths import EXAMPLES


@pytest.fixture
def in_tmp(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture(scope="session")
def spec_c() -> tuple[Scenario, dict[str, Task]]:
    """The shipped scenario_c and the tasks its specification declares (loaded once)."""
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    return spec.scenario("scenario_c"), {t.id: t for t in spec.tasks}
