"""The live ROS 2 part: Nav2 action clients behind the core's ``Navigator`` and ``Clock``.

rclpy and nav2_msgs come from ROS 2 Jazzy's wheels (the ``ros2`` extra and
``scripts/install-ros2``, which builds nav2_msgs) or a sourced ROS 2 distro; they are imported
inside :func:`require_rclpy` only, so that importing this module works without them.  The node
that holds the clients is :class:`~.dispatcher_node.Ros2DispatcherNode`; a run is
:func:`~.session.execute_runs_ros2`.

The dispatcher node holds a ``NavigateToPose`` action client per robot.  It is
spun in the dispatcher's own thread, a slice at a time while :meth:`Ros2Navigator.next_finished`
waits: goals are sent, and their acceptances and results handled, in that one thread.  (An
executor spinning on a thread of its own would race ``send_goal_async``, which in Humble's
rclpy registers a goal's future only after the request is out, without a lock: a fast answer
would be dropped.)  Time is the node's clock: the wall clock, or ``/clock`` with ``use_sim_time``.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.navigator import Finished
from exsce_dsl.execute.outcomes import GoalOutcome
from exsce_dsl.execute.ros2.nav2 import goal_outcome, stamped_pose
from exsce_dsl.execute.ros2.recorder import SOURCE_HINT
from exsce_dsl.model import Pose

CANCEL_WAIT = 2.0
"""Wall seconds a run that stops on an error waits for goals still unanswered, to cancel them."""
WAIT_SLICE = 0.05
"""Wall seconds between two looks at the clock while waiting for a goal to end."""


@dataclass(frozen=True)
class Ros2Modules:
    """What the adapter uses of a ROS 2 installation."""

    rclpy: ModuleType
    context: ModuleType
    """``rclpy.context`` (Context: this run's own, shut down at its end)."""
    action: ModuleType
    """``rclpy.action`` (ActionClient)."""
    executors: ModuleType
    parameter: ModuleType
    """``rclpy.parameter`` (Parameter, for ``use_sim_time``)."""
    nav2: ModuleType
    """``nav2_msgs.action`` (NavigateToPose)."""


def require_rclpy() -> Ros2Modules:
    """rclpy and nav2_msgs, or :class:`RosGraphError` saying how to get them."""
    try:
        import nav2_msgs.action as nav2
        import rclpy
        import rclpy.action as action
        import rclpy.context as context
        import rclpy.executors as executors
        import rclpy.parameter as parameter
    except ImportError as exc:
        raise RosGraphError(
            f"the ROS 2 adapter needs rclpy and nav2_msgs, which this Python cannot import ({exc}): "
            "install ROS 2 Jazzy's wheels into exscec's environment (pip install 'exsce[ros2]', then "
            f"sh scripts/install-ros2 from exsce's repository), or {SOURCE_HINT} in the shell that runs "
            "exscec, with a Python of the distro's version (3.12 for Jazzy)"
        ) from None
    return Ros2Modules(rclpy, context, action, executors, parameter, nav2)


class Ros2Clock:
    """The node's clock, in seconds (simulated time under ``use_sim_time``)."""

    def __init__(self, node: Any) -> None:
        self.node = node

    def now(self) -> float:
        return float(self.node.get_clock().now().nanoseconds) / 1e9


class Ros2Navigator:
    """The core's :class:`~exsce_dsl.execute.navigator.Navigator` over Nav2's ``NavigateToPose``:
    ``clients`` maps each robot to its action client, ``executor`` spins their node."""

    def __init__(
        self, modules: Ros2Modules, executor: Any, clients: Mapping[str, Any], clock: Ros2Clock
    ) -> None:
        self.modules, self.executor, self.clients, self.clock = modules, executor, dict(clients), clock
        self._ended: deque[Finished] = deque()
        self._handles: dict[int, Any] = {}
        self._cancelled: set[int] = set()
        self._unanswered: set[int] = set()
        """Goals sent whose acceptance or rejection has not come yet."""

    def send(self, goal: int, robot: str, pose: Pose) -> None:
        message = self.modules.nav2.NavigateToPose.Goal()
        stamped = stamped_pose(pose)
        message.pose.header.frame_id = stamped.frame_id
        message.pose.header.stamp = self.clock.node.get_clock().now().to_msg()
        position, orientation = message.pose.pose.position, message.pose.pose.orientation
        position.x, position.y, position.z = stamped.position
        orientation.x, orientation.y, orientation.z, orientation.w = stamped.orientation
        future = self.clients[robot].send_goal_async(message)
        self._unanswered.add(goal)
        future.add_done_callback(lambda done: self._accepted(goal, done))

    def cancel(self, goal: int) -> None:
        self._cancelled.add(goal)
        handle = self._handles.get(goal)
        if handle is not None:  # else: cancelled when its acceptance comes
            handle.cancel_goal_async()

    def next_finished(self, deadline: float) -> Finished | None:
        while not self._ended:
            left = deadline - self.clock.now()
            if left <= 0:
                return None
            self.executor.spin_once(timeout_sec=min(left, WAIT_SLICE))
        return self._ended.popleft()

    def _accepted(self, goal: int, future: Any) -> None:
        self._unanswered.discard(goal)
        handle = future.result()
        if not handle.accepted:
            self._end(goal, GoalOutcome.REJECTED)
            return
        if goal in self._cancelled:  # cancelled while its acceptance was on the way
            handle.cancel_goal_async()
            return
        self._handles[goal] = handle
        handle.get_result_async().add_done_callback(lambda done: self._result(goal, done))

    def cancel_active(self) -> None:
        """Cancel every goal sent and not ended (a run left by an exception, Ctrl-C among them),
        waiting up to :data:`CANCEL_WAIT` for the acceptances still on their way."""
        for goal in sorted(set(self._handles) | self._unanswered):
            self.cancel(goal)
        deadline = time.monotonic() + CANCEL_WAIT
        while self._unanswered and time.monotonic() < deadline:
            self.executor.spin_once(timeout_sec=WAIT_SLICE)

    def _result(self, goal: int, future: Any) -> None:
        self._handles.pop(goal, None)
        outcome = goal_outcome(int(future.result().status))
        self._end(goal, GoalOutcome.ABORTED if outcome is None else outcome)

    def _end(self, goal: int, outcome: GoalOutcome) -> None:
        if goal not in self._cancelled:  # the dispatcher's own cancels are not reported
            self._ended.append(Finished(goal, outcome, self.clock.now()))
