"""Scenario distances d1–d6 on hand-made pairs with known answers, and clustering of derived
scenarios from the store: those that differ only by waypoint order end up together."""

from __future__ import annotations

import json

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.similarity.clustering import cluster
from exsce_dsl.similarity.distances import (
    Norms,
    ScenarioFacts,
    area_of,
    distances,
    pose_id,
    robot_distances,
    segment_distance,
)
from exsce_dsl.similarity.facts import scenario_facts
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES


def facts(id_, bases=("pmb2",), torsos=(True,), segments=(), metrics=None, violation=None, hotspots=None):
    return ScenarioFacts(id_, tuple(bases), tuple(torsos), tuple(segments), metrics or {}, violation, hotspots)


def test_d1_d2_d3_count_robots_base_types_and_torsos_over_the_largest_fleet():
    two = facts("a", ("pmb2", "pmb2"), (True, True))
    one = facts("b", ("pmb2",), (True,))
    mixed = facts("c", ("pmb2", "omni_base"), (True, False))
    assert robot_distances(two, one, 2) == (0.5, 0.5, 0.5)
    assert robot_distances(two, mixed, 2) == (0.0, 1.0, 1.0)  # one pmb2 fewer, one omni_base more
    assert robot_distances(two, two, 2) == (0.0, 0.0, 0.0)
    assert robot_distances(one, mixed, 4) == (0.25, 0.25, 0.25)


def test_d4_shared_segments_cost_nothing_same_areas_half_others_one():
    a = [("hall-w1", "lab-w1"), ("lab-w1", "office-w1")]
    same_areas = [("hall-w1", "lab-w1"), ("lab-w2", "office-w2")]
    assert segment_distance(a, a) == 0.0
    assert segment_distance(a, same_areas) == pytest.approx((0 + 0.5 + 0 + 0.5) / 4)
    assert segment_distance(a, [("kitchen-w1", "hall-w1")]) == pytest.approx((1 + 1 + 1) / 4)
    assert segment_distance([], []) == 0.0
    assert area_of("classroom_c025-w001") == "classroom_c025"
    assert pose_id("classroom_c022-w001-R0.00_P0.00_Y-2.269") == "classroom_c022-w001"


def test_metric_violation_and_hotspot_distances_are_divided_by_the_largest_stored_value():
    a = facts("a", metrics={"task_duration": 100.0, "distance_travelled": 50.0}, violation=2.0, hotspots=1.0)
    b = facts("b", metrics={"task_duration": 150.0, "distance_travelled": 50.0}, violation=6.0, hotspots=3.0)
    no_runs = facts("c")
    norms = Norms.of([a, b, no_runs])
    found = distances(a, b, norms)
    assert found.metrics == pytest.approx((50 / 150 + 0) / 2)
    assert found.d5 == pytest.approx(4 / 6)
    assert found.d6 == pytest.approx(2 / 3)
    without = distances(a, no_runs, norms)
    assert (without.metrics, without.d5, without.d6) == (None, None, None)
    assert without.combined() == pytest.approx((without.d1 + without.d2 + without.d3 + without.d4) / 4)
    weighted = found.combined({"d5": 3.0, "d1": 0.0})
    known = {"d2": 0.0, "d3": 0.0, "d4": 0.0, "metrics": found.metrics, "d5": found.d5, "d6": found.d6}
    assert weighted == pytest.approx((known["metrics"] + 3 * known["d5"] + known["d6"]) / 8)


SPEC = """\
import "{building}/scenario_c.exsce"

derive c_reversed from scenario_c {{
  reverse waypoints of delivery_a
}}

derive c_one from scenario_c {{
  remove robot tiago2 reassign to tiago1
}}

derive c_one_reversed from c_one {{
  reverse waypoints of delivery_b
}}
"""


@pytest.fixture(scope="module")
def project(tmp_path_factory):
    folder = tmp_path_factory.mktemp("similarity")
    (folder / "derived.exsce").write_text(SPEC.format(building=EXAMPLES / "brsu_building_c"))
    spec = load_spec(folder / "derived.exsce")
    with EmbeddedStore(folder / ".exsce" / "store") as store:
        for scenario in spec.scenarios:
            add_prov(store, compile_scenario(scenario))
    return folder


def test_facts_come_from_the_store(project):
    with EmbeddedStore(project / ".exsce" / "store") as store:
        c = scenario_facts(store, "scenario_c")
        one = scenario_facts(store, "c_one")
    assert c.bases == ("pmb2", "pmb2") and c.torsos == (True, True)
    assert c.segments[0] == ("classroom_c025-w001", "classroom_c022-w001")
    assert len(c.segments) == 6  # three per robot
    # c_one's single robot drives one path: each segment starts where the one before ended
    assert all(one.segments[i][1] == one.segments[i + 1][0] for i in range(len(one.segments) - 1))
    assert one.segments[0][0] == "classroom_c025-w001" and len(one.segments) > len(c.segments) / 2
    assert one.fleet == 1 and c.metrics == {} and c.violation is None  # no runs yet


def test_clustering_groups_the_scenarios_that_differ_only_by_waypoint_order(project):
    with EmbeddedStore(project / ".exsce" / "store") as store:
        found = cluster([scenario_facts(store, s) for s in ("scenario_c", "c_reversed", "c_one", "c_one_reversed")],
                        k=2)
    assert found.clusters["scenario_c"] == found.clusters["c_reversed"]
    assert found.clusters["c_one"] == found.clusters["c_one_reversed"]
    assert found.clusters["scenario_c"] != found.clusters["c_one"]
    assert found.pairs[("scenario_c", "c_reversed")].d1 == 0.0
    assert found.pairs[("scenario_c", "c_one")].d1 == 0.5


def test_cli_cluster_prints_the_table_and_the_json(project):
    table = exscec_here("cluster", "--k", "2", cwd=project)
    assert table.returncode == 0, table.stderr
    rows = dict(line.split() for line in table.stdout.splitlines()[1:])
    assert rows["scenario_c"] == rows["c_reversed"] != rows["c_one"] == rows["c_one_reversed"]
    out = exscec_here("cluster", "-s", "scenario_c", "-s", "c_one", "--json", cwd=project)
    data = json.loads(out.stdout)
    assert data["scenarios"] == ["scenario_c", "c_one"] and data["pairs"][0]["d1"] == 0.5
    unknown = exscec_here("cluster", "-s", "nope", "-s", "c_one", cwd=project)
    assert unknown.returncode == 2 and "not in the store: nope" in unknown.stderr and "Traceback" not in unknown.stderr
    bad = exscec_here("cluster", "-w", "d9=1", cwd=project)
    assert bad.returncode == 2 and "write NAME=W" in bad.stderr


def test_facts_of_a_scenario_with_runs_have_metric_means_violations_and_hotspots(tmp_path):
    from exsce_dsl.runs.ingest import ingest_bags
    from exsce_dsl.sim.executor import Fault
    from exsce_dsl.sim.run import simulate

    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario()
    bags = [run.bag for run in simulate(scenario, tmp_path / "runs", runs=1, seed=2)]
    bags += [run.bag for run in simulate(scenario, tmp_path / "fast", runs=1, seed=2,
                                         faults=(Fault.parse("overspeed:tiago1"),))]
    with EmbeddedStore(tmp_path / "store") as store:
        assert not any(r.failed for r in ingest_bags(bags, scenario, store))
        found = scenario_facts(store, "scenario_c")
    assert found.metrics["waypoints_visited"] == pytest.approx(100.0)  # every planned waypoint reached
    assert set(found.metrics) >= {"mission_duration", "task_duration", "distance_travelled", "max_velocity"}
    # the larger of the robots' means over the two runs: tiago1's, ~0.6 m/s clean and ~1.3 m/s too fast
    assert 0.9 < found.metrics["max_velocity"] < 1.3
    assert found.violation > 0 and found.hotspots > 0  # the over-speed run's violations, over two runs


def test_d5_and_d6_count_the_users_safety_metrics_too(tmp_path):
    from exsce_dsl.runs.ingest import ingest_bags
    from exsce_dsl.sim.run import simulate
    from exsce_dsl.store import queries

    (tmp_path / "safety.exsce").write_text(
        f'import "{EXAMPLES / "brsu_building_c" / "scenario_c.exsce"}"\n\n'
        "metric turn_rate for each robot {\n  unit rad/s\n  safe below 0.3 rad/s\n"
        '  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"\n  value max(abs(vel.angular.z))\n}\n'
    )
    scenario = load_spec(tmp_path / "safety.exsce").scenario("scenario_c")
    bags = [run.bag for run in simulate(scenario, tmp_path / "runs", runs=1, seed=2)]
    with EmbeddedStore(tmp_path / "store") as store:
        assert not any(r.failed for r in ingest_bags(bags, scenario, store))
        assert "turn_rate" in queries.safety_metrics(store, "scenario_c")
        turning = queries.violation_duration(store, "scenario_c", "turn_rate")
        spots = sum(queries.hotspot_counts(store, "scenario_c", "turn_rate").values())
        found = scenario_facts(store, "scenario_c")
    assert turning and all(a.mean > 1.0 for a in turning.values())  # both robots turn faster than 0.3 rad/s
    assert spots > 0
    # the clean run breaks none of the built-in limits: d5 and d6 see only the user's metric
    assert found.violation == pytest.approx(sum(a.mean for a in turning.values()))
    assert found.hotspots == spots
