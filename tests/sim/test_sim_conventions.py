"""The executor writes Nav2's and move_base's topics, in every bag format, read back with rosbags'
AnyReader from the bags' own definitions (no exsce code on the reading path)."""

from __future__ import annotations

import hashlib
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.cli.run_commands import simulate as simulate_command
from exsce_dsl.errors import ExsceError
from exsce_dsl.lang import load_spec
from exsce_dsl.messages.navigation import navigation_catalogue, register_navigation_types
from exsce_dsl.model.conventions import METHOD, NAV2
from exsce_dsl.sim.executor import Fault, GoalStatus
from exsce_dsl.sim.run import SimulatedRun, simulate

from tests.support.paths import EXAMPLES

FORMATS = ("ros1", "ros2", "mcap")
CONVENTIONS = ("nav2", "move_base")
SEED = 7
FAULTS = (Fault.parse("skip-waypoint:r2:2"),)  # r2's second waypoint is aborted

# Two robots in open space: r1 at the root namespace, r2 in /r2.
YARD = """
environment yard {
  area yard {
    pose yard-a at (0.0, 0.0)
    pose yard-b at (5.0, 0.0)
    pose yard-c at (5.0, 4.0) facing 90.0 deg
    pose yard-d at (0.0, 8.0)
    pose yard-e at (5.0, 8.0)
    pose yard-f at (5.0, 12.0) facing 90.0 deg
  }
}

robot type pmb2 {
  base pmb2
  torso no
}

task round_1 {
  visit yard-b
  visit yard-c
}

task round_2 {
  visit yard-e
  visit yard-f
}

scenario yard_run in yard {
  robots {
    r1: pmb2 namespace "" starts at yard-a
    r2: pmb2 starts at yard-d
  }
  mission yard_mission parallel {
    r1 does round_1
    r2 does round_2
  }
}
"""

ROBOT_TOPICS = {
    "tf": "tf2_msgs/msg/TFMessage",
    "tf_static": "tf2_msgs/msg/TFMessage",
    "odom": "nav_msgs/msg/Odometry",
    "amcl_pose": "geometry_msgs/msg/PoseWithCovarianceStamped",
    "cmd_vel": "geometry_msgs/msg/Twist",
    "scan": "sensor_msgs/msg/LaserScan",
}
NAV2_TOPICS = {
    "plan": "nav_msgs/msg/Path",
    "navigate_to_pose/_action/status": "action_msgs/msg/GoalStatusArray",
    "navigate_to_pose/_action/feedback": "nav2_msgs/action/NavigateToPose_FeedbackMessage",
}
MOVE_BASE_TOPICS = {
    "move_base/goal": "move_base_msgs/msg/MoveBaseActionGoal",
    "move_base/status": "actionlib_msgs/msg/GoalStatusArray",
    "move_base/feedback": "move_base_msgs/msg/MoveBaseActionFeedback",
    "move_base/result": "move_base_msgs/msg/MoveBaseActionResult",
}
PREFIXES = {"r1": "", "r2": "/r2"}

# Written by hand from action_msgs/GoalStatus and actionlib_msgs/GoalStatus.
NAV2_SUCCEEDED, NAV2_ABORTED = [1, 2, 4], [1, 2, 6]  # accepted → executing → succeeded | aborted
MOVE_BASE_SUCCEEDED, MOVE_BASE_ABORTED = [0, 1, 3], [0, 1, 4]  # pending → active → succeeded | aborted

LOCALISATION_BOUND = 0.1  # m: five standard deviations of the localisation noise (0.02 m)
YAW_BOUND = 0.05  # rad: five standard deviations (0.01 rad)


@pytest.fixture(scope="module")
def yard(tmp_path_factory: pytest.TempPathFactory) -> Any:
    folder = tmp_path_factory.mktemp("yard")
    (folder / "yard.exsce").write_text(YARD, encoding="utf-8")
    return load_spec(folder / "yard.exsce").scenario()


@pytest.fixture(scope="module")
def bags(yard: Any, tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], SimulatedRun]:
    out = tmp_path_factory.mktemp("bags")
    return {
        (convention, fmt): next(
            simulate(yard, out / f"{convention}-{fmt}", 1, fmt, SEED, FAULTS, convention=convention)
        )
        for convention in CONVENTIONS
        for fmt in FORMATS
    }


@pytest.fixture(scope="module")
def decoded(bags: dict[tuple[str, str], SimulatedRun]) -> dict[tuple[str, str], dict[str, Any]]:
    return {key: _read(run.bag, key[1]) for key, run in bags.items()}


def _read(bag: Path, fmt: str) -> dict[str, Any]:
    """Topics → (type, latched, [(stamp, message)]), decoded from the bag's own definitions."""
    plain = get_typestore(Stores.ROS1_NOETIC if fmt == "ros1" else Stores.ROS2_HUMBLE)
    with AnyReader([bag], default_typestore=plain) as reader:
        topics: dict[str, Any] = {}
        for conn in reader.connections:
            if fmt == "ros1":
                latched = bool(conn.ext.latching)
            else:
                latched = any(q.durability.name == "TRANSIENT_LOCAL" for q in conn.ext.offered_qos_profiles)
            topics[conn.topic] = (conn.msgtype, latched, [])
        for conn, stamp, raw in reader.messages():
            topics[conn.topic][2].append((stamp, reader.deserialize(raw, conn.msgtype)))
    return topics


def _digest(bag: Path) -> list[str]:
    files = [bag] if bag.is_file() else sorted(bag.iterdir())
    return [hashlib.sha256(p.read_bytes()).hexdigest() for p in files]


def _matrix(translation: Any, rotation: Any) -> np.ndarray:
    """A 4×4 homogeneous transform from a translation and a unit quaternion."""
    x, y, z, w = rotation.x, rotation.y, rotation.z, rotation.w
    m = np.eye(4)
    m[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    m[:3, 3] = [translation.x, translation.y, translation.z]
    return m


def _planar(pose_x: float, pose_y: float, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0, pose_x], [s, c, 0, pose_y], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _yaw(m: np.ndarray) -> float:
    return math.atan2(m[1, 0], m[0, 0])


def _angle(a: float, b: float) -> float:
    return abs(math.atan2(math.sin(a - b), math.cos(a - b)))


def _transforms(topics: dict[str, Any], topic: str, parent: str, child: str) -> dict[int, np.ndarray]:
    """Header stamp (ns) → 4×4 transform of ``child`` in ``parent``, from a tf topic."""
    found = {}
    for _, msg in topics[topic][2]:
        for t in msg.transforms:
            if t.header.frame_id == parent and t.child_frame_id == child:
                stamp = t.header.stamp.sec * 1_000_000_000 + t.header.stamp.nanosec
                found[stamp] = _matrix(t.transform.translation, t.transform.rotation)
    return found


def _truth(run: SimulatedRun, robot: str, stamp: int) -> np.ndarray:
    tr = run.execution.trajectories[robot]
    k = int(round((stamp - run.start.timestamp() * 1e9) / 20_000_000))
    return _planar(float(tr.x[k]), float(tr.y[k]), float(tr.yaw[k]))


CASES = [(c, f) for c in CONVENTIONS for f in FORMATS]


@pytest.mark.parametrize(("convention", "fmt"), CASES)
def test_the_bag_has_exactly_the_conventions_topics(decoded, convention: str, fmt: str) -> None:
    action = NAV2_TOPICS if convention == "nav2" else MOVE_BASE_TOPICS
    expected = {
        f"{prefix}/{name}": msgtype
        for prefix in PREFIXES.values()
        for name, msgtype in {**ROBOT_TOPICS, **action}.items()
    }
    if fmt == "ros1":  # ROS 1 has no action/ types: the ROS 1 name of the same definition
        expected = {t: m.replace("/action/", "/msg/") for t, m in expected.items()}
    topics = decoded[(convention, fmt)]
    assert {t: v[0] for t, v in topics.items()} == expected
    assert {t for t, v in topics.items() if v[1]} >= {"/tf_static", "/r2/tf_static"}
    assert [len(topics[t][2]) for t in ("/tf_static", "/r2/tf_static")] == [1, 1]
    [(_, static)] = topics["/tf_static"][2]
    assert {(t.header.frame_id, t.child_frame_id) for t in static.transforms} == {
        ("base_link", "base_laser_link"),
        ("base_link", "base_footprint"),
    }
    assert {msg.header.frame_id for _, msg in topics["/r2/scan"][2]} == {"base_laser_link"}


@pytest.mark.parametrize(("convention", "fmt"), CASES)
def test_map_odom_base_link_is_the_true_pose(bags, decoded, convention: str, fmt: str) -> None:
    run, topics = bags[(convention, fmt)], decoded[(convention, fmt)]
    for robot, prefix in PREFIXES.items():
        correction = _transforms(topics, f"{prefix}/tf", "map", "odom")
        odometry = _transforms(topics, f"{prefix}/tf", "odom", "base_link")
        stamps = sorted(correction)
        assert len(odometry) == pytest.approx(5 * len(correction), abs=5)  # 50 Hz and 10 Hz
        for stamp in stamps[:: max(len(stamps) // 8, 1)]:
            chained = correction[stamp] @ odometry[stamp]
            truth = _truth(run, robot, stamp)
            assert math.dist(chained[:2, 3], truth[:2, 3]) < LOCALISATION_BOUND, (robot, stamp)
            assert _angle(_yaw(chained), _yaw(truth)) < YAW_BOUND, (robot, stamp)


@pytest.mark.parametrize(("convention", "fmt"), CASES)
def test_odometry_drifts_and_map_to_odom_corrects_it(bags, decoded, convention: str, fmt: str) -> None:
    run, topics = bags[(convention, fmt)], decoded[(convention, fmt)]
    start = _truth(run, "r1", run.start.timestamp() * 1e9)  # odometry starts at zero, where r1 starts
    errors = []
    for _, msg in topics["/odom"][2]:
        assert (msg.header.frame_id, msg.child_frame_id) == ("odom", "base_link")
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        odom = _matrix(msg.pose.pose.position, msg.pose.pose.orientation)
        errors.append(math.dist((np.linalg.inv(start) @ _truth(run, "r1", stamp))[:2, 3], odom[:2, 3]))
    quarter, end = errors[len(errors) // 4], errors[-1]
    assert 0.05 < end and quarter < end  # wheel odometry drifts, more the farther the robot drove
    correction = _transforms(topics, "/tf", "map", "odom")
    last = max(correction)
    chained = correction[last] @ _transforms(topics, "/tf", "odom", "base_link")[last]
    assert math.dist(chained[:2, 3], _truth(run, "r1", last)[:2, 3]) < min(LOCALISATION_BOUND, end)
    # AMCL's pose is the same estimate
    for _, msg in topics["/amcl_pose"][2]:
        stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        p = msg.pose.pose.position
        assert math.dist((p.x, p.y), _truth(run, "r1", stamp)[:2, 3]) < LOCALISATION_BOUND


def _status_sequences(topics: dict[str, Any], topic: str, key: Any) -> dict[Any, list[int]]:
    """Each goal's statuses in the order they appear, repeats removed."""
    sequences: dict[Any, list[int]] = {}
    for _, msg in topics[topic][2]:
        for status in msg.status_list:
            seen = sequences.setdefault(key(status), [])
            if not seen or seen[-1] != status.status:
                seen.append(int(status.status))
    return sequences


@pytest.mark.parametrize("fmt", FORMATS)
def test_nav2_sends_one_goal_per_waypoint(bags, decoded, fmt: str) -> None:
    run, topics = bags[("nav2", fmt)], decoded[("nav2", fmt)]
    for robot, prefix in PREFIXES.items():
        actions = [a for a in run.execution.actions if a.robot == robot]
        sequences = _status_sequences(
            topics, f"{prefix}/navigate_to_pose/_action/status", lambda s: bytes(s.goal_info.goal_id.uuid)
        )
        assert len(sequences) == len(actions) == 2  # one goal per planned waypoint, distinct UUIDs
        expected = [NAV2_SUCCEEDED if a.status is GoalStatus.SUCCEEDED else NAV2_ABORTED for a in actions]
        assert list(sequences.values()) == expected  # in the order the goals were sent
        plans = [msg for _, msg in topics[f"{prefix}/plan"][2]]
        assert len(plans) == len(actions)
        for plan, action in zip(plans, actions, strict=True):
            last, first = plan.poses[-1].pose, plan.poses[0].pose.position
            yaw = 2 * math.atan2(last.orientation.z, last.orientation.w)
            assert (last.position.x, last.position.y) == pytest.approx(
                (action.goal.position.x, action.goal.position.y)
            )
            assert _angle(yaw, action.goal.orientation.yaw) < 1e-9
            assert (first.x, first.y) == pytest.approx(action.path[0])
            assert plan.header.frame_id == "map"
        feedback = [msg for _, msg in topics[f"{prefix}/navigate_to_pose/_action/feedback"][2]]
        assert {bytes(m.goal_id.uuid) for m in feedback} <= set(sequences)
        first_goal = next(iter(sequences))
        remaining = [m.feedback.distance_remaining for m in feedback if bytes(m.goal_id.uuid) == first_goal]
        assert remaining[0] == pytest.approx(actions[0].path_length, abs=0.1)
        assert remaining[-1] < 0.5 < remaining[0]
    # the fault is there: r2's second goal was aborted
    assert [a.status for a in run.execution.actions if a.robot == "r2"] == [
        GoalStatus.SUCCEEDED,
        GoalStatus.ABORTED,
    ]


@pytest.mark.parametrize("fmt", FORMATS)
def test_move_base_sends_one_goal_per_waypoint(bags, decoded, fmt: str) -> None:
    run, topics = bags[("move_base", fmt)], decoded[("move_base", fmt)]
    for robot, prefix in PREFIXES.items():
        actions = [a for a in run.execution.actions if a.robot == robot]
        goals = [msg for _, msg in topics[f"{prefix}/move_base/goal"][2]]
        ids = [g.goal_id.id for g in goals]
        assert len(set(ids)) == len(actions) == 2
        assert all(re.fullmatch(rf"{prefix}/move_base-\d+-\d+\.\d+", i) for i in ids), ids
        for goal, action in zip(goals, actions, strict=True):
            target = goal.goal.target_pose
            assert target.header.frame_id == "map"
            assert (target.pose.position.x, target.pose.position.y) == pytest.approx(
                (action.goal.position.x, action.goal.position.y)
            )
        sequences = _status_sequences(topics, f"{prefix}/move_base/status", lambda s: s.goal_id.id)
        expected = [
            MOVE_BASE_SUCCEEDED if a.status is GoalStatus.SUCCEEDED else MOVE_BASE_ABORTED for a in actions
        ]
        assert [sequences[i] for i in ids] == expected
        results = [msg.status for _, msg in topics[f"{prefix}/move_base/result"][2]]
        assert [(r.goal_id.id, r.status) for r in results] == [
            (i, s[-1]) for i, s in zip(ids, expected, strict=True)
        ]
        feedback = [msg for _, msg in topics[f"{prefix}/move_base/feedback"][2]]
        assert {m.status.goal_id.id for m in feedback} <= set(ids) and {
            m.status.status for m in feedback
        } == {1}
        assert {m.feedback.base_position.header.frame_id for m in feedback} == {"map"}


@pytest.mark.parametrize("convention", CONVENTIONS)
def test_same_seed_same_bytes(yard, bags, tmp_path: Path, convention: str) -> None:
    for fmt in FORMATS:
        [again] = simulate(yard, tmp_path / fmt, 1, fmt, SEED, FAULTS, convention=convention)
        assert again.bag.name == bags[(convention, fmt)].bag.name
        assert _digest(again.bag) == _digest(bags[(convention, fmt)].bag)
    [other] = simulate(yard, tmp_path / "other", 1, "ros1", SEED + 1, FAULTS, convention=convention)
    assert _digest(other.bag) != _digest(bags[(convention, "ros1")].bag)


def test_a_convention_is_given_by_name_or_as_signals(yard, bags, tmp_path: Path) -> None:
    [by_signals] = simulate(yard, tmp_path, 1, "mcap", SEED, FAULTS, convention=NAV2)
    assert _digest(by_signals.bag) == _digest(bags[("nav2", "mcap")].bag)
    with pytest.raises(ExsceError, match="unknown convention 'ros3'; the executor writes method, nav2"):
        next(simulate(yard, tmp_path / "bad", 1, "ros1", SEED, convention="ros3"))


def test_the_methods_bags_are_unchanged(yard, bags, tmp_path: Path) -> None:
    """The method's convention is the default: the bytes of the code path without a convention."""
    for fmt in FORMATS:
        [default] = simulate(yard, tmp_path / f"default-{fmt}", 1, fmt, SEED, FAULTS)
        [named] = simulate(yard, tmp_path / f"named-{fmt}", 1, fmt, SEED, FAULTS, convention="method")
        [signals] = simulate(yard, tmp_path / f"signals-{fmt}", 1, fmt, SEED, FAULTS, convention=METHOD)
        assert _digest(default.bag) == _digest(named.bag) == _digest(signals.bag)
        assert default.bag.name == named.bag.name != bags[("nav2", fmt)].bag.name
        topics = _read(default.bag, fmt)
        assert "/waypoint_dispatcher/feedback" in topics and "/tf" not in topics


def test_cmd_vel_is_stamped_when_asked(yard, tmp_path: Path) -> None:
    [run] = simulate(yard, tmp_path, 1, "ros2", SEED, convention="nav2", twist_stamped=True)
    topics = _read(run.bag, "ros2")
    assert topics["/cmd_vel"][0] == "geometry_msgs/msg/TwistStamped"
    stamps = [stamp for stamp, _ in topics["/cmd_vel"][2]]
    assert {msg.header.frame_id for _, msg in topics["/cmd_vel"][2]} == {"base_link"}
    assert set(np.diff(stamps).tolist()) == {50_000_000}  # 20 Hz, the controller's rate


def test_the_navigation_definitions_ship_with_the_package() -> None:
    catalogue = navigation_catalogue()
    for name in (
        "nav2_msgs/action/NavigateToPose_FeedbackMessage",
        "nav2_msgs/action/NavigateThroughPoses_Feedback",
        "nav2_msgs/action/FollowWaypoints_Result",
        "move_base_msgs/msg/MoveBaseActionGoal",
        "move_base_msgs/msg/MoveBaseActionResult",
        "move_base_msgs/msg/MoveBaseActionFeedback",
    ):
        assert name in catalogue, name
        assert "packaged definition" in catalogue.source_of(name).text
    assert [f for f, _ in catalogue.fields_of("nav2_msgs/action/NavigateToPose_Feedback")] == [
        "current_pose",
        "navigation_time",
        "estimated_time_remaining",
        "number_of_recoveries",
        "distance_remaining",
    ]
    assert [f for f, _ in catalogue.fields_of("move_base_msgs/msg/MoveBaseFeedback")] == ["base_position"]
    ros1 = get_typestore(Stores.ROS1_NOETIC)
    register_navigation_types(ros1)
    # the ROS 1 md5sums of move_base_msgs and tf2_msgs, as ROS 1 bags record them
    assert ros1.generate_msgdef("tf2_msgs/msg/TFMessage")[1] == "94810edda583a504dfda3829e70d7eec"
    assert (
        ros1.generate_msgdef("move_base_msgs/msg/MoveBaseActionGoal")[1] == "660d6895a1b9a16dce51fbdd9a64a56b"
    )


def test_exscec_simulate_writes_nav2_bags(tmp_path: Path) -> None:
    spec = tmp_path / "yard.exsce"
    spec.write_text(YARD, encoding="utf-8")
    result = CliRunner().invoke(
        simulate_command,
        [
            str(spec),
            "--convention",
            "nav2",
            "--format",
            "ros2",
            "-o",
            str(tmp_path / "runs"),
            "--cmd-vel-stamped",
        ],
    )
    assert result.exit_code == 0, result.output
    [bag] = [p for p in (tmp_path / "runs").iterdir() if p.is_dir()]
    topics = _read(bag, "ros2")
    assert topics["/r2/cmd_vel"][0] == "geometry_msgs/msg/TwistStamped"
    assert (
        topics["/r2/navigate_to_pose/_action/feedback"][0]
        == "nav2_msgs/action/NavigateToPose_FeedbackMessage"
    )


def test_the_help_documents_the_convention_with_an_example_that_runs(in_tmp: Path) -> None:
    runner = CliRunner()
    help_text = runner.invoke(simulate_command, ["--help"]).output
    assert "--convention [method|nav2|move_base]" in help_text and "--cmd-vel-stamped" in help_text
    [example] = [
        line.split()
        for line in help_text.splitlines()
        if "exscec simulate" in line and "--convention" in line
    ]
    args = [str(EXAMPLES.parent / a) if a.startswith("examples/") else a for a in example[2:]]
    result = runner.invoke(simulate_command, args)  # in a temporary folder: the example's -o runs/
    assert result.exit_code == 0, result.output
    [bag] = [p for p in (in_tmp / "runs").iterdir() if p.is_dir()]
    assert any(p.suffix == ".mcap" for p in bag.iterdir())
    assert "/tiago1/navigate_to_pose/_action/status" in _read(bag, "mcap")
