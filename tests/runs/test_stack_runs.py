"""Ingesting runs of Nav2 and move_base robots: the built-in metrics from their own topics, path
segments from their goals, from arrival, or none.

The reference is the same run (same scenario, same seed: the same trajectories)
written in the method's convention and ingested as before: the metrics must agree
within what the conventions' different sensors explain (localisation noise in the
pose, status arrays recorded once a second besides each change).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.prov.serialize import serialize_prov
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.bags.reading import bag_topics
from exsce_dsl.sim.run import simulate

from tests.support.yard_spec import yard_text


def _scenario(tmp_path: Path, robot_type: str, name: str) -> Scenario:
    path = tmp_path / f"{name}.exsce"
    path.write_text(yard_text(robot_type))
    return load_spec(path).scenario()


def _run(tmp_path: Path, robot_type: str, fmt: str, convention: str) -> AnalysedRun:
    scenario = _scenario(tmp_path, robot_type, f"{convention}-{fmt}")
    (run,) = simulate(scenario, tmp_path / f"bags-{convention}-{fmt}", fmt=fmt, seed=5, convention=convention)
    return analyse_bag(run.bag, scenario)


def _values(analysed: AnalysedRun) -> dict[tuple[str, str, str], float]:
    found = {}
    for v in analysed.run.metrics:
        where = str(v.action) if v.action is not None else v.robot or "mission"
        found[(v.metric, where, v.scope.value)] = v.value
    return found


@pytest.fixture(scope="module")
def method_run(tmp_path_factory: pytest.TempPathFactory) -> AnalysedRun:
    return _run(tmp_path_factory.mktemp("method"), "torso no", "ros1", "method")


TOLERANCES = {
    "distance_travelled": (0.15, 0.03),  # m, and relative: localisation noise along the path
    "max_velocity": (0.0, 0.02),  # cmd_vel is the command the method's nav_vel records too
    "task_duration": (1.05, 0.0),  # s: goal statuses stamped on change; arrival within the tolerance
    "mission_duration": (1.05, 0.0),
    "waypoints_visited": (0.0, 0.0),
    "distance_to_obstacles": (0.0, 0.01),  # scans of the same places, their noise drawn in another order
    "distance_between_robots": (0.15, 0.0),  # two localisation noises
}


def _agree(ours: dict[tuple[str, str, str], float], reference: dict[tuple[str, str, str], float]) -> None:
    compared = 0
    for key, expected in reference.items():
        if key[0] not in TOLERANCES:
            continue
        absolute, relative = TOLERANCES[key[0]]
        assert key in ours, f"{key} is missing"
        assert ours[key] == pytest.approx(expected, abs=absolute + relative * abs(expected)), key
        compared += 1
    assert compared >= 15


@pytest.mark.parametrize("fmt", ["ros1", "ros2", "mcap"])
@pytest.mark.parametrize("convention", ["nav2", "move_base"])
def test_a_stacks_run_has_the_methods_metrics(
    tmp_path: Path, method_run: AnalysedRun, fmt: str, convention: str
) -> None:
    analysed = _run(tmp_path, f"convention {convention}", fmt, convention)
    assert not [p for p in analysed.problems if "missing" in p], analysed.problems
    _agree(_values(analysed), _values(method_run))
    sources = {v.metric: v.topics for v in analysed.run.metrics if v.robot == "r2"}
    assert sources["max_velocity"] == ("/r2/cmd_vel",)  # the topics the values came from
    assert sources["distance_travelled"] == ("/r2/odom",)  # the wheel odometry: no localisation jitter
    mission = {v.metric: v.topics for v in analysed.run.metrics if v.robot is None and v.action is None}
    assert mission["distance_between_robots"] == ("/tf", "/tf_static", "/r2/tf", "/r2/tf_static")
    goals = "/r2/navigate_to_pose/_action/status" if convention == "nav2" else "/r2/move_base/status"
    assert goals in sources["task_duration"]


def test_without_goals_a_run_is_segmented_by_arrival(tmp_path: Path, method_run: AnalysedRun) -> None:
    analysed = _run(tmp_path, "convention nav2\nnavigation none", "ros1", "nav2")
    ours, reference = _values(analysed), _values(method_run)
    segments = [k for k in reference if k[0] == "task_duration" and k[2] == "segment"]
    assert len(segments) == 3 and all(k in ours for k in segments)
    # a segment ends on arrival within 0.35 m, before the goal's success (0.35 m at the ~0.3 m/s of
    # the approach: ~1.2 s), and the first starts when the robot first moves, not when its goal does
    for key in segments:
        assert abs(reference[key] - ours[key]) <= 2.0, (key, reference[key], ours[key])
    assert ours[("waypoints_visited", "r1", "robot")] == 2


def test_without_goals_or_a_pose_a_run_has_whole_run_metrics_and_says_why(tmp_path: Path) -> None:
    robot_type = 'convention nav2\npose on "/{ns}/ground_truth"\nnavigation none'
    analysed = _run(tmp_path, robot_type, "ros1", "nav2")
    ours = _values(analysed)
    assert ("max_velocity", "r2", "robot") in ours
    assert not any(k[2] == "segment" for k in ours)
    said = " ".join(analysed.problems)
    assert "robot 'r2' has no pose in this bag (looked for /r2/ground_truth)" in said
    assert "robot 'r2': no path segments" in said and "whole run only" in said


def test_the_executor_writes_the_convention_the_robot_types_name(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, "convention move_base", "named")
    (run,) = simulate(scenario, tmp_path / "bags", seed=5)  # no convention given
    topics = bag_topics(run.bag)
    assert topics["/r2/move_base/status"] == "actionlib_msgs/msg/GoalStatusArray"
    assert "/r2/robot_pose" not in topics


def test_robots_of_two_conventions_need_one_chosen(tmp_path: Path) -> None:
    text = (
        yard_text("convention nav2").replace("r2: rover starts", "r2: plain starts")
        + "\nrobot type plain {\n  torso no\n}\n"
    )
    path = tmp_path / "mixed.exsce"
    path.write_text(text)
    scenario = load_spec(path).scenario()
    with pytest.raises(ExsceError, match=r"different conventions \(r1: nav2, r2: method\).*choose it"):
        list(simulate(scenario, tmp_path / "bags"))
    (run,) = simulate(scenario, tmp_path / "bags", convention="method")
    assert "/r2/robot_pose" in bag_topics(run.bag)


def test_a_tf_chain_the_bag_cannot_compose_is_said_with_the_frames_it_has(tmp_path: Path) -> None:
    analysed = _run(tmp_path, "convention nav2\npose from tf map -> base_footprint_typo", "ros1", "nav2")
    said = "\n".join(analysed.problems)
    assert "robot 'r2': no pose from TF on /r2/tf: no frame 'base_footprint_typo'" in said, said
    assert "did you mean 'base_footprint'" in said
    values = _values(analysed)
    assert ("max_velocity", "r2", "robot") in values  # what does not need the pose is there
    assert ("distance_between_robots", "mission", "mission") not in values


def test_the_runs_prov_says_what_segmented_it(tmp_path: Path) -> None:
    analysed = _run(tmp_path, "convention nav2", "mcap", "nav2")
    assert {t.segmented_by for t in analysed.run.tasks} == {"nav2 goals"}
    scenario = _scenario(tmp_path, "convention nav2", "prov")
    provn = serialize_prov(compile_run(analysed.run, scenario), "provn")
    assert provn.count('exsce:segmented_by="nav2 goals"') == len(analysed.run.tasks) == 2
    arrival = _run(tmp_path, "convention nav2\nnavigation none", "ros1", "nav2")
    assert {t.segmented_by for t in arrival.run.tasks} == {"arrival at the planned waypoints"}


def test_one_robot_may_say_otherwise_than_its_type(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, "convention nav2", "override")
    path = tmp_path / "override.exsce"
    path.write_text(
        path.read_text().replace(
            "r2: rover starts at yard-d", "r2: rover starts at yard-d { navigation none }"
        )
    )
    scenario = load_spec(path).scenario()
    (run,) = simulate(scenario, tmp_path / "bags", fmt="ros1", seed=5)
    analysed = analyse_bag(run.bag, scenario)
    by = {t.robot: t.segmented_by for t in analysed.run.tasks}
    assert by == {"r1": "nav2 goals", "r2": "arrival at the planned waypoints"}


def test_a_bag_without_the_navigation_topics_is_segmented_by_arrival(tmp_path: Path) -> None:
    """The robot type expects move_base's goals, the bag (Nav2's) has none of them: arrival."""
    analysed = _run(tmp_path, "convention nav2\nnavigation move_base", "ros1", "nav2")
    assert {t.segmented_by for t in analysed.run.tasks} == {"arrival at the planned waypoints"}
    assert "robot 'r2': no move_base goals in this bag" in analysed.problems
    assert _values(analysed)[("waypoints_visited", "r2", "robot")] == 1


SIGNAL_METRICS = """
metric furthest_east for each robot {
  "the largest x the robot reached"
  unit m
  reads pose: robot pose
  value max(pose.x)
}

metric fastest_turn for each robot {
  "the fastest turn commanded"
  unit rad/s
  reads vel: robot velocity
  value max(norm(vel.angular.z))
}
"""


def _signal_run(tmp_path: Path, robot_type: str, convention: str) -> AnalysedRun:
    path = tmp_path / f"signals-{convention}.exsce"
    path.write_text(yard_text(robot_type) + SIGNAL_METRICS)
    scenario = load_spec(path).scenario()
    (run,) = simulate(scenario, tmp_path / f"bags-{convention}", fmt="ros1", seed=5)
    return analyse_bag(run.bag, scenario)


def test_a_metric_reads_a_robots_signal_wherever_its_type_says_it_is(tmp_path: Path) -> None:
    method = _signal_run(tmp_path, "torso no", "method")
    nav2 = _signal_run(tmp_path, "convention nav2", "nav2")
    ours, theirs = _values(nav2), _values(method)
    for robot in ("r1", "r2"):
        assert ours[("furthest_east", robot, "robot")] == pytest.approx(
            theirs[("furthest_east", robot, "robot")], abs=0.15
        )
        assert ours[("fastest_turn", robot, "robot")] == pytest.approx(
            theirs[("fastest_turn", robot, "robot")], rel=0.02
        )
    (bag,) = (tmp_path / "bags-method").glob("*.bag")  # the reference: rosbags' own reading
    store = get_typestore(Stores.ROS1_NOETIC)
    with AnyReader([bag], default_typestore=store) as reader:
        poses = [c for c in reader.connections if c.topic == "/r2/robot_pose"]
        samples = [
            (t / 1e9, reader.deserialize(raw, c.msgtype).pose.pose.position.x)
            for c, t, raw in reader.messages(poses)
        ]
    actions = [a for task in method.run.tasks if task.robot == "r2" for a in task.actions]
    begin, end = min(a.start for a in actions).timestamp(), max(a.end for a in actions).timestamp()
    inside = [x for t, x in samples if begin <= t <= end]
    assert theirs[("furthest_east", "r2", "robot")] == pytest.approx(max(inside), abs=1e-9)
    sources = {v.metric: v.topics for v in nav2.run.metrics if v.robot == "r2"}
    assert sources["furthest_east"] == ("/r2/tf", "/r2/tf_static")
    assert sources["fastest_turn"] == ("/r2/cmd_vel",)
    method_sources = {v.metric: v.topics for v in method.run.metrics if v.robot == "r2"}
    assert method_sources["furthest_east"] == ("/r2/robot_pose",)


SCAN_METRIC = """
metric nearest_obstacle for each robot per segment {
  "least laser range, read from the robot's scan signal"
  unit m
  reads laser: robot scan
  value min(laser.ranges where laser.ranges >= laser.range_min and laser.ranges <= laser.range_max)
}
"""


@pytest.mark.parametrize("robot_type, convention", [("torso no", "method"), ("convention nav2", "nav2")])
def test_a_metric_reads_a_robots_scan_signal(tmp_path: Path, robot_type: str, convention: str) -> None:
    """``reads laser: robot scan`` reads the scan the robot's convention says, wherever it is: its
    values are the built-in distance_to_obstacles' (which reads the same scan), from the same topic."""
    path = tmp_path / "scan.exsce"
    path.write_text(yard_text(robot_type) + SCAN_METRIC)
    scenario = load_spec(path).scenario()
    (run,) = simulate(scenario, tmp_path / "bags", fmt="ros1", seed=5, convention=convention)
    analysed = analyse_bag(run.bag, scenario)
    values = _values(analysed)
    compared = [
        (value, values[("distance_to_obstacles", *key[1:])])
        for key, value in values.items()
        if key[0] == "nearest_obstacle"
    ]
    assert len(compared) >= 4
    assert all(ours == builtin for ours, builtin in compared)
    sources = {v.metric: v.topics for v in analysed.run.metrics if v.robot == "r2"}
    assert sources["nearest_obstacle"] == sources["distance_to_obstacles"] == ("/r2/scan",)
