"""``exscec stand-in --ros2`` on a live ROS 2 graph: a process of its own serving Nav2 goals, driven
by an rclpy action client in the test's process (a domain of the test's own)."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest

from tests.support.paths import EXAMPLES

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
GOAL_WAIT = 120.0


@contextmanager
def stand_in(*options: str) -> Iterator[subprocess.Popen[str]]:
    """``exscec stand-in scenario_c --ros2 OPTIONS`` until the block ends (SIGTERM: exit 0)."""
    process = subprocess.Popen(
        [str(Path(sys.executable).with_name("exscec")), "stand-in", str(SCENARIO_C), "--ros2", *options],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        assert process.stdout is not None
        first = process.stdout.readline().strip()
        assert first == f"ROS_DOMAIN_ID={os.environ['ROS_DOMAIN_ID']}", (
            first,
            process.stderr and process.stderr.read(),
        )
        yield process
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGTERM)
        _, err = process.communicate(timeout=30)
    assert process.returncode == 0, err
    assert "Traceback" not in err and "terminate called" not in err, err


class Client:
    """An rclpy node with a NavigateToPose client per robot, and what it hears of ``/tiago1/odom``."""

    def __init__(self) -> None:
        import rclpy
        from nav2_msgs.action import FollowWaypoints, NavigateToPose
        from nav_msgs.msg import Odometry
        from rclpy.action import ActionClient
        from rclpy.executors import SingleThreadedExecutor

        self.rclpy, self.action, self.follow_action = rclpy, NavigateToPose, FollowWaypoints
        self.context = rclpy.Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node("exsce_test_client", context=self.context)
        self.clients = {
            r: ActionClient(self.node, NavigateToPose, f"/{r}/navigate_to_pose") for r in ("tiago1", "tiago2")
        }
        self.followers = {
            r: ActionClient(self.node, FollowWaypoints, f"/{r}/follow_waypoints")
            for r in ("tiago1", "tiago2")
        }
        from geometry_msgs.msg import PoseWithCovarianceStamped

        self.odom: list[Any] = []
        self.amcl: list[Any] = []
        # deep queues: this process takes messages only while it waits for a goal's answer (a CI
        # run under load once lost odometry from a queue of 100 before the test took it)
        self.node.create_subscription(Odometry, "/tiago1/odom", self.odom.append, 20000)
        self.node.create_subscription(PoseWithCovarianceStamped, "/tiago1/amcl_pose", self.amcl.append, 1000)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        for client in [*self.clients.values(), *self.followers.values()]:
            assert client.wait_for_server(timeout_sec=30.0)

    def send(self, robot: str, x: float, y: float, feedback: list[float] | None = None) -> Any:
        goal = self.action.Goal()
        goal.pose.header.frame_id = "map"
        goal.pose.pose.position.x, goal.pose.pose.position.y = x, y
        heard = None if feedback is None else (lambda m: feedback.append(m.feedback.distance_remaining))
        sent = self.clients[robot].send_goal_async(goal, feedback_callback=heard)
        self.executor.spin_until_future_complete(sent, timeout_sec=10.0)
        handle = sent.result()
        assert handle is not None and handle.accepted
        return handle

    def follow(self, robot: str, points: list[tuple[float, float]], feedback: list[int]) -> Any:
        goal = self.follow_action.Goal()
        from geometry_msgs.msg import PoseStamped

        for x, y in points:
            stamped = PoseStamped()
            stamped.header.frame_id = "map"
            stamped.pose.position.x, stamped.pose.position.y = x, y
            goal.poses.append(stamped)
        sent = self.followers[robot].send_goal_async(
            goal, lambda m: feedback.append(m.feedback.current_waypoint)
        )
        self.executor.spin_until_future_complete(sent, timeout_sec=10.0)
        handle = sent.result()
        assert handle is not None and handle.accepted
        return handle

    def result(self, handle: Any) -> int:
        return int(self.outcome(handle).status)

    def outcome(self, handle: Any) -> Any:
        future = handle.get_result_async()
        self.executor.spin_until_future_complete(future, timeout_sec=GOAL_WAIT)
        assert future.done()
        return future.result()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        self.context.try_shutdown()


@pytest.fixture
def client(ros2_env: dict[str, str]) -> Iterator[Client]:
    made: list[Client] = []
    with stand_in("--speed-up", "10"):
        made.append(Client())
        try:
            yield made[0]
        finally:
            made[0].close()


def test_a_goal_is_driven_to_its_pose_with_feedback_then_a_cancel_stops_the_robot(
    client: Client, spec_c: Any
) -> None:
    """tiago1 reaches the first waypoint of its task (SUCCEEDED), its feedback's distance left
    falling to nothing and its odometry on simulated time; a second goal cancelled on the way is
    CANCELED, and the odometry stops moving."""
    scenario, _ = spec_c
    task = next(t for t in scenario.tasks if t.id == "delivery_a")
    target = next(iter(task.waypoints())).position
    feedback: list[float] = []
    handle = client.send("tiago1", target.x, target.y, feedback)
    assert client.result(handle) == 4  # SUCCEEDED
    assert len(feedback) > 5 and feedback[0] > 1.0 and feedback[-1] < 0.3
    assert all(a >= b - 1e-6 for a, b in zip(feedback, feedback[1:], strict=False))
    stamps = [m.header.stamp.sec + m.header.stamp.nanosec / 1e9 for m in client.odom]
    assert len(stamps) > 50 and all(
        b - a == pytest.approx(0.02, abs=1e-6) for a, b in zip(stamps, stamps[1:], strict=False)
    )

    start = scenario.robot("tiago1").start_pose.position
    going = client.send("tiago1", start.x, start.y)
    deadline = time.monotonic() + 0.5
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.05)
    cancelled = going.cancel_goal_async()
    client.executor.spin_until_future_complete(cancelled, timeout_sec=10.0)
    assert client.result(going) == 5  # CANCELED
    # odometry sent before the cancel may still be on its way under load (CI saw 7 mm of it after
    # the clear): a second to take it in, then two in which the robot must stand still
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.05)
    client.odom.clear()
    deadline = time.monotonic() + 2.0
    while time.monotonic() < deadline:
        client.executor.spin_once(timeout_sec=0.05)
    poses = [(m.pose.pose.position.x, m.pose.pose.position.y) for m in client.odom]
    assert len(poses) > 10 and math.dist(poses[0], poses[-1]) < 1e-9  # standing still


def test_a_planted_skip_waypoint_fault_aborts_the_robots_first_goal(
    ros2_env: dict[str, str], spec_c: Any
) -> None:
    """``--fault skip-waypoint:tiago2`` aborts tiago2's first goal (ABORTED) and not tiago1's."""
    scenario, _ = spec_c
    target = next(iter(next(t for t in scenario.tasks if t.id == "delivery_b").waypoints())).position
    with stand_in("--fault", "skip-waypoint:tiago2", "--speed-up", "10"):
        client = Client()
        try:
            assert client.result(client.send("tiago2", target.x, target.y)) == 6  # ABORTED
            assert client.result(client.send("tiago2", target.x, target.y)) == 4
        finally:
            client.close()


def test_a_follow_waypoints_goal_drives_its_poses_in_order_and_a_failed_one_is_missed(
    ros2_env: dict[str, str], spec_c: Any
) -> None:
    """tiago1 follows delivery_a's waypoints (SUCCEEDED, feedback current_waypoint 0, 1, 2, no
    waypoint missed); with ``skip-waypoint:tiago2`` planted, tiago2's FollowWaypoints goal stops at
    its first waypoint: ABORTED, that waypoint in missed_waypoints."""
    scenario, _ = spec_c
    points = {
        task.id: [(w.position.x, w.position.y) for w in task.waypoints()]
        for task in scenario.tasks
        if task.id in ("delivery_a", "delivery_b")
    }
    with stand_in("--fault", "skip-waypoint:tiago2", "--speed-up", "10"):
        client = Client()
        try:
            heard: list[int] = []
            done = client.outcome(client.follow("tiago1", points["delivery_a"], heard))
            assert done.status == 4 and list(done.result.missed_waypoints) == []
            assert sorted(set(heard)) == list(range(len(points["delivery_a"])))
            assert heard == sorted(heard)
            failed = client.outcome(client.follow("tiago2", points["delivery_b"], []))
            assert failed.status == 6
            assert [m.index for m in failed.result.missed_waypoints] == [0]
        finally:
            client.close()


def test_with_irsim_a_goals_leg_is_driven_by_irsim(ros2_env: dict[str, str], spec_c: Any) -> None:
    """``--simulator irsim``: tiago1's goal is driven in IR-SIM (its rvo behaviour) and succeeds
    within IR-SIM's goal tolerance (0.2 m) of the pose, as AMCL's pose (the estimate, 2 cm noise)
    then says; the global plan of the goal was published on ``/tiago1/plan``."""
    from nav_msgs.msg import Path as PlanMessage

    scenario, _ = spec_c
    target = next(iter(next(t for t in scenario.tasks if t.id == "delivery_a").waypoints())).position
    with stand_in("--simulator", "irsim", "--speed-up", "10"):
        client = Client()
        plans: list[Any] = []
        client.node.create_subscription(PlanMessage, "/tiago1/plan", plans.append, 10)
        try:
            assert client.result(client.send("tiago1", target.x, target.y)) == 4
            client.amcl.clear()
            deadline = time.monotonic() + 3.0
            while time.monotonic() < deadline and not client.amcl:
                client.executor.spin_once(timeout_sec=0.05)
            where = client.amcl[-1].pose.pose.position
            assert math.dist((where.x, where.y), (target.x, target.y)) < 0.2 + 0.1
            assert len(plans) == 1 and plans[0].poses[-1].pose.position.x == pytest.approx(target.x, abs=0.1)
        finally:
            client.close()
