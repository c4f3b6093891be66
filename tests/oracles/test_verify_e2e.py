"""The method end to end on the executor's runs: clean runs build a baseline, further clean
runs pass every oracle, and each injected fault fails exactly the oracles it should.

The same table holds when the robots are Nav2's (their runs in Nav2's topics and types).

Two robots in a 10 m yard whose paths never meet: r1 goes a → b → e, r2 goes d → c.  The
whole verdict table is asserted; what each fault should fail, and why:

* over-speed of r1: r1's max_velocity (above 1 m/s) and r1's task_duration (done ~30 % faster);
* slow r1: r1's task_duration (half speed);
* r1 skips its 2nd waypoint: r1's waypoints_visited, distance_travelled and task_duration;
* near-collision (r2 first drives up to r1, which waits, then goes back): the distance between
  the robots, r2's distance_to_obstacles (its laser sees r1 5 cm away), and r2's
  distance_travelled and task_duration (the detour is r2's).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.runs.bags.reading import bag_topics
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC as SPEC

FAULTS = ("overspeed:r1", "slow:r1", "skip-waypoint:r1:2", "near-collision")
SHOULD_FAIL = {
    "clean": set(),
    "overspeed:r1": {"r1-max_velocity", "r1-task_duration"},
    "slow:r1": {"r1-task_duration"},
    "skip-waypoint:r1:2": {"r1-waypoints_visited", "r1-distance_travelled", "r1-task_duration"},
    "near-collision": {
        "distance_between_robots",
        "r2-distance_to_obstacles",
        "r2-distance_travelled",
        "r2-task_duration",
    },
}
ORACLES = {
    "r1-max_velocity",
    "r2-max_velocity",
    "r1-distance_to_obstacles",
    "r2-distance_to_obstacles",
    "distance_between_robots",
    "r1-waypoints_visited",
    "r2-waypoints_visited",
    "r1-task_duration",
    "r2-task_duration",
    "r1-distance_travelled",
    "r2-distance_travelled",
}


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path], dict[str, Path]]:
    """The project folder, six clean bags and one bag per fault."""
    folder = tmp_path_factory.mktemp("yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(SPEC)
    scenario = load_spec(folder / "spec.exsce").scenario()
    clean = [run.bag for run in simulate(scenario, folder / "runs", 6, seed=1)]
    faulty = {
        fault: next(iter(simulate(scenario, folder / "faults", 1, seed=2, faults=(Fault.parse(fault),)))).bag
        for fault in FAULTS
    }
    return folder, clean, faulty


def test_baseline_refuses_too_few_runs_then_builds_from_enough(
    yard: tuple[Path, list[Path], dict[str, Path]],
) -> None:
    folder, clean, _ = yard
    three = exscec_here("ingest", *map(str, clean[:3]), "--scenario", "spec.exsce", cwd=folder)
    assert three.returncode == 0, three.stderr
    refused = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert "scenario 'yard_run' has 3 good stored runs; its baseline needs 4" in refused.stderr
    fourth = exscec_here("ingest", str(clean[3]), "--scenario", "spec.exsce", cwd=folder)
    assert fourth.returncode == 0, fourth.stderr
    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    lines = {line.split()[0]: line.split()[1:] for line in built.stdout.splitlines()[1:]}
    assert set(lines) == ORACLES
    assert lines["r1-max_velocity"] == ["below_max", "1"]
    assert lines["r2-waypoints_visited"] == ["invariant", "1", "0", "4"]  # value, tolerance, runs
    value, tolerance, runs = (float(x) for x in lines["r1-task_duration"][1:])
    assert runs == 4 and tolerance == pytest.approx(0.2 * value, rel=1e-3)


def test_clean_runs_pass_and_each_fault_fails_exactly_its_oracles(
    yard: tuple[Path, list[Path], dict[str, Path]],
) -> None:
    _fault_table_holds(*yard)


@pytest.fixture(scope="module")
def nav2_yard(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Path], dict[str, Path]]:
    """The yard with Nav2 robots: their runs written in Nav2's topics, four of them ingested as
    the baseline (the others are judged)."""
    folder = tmp_path_factory.mktemp("nav2-yard")
    write_map(folder, size=200)
    (folder / "spec.exsce").write_text(SPEC.replace("  torso yes\n", "  torso yes\n  convention nav2\n"))
    scenario = load_spec(folder / "spec.exsce").scenario()
    assert {r.type.signals.convention for r in scenario.robots} == {"nav2"}
    clean = [run.bag for run in simulate(scenario, folder / "runs", 6, seed=1)]
    faulty = {
        fault: next(iter(simulate(scenario, folder / "faults", 1, seed=2, faults=(Fault.parse(fault),)))).bag
        for fault in FAULTS
    }
    baseline = exscec_here("ingest", *map(str, clean[:4]), "--scenario", "spec.exsce", cwd=folder)
    assert baseline.returncode == 0, baseline.stderr
    built = exscec_here("baseline", "spec.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    return folder, clean, faulty


def test_the_fault_table_holds_for_nav2_runs(nav2_yard: tuple[Path, list[Path], dict[str, Path]]) -> None:
    """The same verdicts when the robots are Nav2's: TF poses, cmd_vel, odometry, goals."""
    folder, clean, _ = nav2_yard
    assert "/r1/navigate_to_pose/_action/status" in bag_topics(clean[4])
    assert "/r1/robot_pose" not in bag_topics(clean[4])
    _fault_table_holds(*nav2_yard)


def _fault_table_holds(folder: Path, clean: list[Path], faulty: dict[str, Path]) -> None:
    bags = {"clean": clean[4:], **{fault: [bag] for fault, bag in faulty.items()}}
    given = [str(bag) for group in bags.values() for bag in group]
    judged = exscec_here(
        "verify", *given, "--scenario", "spec.exsce", "--json", "--junit", "verdicts.xml", cwd=folder
    )
    assert judged.returncode == 1, judged.stderr  # some oracle failed
    verdicts = json.loads(judged.stdout)
    listed = exscec_here("runs", "--format", "json", cwd=folder)
    bag_of_run = {
        row["run"]["value"]: row["bag"]["value"] for row in json.loads(listed.stdout)["results"]["bindings"]
    }
    case_of_bag = {bag.name: case for case, group in bags.items() for bag in group}
    table: dict[str, dict[str, set[str]]] = {}
    for verdict in verdicts:
        case = case_of_bag[bag_of_run[verdict["run"]]]
        table.setdefault(case, {}).setdefault(verdict["verdict"], set()).add(verdict["oracle"])
        assert verdict["verdict"] in ("passed", "failed"), verdict
        if verdict["metric"] in ("task_duration", "distance_travelled", "waypoints_visited"):
            assert len(verdict["runs"]) == 4  # the expectation came from the four baseline runs
    for case, should_fail in SHOULD_FAIL.items():
        assert table[case].get("failed", set()) == should_fail, case
        assert table[case]["passed"] == ORACLES - should_fail, case
    report = ET.parse(folder / "verdicts.xml").getroot()
    failures = sum(len(SHOULD_FAIL[case]) * len(group) for case, group in bags.items())
    assert report.tag == "testsuites" and int(report.get("failures", "-1")) == failures == 10
    assert int(report.get("tests", "-1")) == len(ORACLES) * len(given)
    assert len(report.findall("testsuite")) == len(given)
    assert len(report.findall(".//testcase/failure")) == failures


def test_the_verdicts_are_provenance_in_the_store(yard: tuple[Path, list[Path], dict[str, Path]]) -> None:
    folder, _, _ = yard
    query = (
        "PREFIX exsce: <https://www.sesame-project.org/scenarios/> "
        "PREFIX oracle: <https://www.sesame-project.org/scenarios/oracles/> "
        "SELECT ?outcome (COUNT(?v) AS ?n) WHERE { GRAPH ?g { ?v a exsce:verdict ; oracle:outcome ?outcome } } "
        "GROUP BY ?outcome ORDER BY ?outcome"
    )
    found = exscec_here("sparql", query, "--format", "csv", cwd=folder)
    assert found.returncode == 0, found.stderr
    assert found.stdout.split() == ["outcome,n", "failed,10", f"passed,{len(ORACLES) * 6 - 10}"]


LONG = """\
import "spec.exsce"

// yard_run with r1 alone, doing patrol_2 (to c) after patrol_1: a metamorphic test of yard_run
scenario yard_long in yard {
  robots {
    r1: tiago starts at field-a
  }
  mission long_mission sequential {
    r1 does patrol_1 then patrol_2
  }
}

acceptance for yard_long {
  scenario "longer than the pair's r1" {
    given at least 1 baseline runs
    when long_mission runs
    then r1 distance_travelled is increasing by 4 m of yard_run
     and r1 max_velocity is invariant within 10 % of yard_run
     and r1 waypoints_visited is increasing by 1 of yard_run
  }
}
"""


def test_a_derived_scenario_is_judged_against_the_runs_of_its_base(
    yard: tuple[Path, list[Path], dict[str, Path]],
) -> None:
    folder, _, _ = yard
    (folder / "long.exsce").write_text(LONG)
    scenario = load_spec(folder / "long.exsce").scenario()
    bag = next(iter(simulate(scenario, folder / "long", 1, seed=5))).bag
    built = exscec_here("baseline", "long.exsce", cwd=folder)
    assert built.returncode == 0, built.stderr
    rows = {line.split()[0]: line.split()[1:] for line in built.stdout.splitlines()[1:]}
    # the base's runs that passed (4 baseline + 2 clean), not the 4 a fault made fail
    relation, of, base, value, delta, tolerance, runs = rows["r1-distance_travelled"]
    assert (relation, of, base, delta, tolerance, runs) == ("increasing", "of", "yard_run", "4", "0", "6")
    assert float(value) == pytest.approx(11.95, abs=0.01)
    judged = exscec_here("verify", str(bag), "--scenario", "long.exsce", "--json", cwd=folder)
    assert judged.returncode == 0, judged.stdout + judged.stderr
    verdicts = {v["oracle"]: v for v in json.loads(judged.stdout)}
    assert set(verdicts) == {"r1-distance_travelled", "r1-max_velocity", "r1-waypoints_visited"}
    distance = verdicts["r1-distance_travelled"]
    assert distance["verdict"] == "passed" and distance["expected"] == pytest.approx(11.95, abs=0.01)
    assert distance["observed"] == pytest.approx(11.95 + 4.95, abs=0.05)  # e → c is 4.95 m more
    assert verdicts["r1-waypoints_visited"]["observed"] == 3 and len(distance["runs"]) == 6
