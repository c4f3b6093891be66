"""ROS 2 as scripts/install-ros2 leaves it: PyPI's Jazzy wheels, and nav2_msgs and tf2_msgs built
from ros2/interfaces/ with the wheels' rosidl, speaking on a live graph."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

from rosbags.typesys import Stores, get_typestore

SERVER = textwrap.dedent(
    """
    import sys, time, rclpy
    from rclpy.action import ActionServer
    from nav2_msgs.action import NavigateToPose
    rclpy.init()
    node = rclpy.create_node("fake_nav2")
    def execute(handle):
        feedback = NavigateToPose.Feedback()
        feedback.distance_remaining = 2.5
        handle.publish_feedback(feedback)
        handle.succeed()
        print("goal", handle.request.pose.pose.position.x, handle.request.pose.header.frame_id, flush=True)
        return NavigateToPose.Result(error_code=0)
    server = ActionServer(node, NavigateToPose, "/tiago1/navigate_to_pose", execute)
    print("ready", flush=True)
    end = time.monotonic() + 30
    while time.monotonic() < end and sys.stdin.readable():
        rclpy.spin_once(node, timeout_sec=0.1)
    """
)


def built_hash(package: str, kind: str, name: str) -> str:
    """The RIHS01 hash rosidl wrote for ``package/kind/name`` in the venv's share folder."""
    found = Path(sys.prefix) / "share" / package / kind / f"{name}.json"
    hashes = json.loads(found.read_text(encoding="utf-8"))["type_hashes"]
    return next(h["hash_string"] for h in hashes if h["type_name"] == f"{package}/{kind}/{name}")


def test_tf2_msgs_built_here_hash_as_upstream_jazzy() -> None:
    """Our build of tf2_msgs has the type hashes of rosbags' copy of Jazzy's (an independent source):
    the definitions and the build pipeline are the upstream ones."""
    jazzy = get_typestore(Stores.ROS2_JAZZY)
    for name in ("TFMessage", "TF2Error"):
        assert built_hash("tf2_msgs", "msg", name) == jazzy.hash_rihs01(f"tf2_msgs/msg/{name}")


def test_nav2_goal_crosses_processes_on_fast_dds(ros2_env: dict[str, str]) -> None:
    """A NavigateToPose goal sent from this process reaches a server in another, with its feedback
    and result coming back: rclpy, Fast DDS and the built nav2_msgs on loopback."""
    import rclpy
    from nav2_msgs.action import NavigateToPose
    from rclpy.action import ActionClient

    server = subprocess.Popen(
        [sys.executable, "-c", SERVER], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    try:
        assert server.stdout is not None and server.stdout.readline().strip() == "ready"
        context = rclpy.Context()
        rclpy.init(context=context)
        try:
            node = rclpy.create_node("exsce_test_client", context=context)
            client = ActionClient(node, NavigateToPose, "/tiago1/navigate_to_pose")
            assert client.wait_for_server(timeout_sec=20.0)
            feedback: list[float] = []
            goal = NavigateToPose.Goal()
            goal.pose.header.frame_id = "map"
            goal.pose.pose.position.x = 3.25
            sent = client.send_goal_async(
                goal, feedback_callback=lambda m: feedback.append(m.feedback.distance_remaining)
            )
            executor = rclpy.executors.SingleThreadedExecutor(context=context)
            executor.add_node(node)
            executor.spin_until_future_complete(sent, timeout_sec=10.0)
            handle = sent.result()
            assert handle is not None and handle.accepted
            result = handle.get_result_async()
            executor.spin_until_future_complete(result, timeout_sec=10.0)
            assert result.result().status == 4  # action_msgs/GoalStatus STATUS_SUCCEEDED
            assert feedback == [2.5]
            executor.shutdown()
            node.destroy_node()
        finally:
            context.try_shutdown()
        assert server.stdout.readline().split() == ["goal", "3.25", "map"]
    finally:
        server.kill()
        server.wait()
