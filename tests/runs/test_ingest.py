"""Ingestion: metrics from real bags, checked against the executor's ground truth; bad bags."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Reader as Ros1Reader
from rosbags.rosbag1 import Writer as Ros1Writer

from exsce_dsl.errors import BagError, SegmentError
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model.runs import MetricScope, MetricValue
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.executor import Fault, GoalStatus
from exsce_dsl.sim.messages import typestore
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(BUILDING / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def runs_c(scenario_c, tmp_path_factory):
    """One run of scenario_c in each bag format (same seed: same motion)."""
    out = tmp_path_factory.mktemp("runs")
    return {
        fmt: next(iter(simulate(scenario_c, out / fmt, runs=1, fmt=fmt, seed=7)))
        for fmt in ("ros1", "ros2", "mcap")
    }


def _driven(tr, start: float, end: float) -> float:
    """Metres the robot really drove between two instants (backing up to give way included)."""
    k0, k1 = int(round(start / 0.02)), int(round(end / 0.02))
    return float(np.hypot(np.diff(tr.x[k0 : k1 + 1]), np.diff(tr.y[k0 : k1 + 1])).sum())


def _value(
    values: Iterable[MetricValue], metric: str, robot: str | None = None, scope=None, safety=None
) -> float:
    found = [
        v
        for v in values
        if v.metric == metric
        and v.robot == robot
        and (scope is None or v.scope is scope)
        and v.safety_metric == safety
    ]
    assert len(found) == 1, (metric, robot, found)
    return found[0].value


@pytest.mark.parametrize("fmt", ["ros1", "ros2", "mcap"])
def test_metrics_match_the_ground_truth(scenario_c, runs_c, fmt: str) -> None:
    sim = runs_c[fmt]
    truth = sim.execution
    run = analyse_bag(sim.bag, scenario_c).run
    values = run.metrics
    starts = [a.start for a in truth.actions]
    ends = [a.end for a in truth.actions]
    assert _value(values, "mission_duration") == pytest.approx(max(ends) - min(starts), abs=0.03)
    for robot in ("tiago1", "tiago2"):
        mine = [a for a in truth.actions if a.robot == robot]
        tr = truth.trajectories[robot]
        assert _value(values, "task_duration", robot, MetricScope.ROBOT) == pytest.approx(
            max(a.end for a in mine) - min(a.start for a in mine), abs=0.03
        )
        assert _value(values, "waypoints_visited", robot) == 3
        assert _value(values, "distance_travelled", robot, MetricScope.ROBOT) == pytest.approx(
            _driven(tr, min(a.start for a in mine), max(a.end for a in mine)), rel=0.01
        )
        assert _value(values, "max_velocity", robot, MetricScope.ROBOT) == pytest.approx(
            np.abs(tr.v).max(), abs=0.02
        )
        grid = planning_grid(scenario_c)
        k0, k1 = int(min(a.start for a in mine) / 0.02), int(max(a.end for a in mine) / 0.02)
        wall = grid.clearance_at(np.column_stack([tr.x[k0:k1], tr.y[k0:k1]])).min()
        other = truth.trajectories["tiago2" if robot == "tiago1" else "tiago1"]
        robot_gap = np.hypot(tr.x[k0:k1] - other.x[k0:k1], tr.y[k0:k1] - other.y[k0:k1]).min() - 0.3
        nearest = min(wall, robot_gap)  # walls and the other robot's body
        measured = _value(values, "distance_to_obstacles", robot, MetricScope.ROBOT)
        assert nearest - 0.1 <= measured <= nearest + 0.3  # the laser sees 270° around it
        segments = sorted(
            (
                v
                for v in values
                if v.metric == "distance_travelled" and v.scope is MetricScope.SEGMENT and v.robot == robot
            ),
            key=lambda v: (v.action.allocation, v.action.subtask, v.action.waypoint),
        )
        assert [v.value for v in segments] == pytest.approx(
            [_driven(tr, a.start, a.end) for a in mine], abs=0.1
        )
        durations = sorted(
            (
                v
                for v in values
                if v.metric == "task_duration" and v.scope is MetricScope.SEGMENT and v.robot == robot
            ),
            key=lambda v: (v.action.allocation, v.action.subtask, v.action.waypoint),
        )
        assert [v.value for v in durations] == pytest.approx([a.end - a.start for a in mine], abs=0.03)
    a, b = truth.trajectories["tiago1"], truth.trajectories["tiago2"]
    assert _value(values, "distance_between_robots") == pytest.approx(
        np.hypot(a.x - b.x, a.y - b.y).min(), abs=0.03
    )
    assert _value(values, "violation_duration", safety="distance_between_robots") == 0.0
    assert [(t.robot, t.allocation, [x.goal_pose.id for x in t.actions]) for t in run.tasks] == [
        ("tiago1", 1, ["classroom_c022-w001", "classroom_c018-w001"]),
        ("tiago2", 1, ["classroom_c022-w002", "classroom_c018-w002"]),
        ("tiago1", 2, ["classroom_c025-w001"]),
        ("tiago2", 2, ["classroom_c025-w002"]),
    ]


def test_formats_give_the_same_metrics(scenario_c, runs_c) -> None:
    keyed = {}
    for fmt, sim in runs_c.items():
        run = analyse_bag(sim.bag, scenario_c).run
        keyed[fmt] = {(v.metric, v.robot, v.action, v.safety_metric): v.value for v in run.metrics}
    assert keyed["ros1"].keys() == keyed["ros2"].keys() == keyed["mcap"].keys()
    for key, value in keyed["ros1"].items():
        assert keyed["ros2"][key] == pytest.approx(value, abs=1e-6)
        assert keyed["mcap"][key] == pytest.approx(value, abs=1e-6)


def test_faults_move_their_metrics(scenario_c, tmp_path: Path) -> None:
    def run_with(*faults: str):
        [sim] = simulate(
            scenario_c, tmp_path / "-".join(faults), runs=1, seed=7, faults=[Fault.parse(f) for f in faults]
        )
        return analyse_bag(sim.bag, scenario_c).run

    fast = run_with("overspeed:tiago1")
    assert _value(fast.metrics, "max_velocity", "tiago1", MetricScope.ROBOT) > 1.0
    assert _value(fast.metrics, "violation_duration", "tiago1", safety="max_velocity") > 5.0
    assert _value(fast.metrics, "violation_duration", "tiago2", safety="max_velocity") == 0.0
    assert any(h.metric == "max_velocity" and h.robot == "tiago1" for h in fast.hotspots)
    skipped = run_with("skip-waypoint:tiago2:1")
    assert _value(skipped.metrics, "waypoints_visited", "tiago2") == 2
    near = run_with("near-collision")
    assert _value(near.metrics, "distance_between_robots") < 0.1
    assert _value(near.metrics, "violation_duration", safety="distance_between_robots") > 0.5
    assert any(h.metric == "distance_between_robots" for h in near.hotspots)


# ------------------------------------------------------------------ bad bags
def _rewrite(
    source: Path, target: Path, change: Callable[[str, str, int, bytes], list[tuple[str, str, int, bytes]]]
) -> Path:
    """Copy a ROS 1 bag, passing each message through ``change`` (which may drop or alter it)."""
    store = typestore("ros1")
    out: list[tuple[str, str, int, bytes]] = []
    with Ros1Reader(source) as reader:
        for conn, timestamp, raw in reader.messages():
            out.extend(change(conn.topic, conn.msgtype, timestamp, bytes(raw)))
    with Ros1Writer(target) as writer:
        conns = {}
        for topic, msgtype, timestamp, raw in out:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], timestamp, raw)
    return target


def _store_graphs(store: EmbeddedStore) -> set[str]:
    return {g for g in store.graph_names() if "/runs/" in g}


def test_a_truncated_bag_is_reported_and_nothing_is_written(scenario_c, runs_c, tmp_path: Path) -> None:
    good = runs_c["ros1"].bag
    broken = tmp_path / "broken.bag"
    broken.write_bytes(good.read_bytes()[: good.stat().st_size // 3])
    store = EmbeddedStore()
    results = ingest_bags([broken, good], scenario_c, store)
    assert results[0].failed and str(broken) in results[0].message
    assert results[1].status == "ingested", results[1].message
    graphs = _store_graphs(store)
    assert graphs and all(results[1].run_id in g or "run_" in g for g in graphs)
    again = ingest_bags([good], scenario_c, store)
    assert again[0].status == "skipped"
    assert _store_graphs(store) == graphs


def test_an_empty_bag_is_refused(scenario_c, tmp_path: Path) -> None:
    empty = tmp_path / "empty.bag"
    with Ros1Writer(empty):
        pass
    with pytest.raises(BagError, match="holds no messages"):
        analyse_bag(empty, scenario_c)
    store = EmbeddedStore()
    [result] = ingest_bags([empty], scenario_c, store)
    assert result.failed and "empty.bag" in result.message
    assert _store_graphs(store) == set()


def test_a_missing_topic_makes_its_metrics_missing_not_zero(scenario_c, runs_c, tmp_path: Path) -> None:
    bag = _rewrite(
        runs_c["ros1"].bag,
        tmp_path / "noscan.bag",
        lambda topic, msgtype, t, raw: [] if topic == "/tiago2/scan" else [(topic, msgtype, t, raw)],
    )
    analysed = analyse_bag(bag, scenario_c)
    metrics = {(v.metric, v.robot, v.safety_metric) for v in analysed.run.metrics}
    assert ("distance_to_obstacles", "tiago1", None) in metrics
    assert ("distance_to_obstacles", "tiago2", None) not in metrics
    assert not any(
        v.metric == "distance_to_obstacles" and v.action and v.action.robot == "tiago2"
        for v in analysed.run.metrics
    )
    assert any("/tiago2/scan is missing" in p for p in analysed.problems)


def test_a_bag_of_another_scenario_is_refused(tmp_path: Path) -> None:
    scenario_d = load_spec(BUILDING / "scenario_d.exsce").scenario()
    scenario_e = load_spec(BUILDING / "scenario_e.exsce").scenario()
    [sim] = simulate(scenario_d, tmp_path, runs=1, seed=1)
    with pytest.raises(SegmentError, match="another scenario"):
        analyse_bag(sim.bag, scenario_e)
    store = EmbeddedStore()
    [result] = ingest_bags([sim.bag], scenario_e, store)
    assert result.failed and "another scenario" in result.message and sim.bag.name in result.message
    assert _store_graphs(store) == set()


def test_bad_laser_readings_are_ignored(scenario_c, runs_c, tmp_path: Path) -> None:
    rng = np.random.default_rng(0)

    def spoil(topic: str, msgtype: str, t: int, raw: bytes):
        if not topic.endswith("/scan"):
            return [(topic, msgtype, t, raw)]
        data = bytearray(raw)
        # the ranges start after header (16 + frame id) and 7 float32 fields and the count
        at = 16 + int.from_bytes(raw[12:16], "little") + 28 + 4
        ranges = np.frombuffer(bytes(data[at : at + 720 * 4]), dtype="<f4").copy()
        spoilt = rng.choice(720, 40, replace=False)
        ranges[spoilt[:10]] = np.nan
        ranges[spoilt[10:20]] = np.inf
        ranges[spoilt[20:30]] = 0.001  # below range_min
        ranges[spoilt[30:]] = 99.0  # above range_max
        data[at : at + 720 * 4] = ranges.tobytes()
        return [(topic, msgtype, t, bytes(data))]

    spoilt = analyse_bag(_rewrite(runs_c["ros1"].bag, tmp_path / "spoilt.bag", spoil), scenario_c).run
    clean = analyse_bag(runs_c["ros1"].bag, scenario_c).run
    for robot in ("tiago1", "tiago2"):
        measured = _value(spoilt.metrics, "distance_to_obstacles", robot, MetricScope.ROBOT)
        assert math.isfinite(measured) and measured >= 0.05
        assert measured >= _value(clean.metrics, "distance_to_obstacles", robot, MetricScope.ROBOT) - 1e-6


def test_out_of_order_messages_give_the_same_metrics(scenario_c, runs_c, tmp_path: Path) -> None:
    messages: list[tuple[str, str, int, bytes]] = []

    def keep(topic: str, msgtype: str, t: int, raw: bytes):
        messages.append((topic, msgtype, t, raw))
        return []

    _rewrite(runs_c["ros1"].bag, tmp_path / "scratch.bag", keep)
    order = np.random.default_rng(1).permutation(len(messages))
    shuffled = iter([messages[i] for i in order])
    bag = _rewrite(runs_c["ros1"].bag, tmp_path / "shuffled.bag", lambda *_: [next(shuffled)])
    a = analyse_bag(runs_c["ros1"].bag, scenario_c).run
    b = analyse_bag(bag, scenario_c).run
    assert {(v.metric, v.robot, v.action, v.safety_metric): round(v.value, 9) for v in a.metrics} == {
        (v.metric, v.robot, v.action, v.safety_metric): round(v.value, 9) for v in b.metrics
    }


def test_a_topic_of_an_unexpected_type_is_reported(scenario_c, runs_c, tmp_path: Path) -> None:
    from exsce_dsl.sim.messages import typestore as types

    store = types("ros1")
    text = store.serialize_ros1(store.types["std_msgs/msg/String"](data="go"), "std_msgs/msg/String")

    def retype(topic: str, msgtype: str, t: int, raw: bytes):
        if topic == "/tiago1/nav_vel":
            return [(topic, "std_msgs/msg/String", t, bytes(text))]
        return [(topic, msgtype, t, raw)]

    analysed = analyse_bag(_rewrite(runs_c["ros1"].bag, tmp_path / "retyped.bag", retype), scenario_c)
    # no velocity to read: tiago1's speed is estimated from its pose, and the value says so
    estimated = [v for v in analysed.run.metrics if v.metric == "max_velocity" and v.robot == "tiago1"]
    assert estimated and all(v.estimated_from == "pose" for v in estimated)
    assert all(v.topics == ("/tiago1/robot_pose",) for v in estimated)
    assert any("/tiago1/nav_vel, which carries std_msgs/msg/String" in p for p in analysed.problems), analysed.problems


def test_statuses_in_the_bag_are_the_executors(runs_c) -> None:
    assert all(a.status is GoalStatus.SUCCEEDED for a in runs_c["ros1"].execution.actions)


def test_bags_analysed_in_parallel_give_the_same_runs(scenario_c, runs_c, tmp_path: Path) -> None:
    [other] = simulate(scenario_c, tmp_path, runs=1, seed=8)
    broken = tmp_path / "broken.bag"
    broken.write_bytes(runs_c["ros1"].bag.read_bytes()[:5000])
    bags = [runs_c["ros1"].bag, other.bag, runs_c["ros1"].bag, broken, tmp_path / "missing.bag"]
    serial = ingest_bags(bags, scenario_c, EmbeddedStore())
    parallel = ingest_bags(bags, scenario_c, EmbeddedStore(), jobs=2)
    assert sorted(r.status for r in parallel) == ["failed", "failed", "ingested", "ingested", "skipped"]
    assert [(r.bag, r.status, r.run_id, r.statements) for r in parallel] == [
        (r.bag, r.status, r.run_id, r.statements) for r in serial
    ]
