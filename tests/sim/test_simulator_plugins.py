"""A simulator from an installed package's entry point (group ``exsce.simulators``) plays runs
as the built-ins do, and its run's PROV names it; a name no simulator has is said with the names
there are."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

from exsce_dsl import api
from exsce_dsl.errors import ExsceError
from exsce_dsl.sim.simulators import SIMULATORS

from tests.support.paths import EXAMPLES
from tests.support.plugin_packages import installed_plugins

PLUGIN = """\
from exsce_dsl.sim.executor import execute


class Mirror:
    name = "mirror"
    version = "1.0"
    settings = {"plays": "the kinematic executor's runs"}

    def play(self, scenario, grid, seed, faults):
        return execute(scenario, grid, seed, faults)
"""
ENTRY_POINTS = """\
[exsce.simulators]
mirror = exsce_test_simulators:Mirror
"""


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    yield from installed_plugins(
        tmp_path, monkeypatch, SIMULATORS, "exsce_test_simulators", PLUGIN, ENTRY_POINTS
    )


@pytest.mark.usefixtures("installed")
def test_a_plugin_simulator_plays_runs_and_is_named_in_their_prov(tmp_path: Path) -> None:
    scenario = api.load(EXAMPLES / "irsim_crossing" / "crossing.exsce").scenario(None)
    [run] = api.simulate(scenario, tmp_path / "runs", 1, simulator="mirror")
    [kinematic] = api.simulate(scenario, tmp_path / "kinematic", 1)
    assert run.run_id != kinematic.run_id  # another simulator's run is another run
    [recorded] = list((tmp_path / "runs").glob("*.prov.json"))
    agents = [
        a for b in json.loads(recorded.read_text())["bundle"].values() for a in b.get("agent", {}).values()
    ]
    [simulator] = [a for a in agents if a.get("exsce:simulator")]
    assert (simulator["exsce:simulator"], simulator["exsce:simulator_version"]) == ("mirror", "1.0")
    assert simulator["exsce:simulator_settings"] == "plays=the kinematic executor's runs"


def test_an_unknown_simulator_is_said_with_the_ones_there_are(tmp_path: Path) -> None:
    scenario = api.load(EXAMPLES / "irsim_crossing" / "crossing.exsce").scenario(None)
    with pytest.raises(ExsceError, match=r"no simulator 'irsm'.*irsim.*the simulators are kinematic, irsim"):
        api.simulate(scenario, tmp_path, 1, simulator="irsm")
