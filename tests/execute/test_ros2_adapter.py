"""The ROS 2 adapter without ROS 2: what it sends to Nav2, and how it says rclpy is
missing.  No live ROS 2 graph runs here (rclpy cannot be installed on this machine): the live
part (execute/ros2/live.py) is checked only for its refusal without rclpy.

Reference values are written by hand: scenario_c's poses from examples/brsu_building_c
(environment.exsce, tasks/*.exsce), quaternions of rotations worked out on paper, GoalStatus codes
from action_msgs/msg/GoalStatus.msg (UNKNOWN 0, ACCEPTED 1, EXECUTING 2, CANCELING 3, SUCCEEDED 4,
CANCELED 5, ABORTED 6).  The recorder is tested on a live graph in test_ros2_recorder.py."""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.execute.mission import schedule
from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.execute.ros2 import (
    follow_waypoints_goals,
    goal_outcome,
    nav2_actions,
    navigate_to_pose_goals,
    waypoint_outcomes,
)
from exsce_dsl.lang import load_spec
from exsce_dsl.model.conventions import METHOD, MOVE_BASE, NAV2, TopicSource
from exsce_dsl.model.geometry import quaternion
from exsce_dsl.model.scenario import Assignment

from tests.support.paths import EXAMPLES

# environment.exsce and tasks/*.exsce, by hand: (x, y, yaw as the task visits it)
C022_W001 = (52.82560729980469, 32.562904357910156, 2.269)
C018_W001 = (48.26420974731445, 24.618297576904297, -0.641)
C025_W001 = (44.80387496948242, 37.15502166748047, 0.925)  # navigate_home_1: facing 0.925
C022_W002 = (54.497589111328125, 31.52023696899414, 2.269)
C018_W002 = (46.25560760498047, 21.586545944213867, -0.641)
C025_W002 = (43.432926177978516, 38.493873596191406, 0.925)



@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")


def _planar(
    x: float, y: float, yaw: float
) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """A planar pose as a PoseStamped holds it: a turn by yaw about z is (0, 0, sin(yaw/2), cos(yaw/2))."""
    return (x, y, 0.0), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def _close(got, expected) -> bool:
    return all(a == pytest.approx(b, abs=1e-12) for a, b in zip(got, expected, strict=True))


def test_importing_the_adapter_needs_no_rclpy() -> None:
    probe = subprocess.run(
        [sys.executable, "-c", "import sys, exsce_dsl.execute.ros2; print('rclpy' in sys.modules)"],
        capture_output=True,
        text=True,
    )
    assert probe.returncode == 0, probe.stderr
    assert probe.stdout.strip() == "False"


def test_the_live_entry_point_says_rclpy_is_missing_and_how_to_get_it(
    scenario_c, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where rclpy cannot be imported, execute --ros2 says how to get it, before anything starts."""
    from exsce_dsl.api import execute_ros2

    monkeypatch.setitem(sys.modules, "rclpy", None)  # not importable, as on a machine without ROS 2
    with pytest.raises(RosGraphError) as raised:
        execute_ros2(scenario_c, tmp_path / "run")
    message = str(raised.value)
    assert "rclpy" in message and "exsce[ros2]" in message and "scripts/install-ros2" in message
    assert [p.name for p in tmp_path.iterdir()] in ([], ["run"])
    assert not list(tmp_path.rglob("*.prov.json")) and not list(tmp_path.rglob("metadata.yaml"))


def test_scenario_c_sends_one_navigate_to_pose_goal_per_waypoint_in_each_robots_namespace(scenario_c) -> None:
    goals = navigate_to_pose_goals(scenario_c, schedule(scenario_c))
    expected = [
        ("/tiago1/navigate_to_pose", C022_W001),
        ("/tiago1/navigate_to_pose", C018_W001),
        ("/tiago1/navigate_to_pose", C025_W001),
        ("/tiago2/navigate_to_pose", C022_W002),
        ("/tiago2/navigate_to_pose", C018_W002),
        ("/tiago2/navigate_to_pose", C025_W002),
    ]
    assert [g.action for g in goals] == [action for action, _ in expected]
    for goal, (_, pose) in zip(goals, expected, strict=True):
        position, orientation = _planar(*pose)
        assert goal.pose.frame_id == "map"
        assert goal.pose.position == position
        assert _close(goal.pose.orientation, orientation)
    assert [(g.goal.robot, g.goal.task, g.goal.waypoint) for g in goals[:3]] == [
        ("tiago1", "delivery_a", 1),
        ("tiago1", "delivery_a", 2),
        ("tiago1", "navigate_home_1", 1),
    ]


def test_a_robot_at_the_root_and_a_robot_naming_its_actions(scenario_c) -> None:
    tiago1, tiago2 = scenario_c.robots
    at_root = replace(tiago1, namespace="")
    named = replace(
        tiago2, declared_signals=NAV2.overridden(actions=("/{ns}/nav/go", "/{ns}/follow_waypoints"))
    )
    assert nav2_actions(at_root).navigate_to_pose == "/navigate_to_pose"
    assert nav2_actions(at_root).follow_waypoints == "/follow_waypoints"
    assert nav2_actions(named).navigate_to_pose == "/tiago2/nav/go"
    assert nav2_actions(named).follow_waypoints == "/tiago2/follow_waypoints"
    only_waypoints = replace(tiago2, declared_signals=NAV2.overridden(actions=("/{ns}/follow_waypoints",)))
    assert nav2_actions(only_waypoints).navigate_to_pose == "/tiago2/navigate_to_pose"
    changed = replace(scenario_c, robots=(at_root, named))
    assert [g.action for g in navigate_to_pose_goals(changed, schedule(changed))] == (
        ["/navigate_to_pose"] * 3 + ["/tiago2/nav/go"] * 3
    )


def test_a_robot_that_takes_move_base_or_dispatcher_goals_is_refused(scenario_c) -> None:
    robot = replace(scenario_c.robots[0], declared_signals=MOVE_BASE)
    with pytest.raises(ExsceError, match="tiago1.*move_base.*Nav2"):
        nav2_actions(robot)
    method = replace(scenario_c.robots[0], declared_signals=METHOD)  # 'convention method'
    with pytest.raises(ExsceError, match="tiago1.*dispatcher.*Nav2"):
        nav2_actions(method)


def test_a_robot_that_names_no_convention_gets_nav2s_actions(scenario_c) -> None:
    # its type overrides its pose only: the convention is detected per bag, the navigation unsaid
    pose_only = METHOD.overridden(
        pose=(TopicSource("/{ns}/ground_truth"),), named=False, said=frozenset({"pose"})
    )
    robot = replace(scenario_c.robots[0], declared_signals=pose_only)
    assert nav2_actions(robot).navigate_to_pose == "/tiago1/navigate_to_pose"


def test_follow_waypoints_goals_hold_one_subtask_each(scenario_c) -> None:
    # tiago1 does delivery_d (two subtasks: c022-w001, c018-w001 | c022-w002, c018-w002) instead of delivery_a
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    delivery_d = next(t for t in spec.tasks if t.id == "delivery_d")
    allocation = (Assignment("tiago1", "delivery_d"), *scenario_c.mission.allocation[1:])
    mission = replace(scenario_c.mission, allocation=allocation)
    changed = replace(scenario_c, mission=mission, tasks=(*scenario_c.tasks, delivery_d))
    goals = follow_waypoints_goals(changed, schedule(changed))
    assert [(g.action, len(g.poses)) for g in goals] == [
        ("/tiago1/follow_waypoints", 2),
        ("/tiago1/follow_waypoints", 2),
        ("/tiago1/follow_waypoints", 1),
        ("/tiago2/follow_waypoints", 2),
        ("/tiago2/follow_waypoints", 1),
    ]
    assert [p.position[:2] for p in goals[1].poses] == [C022_W002[:2], C018_W002[:2]]
    assert [(g.task, g.subtask, g.waypoint) for g in goals[1].goals] == [
        ("delivery_d", 2, 1),
        ("delivery_d", 2, 2),
    ]


def test_quaternions_of_rotations_worked_out_by_hand() -> None:
    c = math.sqrt(0.5)
    assert _close(quaternion(0.0, 0.0, math.pi / 2), (0.0, 0.0, c, c))
    assert _close(quaternion(math.pi, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))
    # roll 90° then yaw 90°: qz * qx = (c + s k)(c + s i) = c² + cs i + s² j + sc k
    assert _close(quaternion(math.pi / 2, 0.0, math.pi / 2), (0.5, 0.5, 0.5, 0.5))


@pytest.mark.parametrize(
    "status, outcome",
    [
        (4, GoalOutcome.SUCCEEDED),
        (6, GoalOutcome.ABORTED),
        (5, GoalOutcome.CANCELLED),
        (0, GoalOutcome.ABORTED),
        (1, None),
        (2, None),
        (3, None),
    ],
)
def test_goal_status_codes_map_onto_the_cores_outcomes(status: int, outcome: GoalOutcome | None) -> None:
    assert goal_outcome(status) is outcome


def test_a_goal_not_accepted_is_rejected_and_an_unknown_code_is_an_error() -> None:
    assert goal_outcome(0, accepted=False) is GoalOutcome.REJECTED
    with pytest.raises(ExsceError, match="7"):
        goal_outcome(7)


def test_follow_waypoints_results_map_onto_each_waypoint() -> None:
    s, a, c = GoalOutcome.SUCCEEDED, GoalOutcome.ABORTED, GoalOutcome.CANCELLED
    # succeeded, waypoint 1 missed (stop_on_failure false): the others were reached
    assert waypoint_outcomes(4, 3, [1], 2) == (s, a, s)
    # aborted at waypoint 1, which is missed: waypoint 0 reached, waypoint 2 never sent
    assert waypoint_outcomes(6, 3, [1], 1) == (s, a, None)
    # cancelled while driving to waypoint 1
    assert waypoint_outcomes(5, 3, [], 1) == (s, c, None)
    with pytest.raises(ExsceError, match="not ended"):
        waypoint_outcomes(2, 3, [], 1)
    with pytest.raises(ExsceError, match="outside"):
        waypoint_outcomes(4, 3, [3], 2)
