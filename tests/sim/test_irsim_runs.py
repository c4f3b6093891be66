"""IR-SIM's runs of the crossing example: the same seed gives the same bags (a campaign's
finding reproduces by its seed), every convention and format is written and ingested, the faults
IR-SIM plays are planted and the others refused, and a missing IR-SIM is said plainly."""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from exsce_dsl import api
from exsce_dsl.cli.main import main
from exsce_dsl.errors import ExsceError
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.sim.irsim_play import play_in_irsim
from exsce_dsl.sim.simulators import IrsimSimulator

from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "irsim_crossing" / "crossing.exsce"


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return api.load(SPEC).scenario(None)


def _digest(bag: Path) -> str:
    files = sorted(bag.rglob("*")) if bag.is_dir() else [bag]
    return hashlib.sha256(b"".join(f.read_bytes() for f in files if f.is_file())).hexdigest()


def test_the_same_seed_gives_the_same_bag(scenario: Scenario, tmp_path: Path) -> None:
    first = api.simulate(scenario, tmp_path / "a", 1, seed=4, simulator="irsim")
    again = api.simulate(scenario, tmp_path / "b", 1, seed=4, simulator="irsim")
    other = api.simulate(scenario, tmp_path / "c", 1, seed=5, simulator="irsim")
    assert _digest(first[0].bag) == _digest(again[0].bag)
    assert first[0].run_id == again[0].run_id
    assert _digest(first[0].bag) != _digest(other[0].bag)


@pytest.mark.parametrize(("convention", "fmt"), [("method", "ros1"), ("move_base", "ros2"), ("nav2", "mcap")])
def test_each_convention_and_format_is_ingested(
    scenario: Scenario, tmp_path: Path, convention: str, fmt: str
) -> None:
    [run] = api.simulate(scenario, tmp_path / "runs", 1, format=fmt, convention=convention, simulator="irsim")
    results, tally = api.ingest_files(str(tmp_path / "store"), scenario, [run.bag])
    assert tally.ingested == 1, results
    assert not results[0].problems, results[0].problems
    assert [a.status.name for a in run.execution.actions] == ["SUCCEEDED"] * 6


def test_an_irsim_run_is_never_a_kinematic_one(scenario: Scenario, tmp_path: Path) -> None:
    [irsim] = api.simulate(scenario, tmp_path, 1, simulator="irsim")
    [kinematic] = api.simulate(scenario, tmp_path, 1)
    assert irsim.run_id != kinematic.run_id and irsim.bag != kinematic.bag


def test_overspeed_is_planted_in_irsim(scenario: Scenario, tmp_path: Path) -> None:
    [run] = api.simulate(scenario, tmp_path, 1, simulator="irsim", faults=["overspeed:robot_w"])
    fastest = {r: float(abs(m.v).max()) for r, m in run.execution.trajectories.items()}
    assert fastest["robot_w"] > 1.0 > fastest["robot_e"]


def test_a_fault_irsim_does_not_play_is_refused(scenario: Scenario, tmp_path: Path) -> None:
    with pytest.raises(ExsceError, match="IR-SIM does not play the fault.*near-collision"):
        api.simulate(scenario, tmp_path, 1, simulator="irsim", faults=["near-collision"])


def test_an_unknown_behaviour_is_refused(scenario: Scenario, tmp_path: Path) -> None:
    result = CliRunner().invoke(
        main, ["simulate", str(SPEC), "--simulator", "irsim", "--behaviour", "rvp", "-o", str(tmp_path)]
    )
    assert result.exit_code == 2 and "rvp" in result.output


def test_an_unknown_behaviour_or_scan_source_is_refused_by_the_library(scenario: Scenario) -> None:
    grid = planning_grid(scenario)
    with pytest.raises(ExsceError, match="IR-SIM has no behaviour 'rvp'.*rvo"):
        play_in_irsim(scenario, grid, 0, behaviour="rvp")
    with pytest.raises(ExsceError, match="unknown scan source 'lidar'"):
        IrsimSimulator("rvo", "lidar")


def test_a_missing_irsim_is_said_with_its_remedy(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setitem(sys.modules, "irsim", None)  # import irsim now raises ImportError
    result = CliRunner().invoke(main, ["simulate", str(SPEC), "--simulator", "irsim", "-o", str(tmp_path)])
    assert result.exit_code == 2
    assert "IR-SIM is not installed: pip install 'exsce[irsim]'" in result.output
    assert "Traceback" not in result.output
    assert not list(tmp_path.iterdir())  # nothing half-way


def _variant(tmp_path: Path, mission: str, allocation: str) -> Scenario:
    spec = tmp_path / "variant.exsce"
    spec.write_text(
        f'import "{SPEC}"\n'
        "scenario variant in three_rooms {\n"
        "  robots {\n    robot_w: pmb2 starts at west-desk\n    robot_e: pmb2 starts at east-desk\n  }\n"
        f"  mission variant_mission {mission} {{\n{allocation}  }}\n}}\n",
        encoding="utf-8",
    )
    return api.load(spec).scenario("variant")


def test_a_sequential_mission_runs_one_robot_at_a_time(tmp_path: Path) -> None:
    scenario = _variant(tmp_path, "sequential", "    robot_w does sort_west\n    robot_e does sort_east\n")
    [run] = api.simulate(scenario, tmp_path / "runs", 1, simulator="irsim")
    west = [a for a in run.execution.actions if a.robot == "robot_w"]
    east = [a for a in run.execution.actions if a.robot == "robot_e"]
    assert len(west) == len(east) == 3
    assert all(a.status.name == "SUCCEEDED" for a in west + east)
    assert min(a.start for a in east) > max(a.end for a in west)  # robot_e waited for robot_w's entry


def test_robots_that_collide_in_irsim_abort_their_goals_and_say_so(tmp_path: Path) -> None:
    # dash does not avoid: the two robots cross the hall head-on, on one line
    scenario = _variant(tmp_path, "parallel", "    robot_w does sort_east\n    robot_e does sort_west\n")
    [run] = api.simulate(scenario, tmp_path / "runs", 1, simulator="irsim", behaviour="dash")
    outcomes = {(a.robot, a.waypoint_number): (a.status.name, a.outcome) for a in run.execution.actions}
    assert outcomes[("robot_w", 1)] == ("ABORTED", "collided")
    assert outcomes[("robot_e", 1)] == ("ABORTED", "collided")
    [recorded] = list(run.bag.parent.glob("*.prov.json"))
    prov = recorded.read_text()
    assert prov.count('"exsce:goal_outcome": "collided"') == 6  # the later goals of a stopped robot too
