"""A robot's signals from wherever its convention puts them (runs/signals.py), on executor bags
of Nav2 and move_base robots.

Reference values come from rosbags' own deserialisation of the same bags: a
topic's values field by field, and a TF pose composed here by hand from 4×4
matrices of the recorded transforms, at stamps where the transforms it chains
were both recorded (no interpolation on the reference's side).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.signals.sources import (
    RobotSources,
    choose_sources,
    signal_topic,
    signal_topics,
    signals_wanted,
)
from exsce_dsl.runs.signals.trajectories import trajectories
from exsce_dsl.sim.run import simulate

from tests.support.yard_spec import yard_text


def _scenario(tmp_path: Path, robot_type: str) -> Scenario:
    path = tmp_path / "yard.exsce"
    path.write_text(yard_text(robot_type))
    return load_spec(path).scenario()


def _bag(tmp_path: Path, scenario: Scenario, fmt: str, convention: str, stamped: bool = False) -> Path:
    (run,) = simulate(
        scenario, tmp_path / "bags", fmt=fmt, seed=5, convention=convention, twist_stamped=stamped
    )
    return run.bag


def _sources(scenario: Scenario, bag: Path) -> list[RobotSources]:
    available = bag_topics(bag)
    return [choose_sources(robot, available) for robot in scenario.robots]


def _signals(scenario: Scenario, bag: Path) -> tuple[list[RobotSources], dict[str, Any]]:
    sources = _sources(scenario, bag)
    data = read_bag(bag, signals_wanted(sources, []))
    topics: dict[str, Any] = {}
    for robot in sources:
        topics.update(signal_topics(robot, data))
    return sources, topics


def _messages(bag: Path, topic: str) -> list[tuple[int, Any]]:
    store = get_typestore(Stores.ROS2_HUMBLE if bag.is_dir() else Stores.ROS1_NOETIC)
    with AnyReader([bag], default_typestore=store) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return [
            (t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages(connections=connections)
        ]


def _matrix(transform: Any) -> np.ndarray:
    q, p = transform.rotation, transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    rotation = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, (p.x, p.y, p.z)
    return matrix


def _stamp(header: Any) -> float:
    return header.stamp.sec + header.stamp.nanosec * 1e-9


def _tf_reference(bag: Path, tf_topic: str) -> dict[float, np.ndarray]:
    """base_link in map at every stamp where map→odom and odom→base_link were both recorded."""
    edges: dict[tuple[str, str], dict[float, np.ndarray]] = {}
    for _, message in _messages(bag, tf_topic):
        for t in message.transforms:
            key = (t.header.frame_id, t.child_frame_id)
            edges.setdefault(key, {})[round(_stamp(t.header), 6)] = _matrix(t.transform)
    upper, lower = edges[("map", "odom")], edges[("odom", "base_link")]
    return {stamp: upper[stamp] @ lower[stamp] for stamp in sorted(set(upper) & set(lower))}


@pytest.mark.parametrize("fmt, convention", [("ros1", "nav2"), ("mcap", "nav2"), ("ros2", "move_base")])
def test_the_pose_from_tf_is_the_chain_map_odom_base_link(tmp_path: Path, fmt: str, convention: str) -> None:
    scenario = _scenario(tmp_path, f"convention {convention}")
    bag = _bag(tmp_path, scenario, fmt, convention)
    sources, topics = _signals(scenario, bag)
    for robot, tf_topic in zip(sources, ["/tf", "/r2/tf"], strict=True):
        chosen = robot.chosen["pose"]
        assert chosen.tf is not None and chosen.topics[0] == tf_topic  # TF first, and it is there
        pose = topics[signal_topic("pose", robot.namespace)]
        reference = _tf_reference(bag, tf_topic)
        assert len(reference) > 20
        at = {round(float(t), 6): i for i, t in enumerate(pose.t)}
        checked = 0
        for stamp, matrix in reference.items():
            if stamp not in at:
                continue
            i = at[stamp]
            assert pose.fields["x"][i] == pytest.approx(matrix[0, 3], abs=1e-9)
            assert pose.fields["y"][i] == pytest.approx(matrix[1, 3], abs=1e-9)
            yaw = math.atan2(matrix[1, 0], matrix[0, 0])
            assert math.remainder(pose.fields["yaw"][i] - yaw, math.tau) == pytest.approx(0.0, abs=1e-9)
            checked += 1
        assert checked >= 0.9 * len(reference)


@pytest.mark.parametrize("fmt", ["ros1", "ros2"])
def test_a_pose_topic_and_a_stamped_velocity_read_as_rosbags_reads_them(tmp_path: Path, fmt: str) -> None:
    scenario = _scenario(tmp_path, 'convention nav2\npose on "/{ns}/odom"')
    bag = _bag(tmp_path, scenario, fmt, "nav2", stamped=True)
    sources, topics = _signals(scenario, bag)
    r2 = next(s for s in sources if s.robot == "r2")
    assert (r2.chosen["pose"].topic, r2.chosen["pose"].msgtype) == ("/r2/odom", "nav_msgs/msg/Odometry")
    assert r2.chosen["velocity"].msgtype == "geometry_msgs/msg/TwistStamped"
    pose = topics[signal_topic("pose", "r2")]
    odometry = [m.pose.pose for _, m in _messages(bag, "/r2/odom")]
    np.testing.assert_array_equal(pose.fields["x"], [p.position.x for p in odometry])
    np.testing.assert_array_equal(pose.fields["y"], [p.position.y for p in odometry])
    yaw = [
        math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        for q in (p.orientation for p in odometry)
    ]
    np.testing.assert_allclose(pose.fields["yaw"], yaw, atol=1e-12)
    velocity = topics[signal_topic("velocity", "r2")]
    commands = [m.twist for _, m in _messages(bag, "/r2/cmd_vel")]
    np.testing.assert_array_equal(velocity.fields["linear.x"], [c.linear.x for c in commands])
    np.testing.assert_array_equal(velocity.fields["angular.z"], [c.angular.z for c in commands])
    times = [t / 1e9 for t, _ in _messages(bag, "/r2/cmd_vel")]
    np.testing.assert_allclose(velocity.t, times)


def test_the_method_convention_reads_the_methods_topics(tmp_path: Path) -> None:
    scenario = _scenario(tmp_path, "torso no")  # a robot type that says nothing: the method's
    bag = _bag(tmp_path, scenario, "ros1", "method")
    sources, topics = _signals(scenario, bag)
    chosen = {s: c.topics for s, c in next(r for r in sources if r.robot == "r2").chosen.items()}
    assert chosen == {
        "pose": ("/r2/robot_pose",),
        "velocity": ("/r2/nav_vel",),
        "scan": ("/r2/scan",),
        "distance": ("/r2/distance_travelled",),
    }
    poses = [m.pose.pose.position.x for _, m in _messages(bag, "/r2/robot_pose")]
    np.testing.assert_array_equal(topics[signal_topic("pose", "r2")].fields["x"], poses)


def test_a_signal_the_bag_lacks_is_said_and_not_made_up(tmp_path: Path) -> None:
    scenario = _scenario(
        tmp_path, 'convention nav2\npose on "/{ns}/ground_truth"\nscan on "/{ns}/front_scan"'
    )
    bag = _bag(tmp_path, scenario, "ros1", "nav2")
    sources, topics = _signals(scenario, bag)
    r2 = next(s for s in sources if s.robot == "r2")
    assert set(r2.chosen) == {"velocity", "distance"}  # from cmd_vel and odom; the others are not in the bag
    assert r2.notes == (
        "robot 'r2' has no pose in this bag (looked for /r2/ground_truth)",
        "robot 'r2' has no scan in this bag (looked for /r2/front_scan)",
    )
    assert signal_topic("pose", "r2") not in topics and signal_topic("pose", "") not in topics


def test_the_reports_paths_are_in_the_map_frame_whatever_the_convention(tmp_path: Path) -> None:
    """A Nav2 bag's paths come from TF map -> base_link, not from the drifting odometry; the
    method's from robot_pose; both are the same drive (same seed) within localisation noise."""
    nav2 = trajectories(_bag(tmp_path / "nav2", _scenario(tmp_path, "convention nav2"), "ros1", "nav2"))
    method = trajectories(_bag(tmp_path / "method", _scenario(tmp_path, "torso no"), "ros1", "method"))
    assert [p.topic for p in nav2] == ["/tf (map → base_link)", "/r2/tf (map → base_link)"]
    assert [p.topic for p in method] == ["/robot_pose", "/r2/robot_pose"]
    for ours, theirs in zip(nav2, method, strict=True):
        assert np.linalg.norm(ours.xy[-1] - theirs.xy[-1]) < 0.15  # both end where the robot stopped
        ends = np.linalg.norm(ours.xy[-1] - ours.xy[0])
        assert ends > 3.0  # and it drove
