"""The mission core's :class:`Navigator` and :class:`Clock` over exsce's dispatcher node.

The node (``nodes/dispatcher_node.py``, run by rospy's Python) holds one actionlib client per
robot; this side numbers the goals, asks the node for the ROS time and for a word when the ROS
time passes a deadline (on ``/use_sim_time`` the ROS clock runs at the simulator's pace, faster
or slower than the wall clock, so only the node can tell), and keeps the goal ends the node
reported while it waited for something else.
"""

from __future__ import annotations

import json
import re
import time
from collections import deque
from collections.abc import Callable, Mapping
from itertools import count
from pathlib import Path
from typing import Any

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.navigator import Finished
from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.execute.ros1.channel import Message, NodeChannel
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.model.conventions import Navigation
from exsce_dsl.model.geometry import quaternion
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.runs import PROV_TOPIC

MOVE_BASE_ACTION = "/{ns}/move_base"
STARTUP = 30.0
"""Wall seconds the node may take to start (rospy's imports, registering with the master) on
top of the time it waits for the action servers."""
REPLY_TIMEOUT = 10.0
"""Wall seconds the node may take to answer a question."""
WAKE = 0.1
"""Wall seconds between two looks at ``interrupted`` while waiting for the node."""
_NAME = re.compile(r"^(/[A-Za-z][A-Za-z0-9_]*)+$")
_OUTCOMES = {
    "succeeded": GoalOutcome.SUCCEEDED,
    "aborted": GoalOutcome.ABORTED,
    "rejected": GoalOutcome.REJECTED,
    "cancelled": GoalOutcome.CANCELLED,
}


def move_base_actions(scenario: Scenario) -> dict[str, str]:
    """Robot → the move_base action its goals go to (``/tiago1/move_base``; ``/move_base`` for a
    robot at the root), from its convention (the method's and undeclared ones: move_base)."""
    actions = {}
    for robot in scenario.robots:
        signals = robot.signals
        if signals.navigation is Navigation.NAV2:
            raise RosGraphError(
                f"robot '{robot.id}' navigates with Nav2 (ROS 2); ROS 1 sends move_base goals"
            )
        pattern = signals.actions[0] if signals.navigation is Navigation.MOVE_BASE else MOVE_BASE_ACTION
        name = expand_topic(pattern, robot.namespace)
        if not _NAME.match(name):
            raise RosGraphError(f"robot '{robot.id}': '{name}' is not a ROS action name")
        actions[robot.id] = name
    return actions


class DispatcherNode:
    """The running dispatcher node; up (every action server answering) once constructed."""

    def __init__(
        self,
        actions: Mapping[str, str],
        master_uri: str,
        log: Path,
        server_timeout: float,
        prov_topic: str = PROV_TOPIC,
        ros_home: Path | None = None,
    ) -> None:
        args = ["--actions", json.dumps(dict(actions)), "--server-timeout", f"{server_timeout:g}"]
        args += ["--prov-topic", prov_topic]
        self.channel = NodeChannel("dispatcher", args, master_uri, log, ros_home)
        self.pending: deque[Message] = deque()
        self._ids = count(1)
        try:
            self.channel.expect("ready", server_timeout + STARTUP)
        except BaseException:
            self.channel.close()
            raise

    def send(self, command: Message) -> None:
        self.channel.send(command)

    def ask(self, command: Message, reply: str) -> Message:
        """Send ``command`` with a new id; the node's ``reply`` event of that id."""
        ident = next(self._ids)
        self.channel.send({**command, "id": ident})
        deadline = time.monotonic() + REPLY_TIMEOUT
        while (left := deadline - time.monotonic()) > 0:
            message = self.channel.receive(left)
            if message is None:
                break
            if message.get("event") == reply and message.get("id") == ident:
                return message
            self.pending.append(message)
        what = command.get("command")
        raise RosGraphError(f"the dispatcher node did not answer '{what}' within {REPLY_TIMEOUT:g} s")

    def next_event(self, timeout: float) -> Message | None:
        """The next event not asked for, waiting at most ``timeout`` wall seconds."""
        if self.pending:
            return self.pending.popleft()
        return self.channel.receive(timeout)

    def publish(self, text: str) -> int:
        """Publish ``text`` on the PROV topic (latched); how many subscribers it has."""
        return int(self.ask({"command": "publish", "text": text}, "published").get("subscribers", 0))

    def new_id(self) -> int:
        return next(self._ids)

    def close(self) -> int | None:
        """End the node: it cancels the goals still active first."""
        return self.channel.close()


class RosClock:
    """The ROS time (simulated time under ``/use_sim_time``), as the dispatcher node reads it."""

    def __init__(self, node: DispatcherNode) -> None:
        self.node = node

    def now(self) -> float:
        return float(self.node.ask({"command": "time"}, "time")["time"])


class Ros1Navigator:
    """Goals to each robot's move_base through the dispatcher node.  ``interrupted`` (asked every
    ``WAKE`` wall seconds while waiting) ends a wait early, so that Ctrl-C is heard even when the
    ROS clock stands still."""

    def __init__(self, node: DispatcherNode, interrupted: Callable[[], bool] | None = None) -> None:
        self.node = node
        self.interrupted = interrupted
        self.sent: list[tuple[int, str, Pose]] = []

    def send(self, goal: int, robot: str, pose: Pose) -> None:
        p, o = pose.position, pose.orientation
        self.sent.append((goal, robot, pose))
        target = [p.x, p.y, p.z, *quaternion(o.roll, o.pitch, o.yaw)]
        self.node.send({"command": "send", "goal": goal, "robot": robot, "pose": target})

    def cancel(self, goal: int) -> None:
        self.node.send({"command": "cancel", "goal": goal})

    def next_finished(self, deadline: float) -> Finished | None:
        wait = self.node.new_id()
        self.node.send({"command": "wait", "id": wait, "until": deadline})
        while True:
            message = self.node.next_event(WAKE)
            if message is not None:
                finished = _finished(message)
                if finished is not None:
                    return finished
                if message.get("event") == "deadline" and message.get("id") == wait:
                    return None
            if self.interrupted is not None and self.interrupted():
                return None


def _finished(message: dict[str, Any]) -> Finished | None:
    if message.get("event") != "finished":
        return None
    outcome = _OUTCOMES.get(str(message.get("outcome")), GoalOutcome.ABORTED)
    return Finished(int(message["goal"]), outcome, float(message["time"]))
