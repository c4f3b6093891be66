"""The kinematic executor and the bags it writes (real bags, read back with rosbags)."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import MissionType
from exsce_dsl.sim.executor import Fault, GoalStatus, execute
from exsce_dsl.sim.messages import FEEDBACK, RESULT, typestore
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(BUILDING / "scenario_c.exsce").scenario()


@pytest.fixture(scope="module")
def scenario_d():
    return load_spec(BUILDING / "scenario_d.exsce").scenario()


def _digest(bag: Path) -> list[str]:
    files = [bag] if bag.is_file() else sorted(bag.iterdir())
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]


def test_paths_stay_in_free_space_and_reach_every_waypoint(scenario_c) -> None:
    grid = planning_grid(scenario_c)
    execution = execute(scenario_c, grid, seed=1)
    for robot, tr in execution.trajectories.items():
        clearance = grid.clearance_at(np.column_stack([tr.x, tr.y]))
        assert clearance.min() > 0.25, robot  # the robot's radius is 0.3 m; walls stay clear of its centre
    assert [a.status for a in execution.actions] == [GoalStatus.SUCCEEDED] * 6
    for action in execution.actions:
        tr = execution.trajectories[action.robot]
        k = int(round(action.end / 0.02))
        assert math.dist((tr.x[k], tr.y[k]), (action.goal.position.x, action.goal.position.y)) < 0.05


def test_distances_are_those_of_the_building(scenario_c) -> None:
    """The method's baseline distances for scenario_c (50.70 m, 59.53 m) came from real TIAGo runs."""
    execution = execute(scenario_c, planning_grid(scenario_c), seed=1)
    travelled = {
        r: sum(a.path_length for a in execution.actions if a.robot == r) for r in ("tiago1", "tiago2")
    }
    assert travelled["tiago1"] == pytest.approx(50.70, rel=0.05)
    assert travelled["tiago2"] == pytest.approx(59.53, rel=0.05)


def test_speed_and_acceleration_are_bounded(scenario_c) -> None:
    execution = execute(scenario_c, planning_grid(scenario_c), seed=2)
    for tr in execution.trajectories.values():
        assert np.abs(tr.v).max() <= 0.6 + 1e-9
        assert (
            np.abs(np.diff(tr.v) / 0.02).max() <= 1.0
        )  # 0.5 m/s² as planned; giving way ramps within 1 m/s²


def test_parallel_robots_keep_apart(scenario_c) -> None:
    for seed in (1, 2, 3):
        tr = execute(scenario_c, planning_grid(scenario_c), seed=seed).trajectories
        gap = np.hypot(tr["tiago1"].x - tr["tiago2"].x, tr["tiago1"].y - tr["tiago2"].y)
        # robots of 0.3 m radius give way and back up; one parked at its last waypoint beside
        # another's path is passed closely after 10 s (the executor does not re-plan around robots)
        assert gap.min() > 0.45


def test_a_sequential_mission_runs_one_task_at_a_time(in_tmp: Path) -> None:
    scenario = load_spec(BUILDING / "scenario_a.exsce").scenario()
    assert scenario.mission.type is MissionType.SEQUENTIAL
    execution = execute(scenario, planning_grid(scenario), seed=1)
    spans = {}
    for a in execution.actions:
        key = (a.robot, a.task_number)
        start, end = spans.get(key, (a.start, a.end))
        spans[key] = (min(start, a.start), max(end, a.end))
    ordered = sorted(spans.values())
    assert all(prev[1] <= nxt[0] for prev, nxt in zip(ordered, ordered[1:], strict=False))


def test_same_seed_same_bytes_in_every_format(scenario_d, tmp_path: Path) -> None:
    for fmt in ("ros1", "ros2", "mcap"):
        [a] = simulate(scenario_d, tmp_path / f"a-{fmt}", runs=1, fmt=fmt, seed=4)
        [b] = simulate(scenario_d, tmp_path / f"b-{fmt}", runs=1, fmt=fmt, seed=4)
        assert a.bag.name == b.bag.name
        assert _digest(a.bag) == _digest(b.bag)
    [c] = simulate(scenario_d, tmp_path / "c", runs=1, fmt="ros1", seed=5)
    assert _digest(c.bag) != _digest(a.bag)


@pytest.mark.parametrize("fmt", ["ros1", "ros2", "mcap"])
def test_bags_read_back_with_the_dispatcher_statuses(scenario_d, tmp_path: Path, fmt: str) -> None:
    [run] = simulate(scenario_d, tmp_path, runs=1, fmt=fmt, seed=1)
    assert run.bag.name.endswith(f"_scenario_d_run-{run.run_id[:8]}" + (".bag" if fmt == "ros1" else ""))
    with AnyReader([run.bag], default_typestore=typestore(fmt)) as reader:
        topics = {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
        assert topics["/tiago1/robot_pose"][0] == "geometry_msgs/msg/PoseWithCovarianceStamped"
        assert topics["/tiago1/scan"][0] == "sensor_msgs/msg/LaserScan"
        assert topics["/tiago1/nav_vel"][0] == "geometry_msgs/msg/Twist"
        assert topics["/tiago1/distance_travelled"][0] == "std_msgs/msg/Float64"
        assert topics["/tiago1/waypoint_dispatcher/feedback"][0] == FEEDBACK
        assert topics["/tiago1/waypoint_dispatcher/result"][0] == RESULT
        duration = run.execution.duration
        assert topics["/tiago1/robot_pose"][1] == pytest.approx(duration * 50, abs=2)
        # scenario_d: delivery_a, delivery_b, navigate_home_1 = 3 goals of 2, 2, 1 waypoints
        assert topics["/tiago1/waypoint_dispatcher/result"][1] == 3
        feedback = [c for c in reader.connections if c.topic.endswith("feedback")]
        seen = []
        for conn, _, raw in reader.messages(connections=feedback):
            msg = reader.deserialize(raw, conn.msgtype)
            seen.append(tuple((s.goal_id.id, s.status) for s in msg.feedback.goal_status.status_list))
    assert seen[:4] == [
        (("classroom_c022-w001", 0), ("classroom_c018-w001", 0)),
        (("classroom_c022-w001", 1), ("classroom_c018-w001", 0)),
        (("classroom_c022-w001", 3), ("classroom_c018-w001", 0)),
        (("classroom_c022-w001", 3), ("classroom_c018-w001", 1)),
    ]
    assert seen[-1] == (("classroom_c025-w001", 3),)


def test_scans_see_walls_at_their_distance(scenario_d, tmp_path: Path) -> None:
    [run] = simulate(scenario_d, tmp_path, runs=1, seed=1)
    grid = planning_grid(scenario_d)
    tr = run.execution.trajectories["tiago1"]
    with AnyReader([run.bag], default_typestore=typestore("ros1")) as reader:
        scans = [c for c in reader.connections if c.topic == "/tiago1/scan"]
        mins = []
        for conn, _, raw in reader.messages(connections=scans):
            msg = reader.deserialize(raw, conn.msgtype)
            assert len(msg.ranges) == 720
            mins.append(float(np.min(msg.ranges)))
    clearance = grid.clearance_at(np.column_stack([tr.x[::5], tr.y[::5]]))[: len(mins)]
    # no return is nearer than the nearest wall (within a cell and the range noise), and when the
    # nearest wall is in the laser's 270° field of view, that is what it sees
    assert np.all(np.asarray(mins) > clearance - 0.12)
    assert np.mean(np.abs(np.asarray(mins) - clearance) < 0.12) > 0.6


def test_faults_change_what_they_should(scenario_c) -> None:
    grid = planning_grid(scenario_c)
    plain = execute(scenario_c, grid, seed=1)
    fast = execute(scenario_c, grid, seed=1, faults=(Fault.parse("overspeed:tiago1"),))
    assert np.abs(fast.trajectories["tiago1"].v).max() > 1.0
    assert np.abs(fast.trajectories["tiago2"].v).max() < 0.61
    slow = execute(scenario_c, grid, seed=1, faults=(Fault.parse("slow:tiago2"),))

    def driving_time(execution, robot):
        return sum(a.end - a.start for a in execution.actions if a.robot == robot)

    assert (
        np.abs(slow.trajectories["tiago2"].v).max()
        <= 0.3 + 1e-9
        < np.abs(plain.trajectories["tiago2"].v).max()
    )
    assert driving_time(slow, "tiago2") > 1.3 * driving_time(plain, "tiago2")
    skipped = execute(scenario_c, grid, seed=1, faults=(Fault.parse("skip-waypoint:tiago1:2"),))
    statuses = [(a.robot, a.goal.id, a.status) for a in skipped.actions if a.robot == "tiago1"]
    assert statuses[1] == ("tiago1", "classroom_c018-w001", GoalStatus.ABORTED)
    near = execute(scenario_c, grid, seed=1, faults=(Fault.parse("near-collision"),)).trajectories
    gap = np.hypot(near["tiago1"].x - near["tiago2"].x, near["tiago1"].y - near["tiago2"].y)
    assert gap.min() < 0.1


def test_bad_faults_are_refused(scenario_c) -> None:
    with pytest.raises(ExsceError, match="unknown fault 'teleport'"):
        Fault.parse("teleport:tiago1")
    with pytest.raises(ExsceError, match="needs a robot"):
        Fault.parse("overspeed")
    with pytest.raises(ExsceError, match="not in scenario_c"):
        execute(scenario_c, planning_grid(scenario_c), seed=1, faults=(Fault.parse("slow:tiago9"),))


def test_a_scenario_without_a_map_runs_in_open_space(tmp_path: Path) -> None:
    scenario = load_spec(EXAMPLES / "drones" / "orchard.exsce").scenario()
    execution = execute(scenario, planning_grid(scenario), seed=1)
    for a in execution.actions:
        assert a.path_length == pytest.approx(
            a.start_pose.position.distance_to(a.goal.position)
            if a.start_pose.position.z == a.goal.position.z
            else a.path_length,
            rel=0.05,
        )
    assert all(a.status is GoalStatus.SUCCEEDED for a in execution.actions)


def test_the_recorders_provenance_is_written_beside_the_bag(scenario_d, tmp_path: Path) -> None:
    import prov.model as pm

    [run] = simulate(scenario_d, tmp_path, runs=1, seed=2)
    record = tmp_path / (run.bag.name.removesuffix(".bag") + ".prov.json")
    document = pm.ProvDocument.deserialize(str(record))
    text = document.get_provn()
    assert f"activity(run:run_{run.run_id}," in text
    # scenario_d: tiago1 does delivery_a (2 waypoints), delivery_b (2), navigate_home_1 (1)
    assert text.count("prov:type='exsce:action'") == 5
    assert "wasEndedBy(run_" in text and "pose:classroom_c025-w001-R0.00_P0.00_Y0.925" in text


def test_any_seed_gives_a_bag_with_valid_stamps(tmp_path):
    """Seed 100001 once started in the year 2300, past what a nanosecond stamp (and ROS 1 time) holds."""
    from exsce_dsl.lang import load_spec
    from exsce_dsl.model.messages import path_of
    from exsce_dsl.runs.bags.data import Wanted
    from exsce_dsl.runs.bags.reading import read_bag
    from exsce_dsl.sim.run import EPOCH, simulate

    scenario = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")
    (run,) = simulate(scenario, tmp_path, 1, seed=100_001)
    data = read_bag(run.bag, {"/tiago1/nav_vel": Wanted("geometry_msgs/msg/Twist", (path_of("linear", "x"),))})
    assert EPOCH.timestamp() <= data.start < 2**32 and run.start.year < 2106
