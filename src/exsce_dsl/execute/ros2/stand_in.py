"""exsce's stand-in robots on a live ROS 2 graph: Nav2-like robots on simulated time.

Per robot namespace a ``nav2_msgs/action/NavigateToPose`` and a ``FollowWaypoints`` server (on
the names the robot's convention gives, ``/{ns}/navigate_to_pose`` and ``/{ns}/follow_waypoints``
by default) and the topics of :mod:`.robot_topics`;
``/clock`` for the whole graph, ``speed_up`` times faster than wall time.  A goal is answered with a
leg of :class:`~exsce_dsl.execute.stand_in.legs.Fleet` (planned on the scenario's occupancy grid
from where the robot stands, driven with its limits and the executor's faults, the same legs as
the ROS 1 stand-in's), played sample by sample; the goal then succeeds or aborts, with feedback
(``current_pose``, ``distance_remaining``, ``navigation_time``) on the way.  A cancel stops the
robot where it is (CANCELED); a new goal preempts the active one (ABORTED), as Nav2's navigator
does.  While a goal's leg is planned, simulated time stands still, as a simulator's does while its
physics steps.

Everything runs in this process: rclpy's executor (goals, cancels) on threads of its own, the
clock on another.  ``Fleet`` is called under :attr:`Ros2StandIn.planning` only; the robots'
playing state under :attr:`Ros2StandIn.lock`, never while an rclpy call of a goal handle is made.
"""

from __future__ import annotations

import importlib
import math
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from types import ModuleType, TracebackType
from typing import Any

import numpy as np

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.execute.ros2.live import Ros2Modules, require_rclpy
from exsce_dsl.execute.ros2.nav2 import nav2_actions
from exsce_dsl.execute.ros2.robot_topics import DT_NS, FEEDBACK_EVERY, TOPICS, RobotMessages
from exsce_dsl.execute.stand_in.irsim_legs import IrsimFleet
from exsce_dsl.execute.stand_in.legs import Fleet, StandInLeg
from exsce_dsl.execute.stand_in.session import DEFAULT_SPEED_UP, GoalEnd, Stats
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model import Scenario
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.sim.faults import Fault
from exsce_dsl.sim.laser import SCAN_EVERY

NODE = "exsce_stand_in"
MESSAGE_PACKAGES = (
    "builtin_interfaces",
    "rosgraph_msgs",
    "nav_msgs",
    "geometry_msgs",
    "sensor_msgs",
    "tf2_msgs",
)
TICK = 0.01
"""Wall seconds between two publishing rounds."""
MAX_LAG_NS = 200_000_000
"""Simulated time runs no further ahead of what was published (a round after a stall moves the
clock 0.2 s at most, not ``speed_up`` times the stall)."""
DEPTH = 2000
"""Messages each publisher keeps for a reader that falls behind (a recorder stalled a moment: at
5x, 2000 odometry messages are 8 s of wall time), as the ROS 1 stand-in's queues."""
WAIT = 0.005
"""Wall seconds between two looks of a goal's thread at its end."""
ERROR_NONE, ERROR_UNKNOWN, ERROR_WAYPOINT = 0, 9000, 600
"""Nav2's error codes: none; NavigateToPose's UNKNOWN; FollowWaypoints' UNKNOWN."""
Feedback = Callable[[int, np.ndarray, float, int], None]
"""Publishes a goal's feedback at a sample: (ns, row, metres left, the leg's sample)."""


@dataclass
class PlayedRobot:
    """One robot as this node plays it."""

    name: str
    namespace: str
    held: np.ndarray
    """The row it stands at between goals (velocities zero)."""
    held_scan: np.ndarray
    publishers: dict[str, Any] = field(default_factory=dict)
    handle: Any = None
    """The goal it drives (or plans) for."""
    goal: str = ""
    leg: StandInLeg | None = None
    rows: np.ndarray | None = None
    remaining: np.ndarray | None = None
    """Metres left along the leg after each sample."""
    start: int = 0
    """The global sample of the leg's first one."""
    planning: bool = False
    feedback: Feedback | None = None
    ends: dict[int, str] = field(default_factory=dict)
    """Goals ended by the clock: id of their handle → ``succeeded`` | ``aborted``."""


class Ros2StandIn:
    """The scenario's robots on the ROS 2 graph of this process's environment (``ROS_DOMAIN_ID``).
    Long because: the goals' threads (what each goal drives) and the clock's (what each sample
    publishes) share the robots' playing state under one lock; split in two, each half would
    reach into the other's state."""

    def __init__(
        self,
        scenario: Scenario,
        *,
        seed: int = 0,
        faults: Sequence[Fault] = (),
        speed_up: float = DEFAULT_SPEED_UP,
        run: int = 0,
        simulator: str = "kinematic",
        behaviour: str | None = None,
    ) -> None:
        """``simulator``: what drives the legs, ``kinematic`` (the kinematic executor's motion) or
        ``irsim`` (IR-SIM, with ``behaviour``, default ``rvo``)."""
        if not speed_up > 0:
            raise ExsceError(f"the stand-in's speed-up must be above 0, not {speed_up:g}")
        self.scenario, self.speed_up = scenario, speed_up
        grid = planning_grid(scenario)
        if simulator == "irsim":
            self.fleet: Fleet = IrsimFleet(scenario, grid, seed, tuple(faults), behaviour or "rvo", run=run)
        elif simulator == "kinematic" and behaviour is None:
            self.fleet = Fleet(scenario, grid, seed, tuple(faults), run=run)
        else:
            raise ExsceError(
                f"the stand-in's legs are driven by 'kinematic' or 'irsim' (a behaviour with irsim only), "
                f"not {simulator!r}" + (f" with behaviour {behaviour!r}" if behaviour else "")
            )
        played = [r for r in scenario.robots if r.id in self.fleet.robots]
        self.actions = {r.id: nav2_actions(r).navigate_to_pose for r in played}
        self.waypoint_actions = {r.id: nav2_actions(r).follow_waypoints for r in played}
        self.lock = threading.RLock()
        self.planning = threading.Lock()
        self.robots: dict[str, PlayedRobot] = {}
        self.ended: list[GoalEnd] = []
        self.counts: dict[str, int] = {}
        self.start_ns = 0
        self.published = 0
        self.running = False
        self._failure: BaseException | None = None
        self._threads: list[threading.Thread] = []
        self._context: Any = None

    # -- starting and stopping ---------------------------------------------------------------

    def __enter__(self) -> Ros2StandIn:
        self.start()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def start(self) -> None:
        modules = require_rclpy()
        msgs = {p: importlib.import_module(f"{p}.msg") for p in MESSAGE_PACKAGES}
        self.topics = RobotMessages(msgs, self.fleet.laser)
        for leg in self.fleet.start_legs():
            rows = leg.rows()
            self.robots[leg.robot] = PlayedRobot(
                leg.robot, self.fleet.robots[leg.robot].namespace, rows[-1], leg.scans[-1]
            )
        rclpy = modules.rclpy
        self._context = modules.context.Context()
        rclpy.init(context=self._context, signal_handler_options=_no_signal_handlers(rclpy))
        self.node = rclpy.create_node(NODE, context=self._context)
        self._create_endpoints(modules, msgs)
        executor = modules.executors.MultiThreadedExecutor(
            num_threads=2 + len(self.robots), context=self._context
        )
        executor.add_node(self.node)
        self._executor = executor
        self.start_ns = int(time.time()) * 1_000_000_000
        self.wall_start = time.monotonic()
        self.running = True
        self._publish_clock(self.start_ns)
        for robot in self.robots.values():
            self._publish(robot, "tf_static", self.topics.static(self.topics.stamp(self.start_ns)))
        for target, name in ((self._run, "stand-in clock"), (executor.spin, "stand-in executor")):
            thread = threading.Thread(target=self._guarded(target), name=name, daemon=True)
            thread.start()
            self._threads.append(thread)

    def close(self) -> None:
        """Stop the clock, end the goals still driven (aborted), then the executor and the node."""
        self.running = False
        if isinstance(self.fleet, IrsimFleet):
            with self.planning:
                self.fleet.close()
        clock, spinner = self._threads if self._threads else (None, None)
        if clock is not None:
            clock.join(5.0)
        if self._context is None:
            return
        deadline = time.monotonic() + 5.0
        while any(r.handle is not None for r in self.robots.values()) and time.monotonic() < deadline:
            time.sleep(WAIT)  # their threads see running False and abort them
        self._executor.shutdown(timeout_sec=5.0)
        if spinner is not None:
            spinner.join(5.0)
        for server in self.servers:
            server.destroy()
        self.node.destroy_node()
        self._context.try_shutdown()
        self._context = None

    def _create_endpoints(self, modules: Ros2Modules, msgs: dict[str, ModuleType]) -> None:
        qos = importlib.import_module("rclpy.qos")
        latched = qos.QoSProfile(
            depth=1,
            reliability=qos.ReliabilityPolicy.RELIABLE,
            durability=qos.DurabilityPolicy.TRANSIENT_LOCAL,
        )
        types = {
            "odom": msgs["nav_msgs"].Odometry,
            "tf": msgs["tf2_msgs"].TFMessage,
            "tf_static": msgs["tf2_msgs"].TFMessage,
            "amcl_pose": msgs["geometry_msgs"].PoseWithCovarianceStamped,
            "cmd_vel": msgs["geometry_msgs"].Twist,
            "scan": msgs["sensor_msgs"].LaserScan,
        }
        self.clock_publisher = self.node.create_publisher(msgs["rosgraph_msgs"].Clock, "/clock", DEPTH)
        group = importlib.import_module("rclpy.callback_groups").ReentrantCallbackGroup()
        self.servers = []
        for robot in self.robots.values():
            plan = expand_topic("/{ns}/plan", robot.namespace)
            robot.publishers["plan"] = self.node.create_publisher(msgs["nav_msgs"].Path, plan, DEPTH)
            for name in TOPICS:
                depth = latched if name == "tf_static" else DEPTH
                topic = expand_topic("/{ns}/" + name, robot.namespace)
                robot.publishers[name] = self.node.create_publisher(types[name], topic, depth)
            served = (
                (modules.nav2.NavigateToPose, self.actions[robot.name], self._execute),
                (modules.nav2.FollowWaypoints, self.waypoint_actions[robot.name], self._follow),
            )
            for action, name, execute in served:
                self.servers.append(
                    modules.action.ActionServer(
                        self.node,
                        action,
                        name,
                        execute_callback=lambda handle, r=robot, run=execute: run(r, handle),
                        cancel_callback=lambda request: modules.action.CancelResponse.ACCEPT,
                        callback_group=group,
                    )
                )
        self.nav2 = modules.nav2
        self.missed_type = importlib.import_module("nav2_msgs.msg").MissedWaypoint

    def _guarded(self, target: Any) -> Any:
        def run() -> None:
            try:
                target()
            except BaseException as e:  # noqa: BLE001  # kept for check(): the stand-in is useless without it
                if self.running:
                    self._failure = e
                    self.running = False

        return run

    # -- what callers ask --------------------------------------------------------------------

    def check(self) -> None:
        """Raise what stopped the stand-in, if something did."""
        if self._failure is not None:
            if isinstance(self._failure, ExsceError):
                raise self._failure
            raise RosGraphError(f"the stand-in failed: {type(self._failure).__name__}: {self._failure}")

    def wait(self, timeout: float | None = None) -> None:
        """Serve until the stand-in fails (an error saying why) or ``timeout`` seconds have passed."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.running and (deadline is None or time.monotonic() < deadline):
            time.sleep(0.1)
        self.check()

    def stats(self) -> Stats:
        with self.lock:
            sim = (self._time_of(self.published) - self.start_ns) / 1e9
            return Stats(sim, time.monotonic() - self.wall_start, dict(self.counts))

    def goals_ended(self) -> list[GoalEnd]:
        with self.lock:
            return list(self.ended)

    # -- goals, on the executor's threads ------------------------------------------------------

    def _execute(self, robot: PlayedRobot, handle: Any) -> Any:
        """A ``NavigateToPose`` goal: driven to its pose, with Nav2's feedback on the way."""
        goal = bytes(handle.goal_id.uuid).hex()

        def feedback(t: int, row: np.ndarray, remaining: float, k: int) -> None:
            message = self.nav2.NavigateToPose.Feedback()
            message.current_pose = self.topics.where(self.topics.stamp(t), row)
            message.distance_remaining = remaining
            message.navigation_time.sec, message.navigation_time.nanosec = divmod(k * DT_NS, 1_000_000_000)
            handle.publish_feedback(message)

        outcome, when = self._drive(robot, handle, goal, handle.request.pose.pose, feedback)
        self._end(robot, handle, goal, outcome, when)
        return self.nav2.NavigateToPose.Result(
            error_code=ERROR_NONE if outcome == "succeeded" else ERROR_UNKNOWN
        )

    def _follow(self, robot: PlayedRobot, handle: Any) -> Any:
        """A ``FollowWaypoints`` goal: its poses driven in order, ``current_waypoint`` as feedback;
        a waypoint that fails stops the goal (ABORTED, the waypoint missed), as Nav2's waypoint
        follower does by default (``stop_on_failure``)."""
        goal = bytes(handle.goal_id.uuid).hex()
        action = self.nav2.FollowWaypoints
        missed, outcome, when = [], "succeeded", self._time_of(self.published) / 1e9
        for index, stamped in enumerate(handle.request.poses):

            def feedback(t: int, row: np.ndarray, remaining: float, k: int, index: int = index) -> None:
                handle.publish_feedback(action.Feedback(current_waypoint=index))

            outcome, when = self._drive(robot, handle, f"{goal}-{index}", stamped.pose, feedback)
            if outcome != "succeeded":
                if outcome == "aborted":
                    missed.append(self.missed_type(index=index, goal=stamped, error_code=ERROR_WAYPOINT))
                break
        self._end(robot, handle, goal, outcome, when)
        return action.Result(
            missed_waypoints=missed, error_code=ERROR_NONE if outcome == "succeeded" else ERROR_WAYPOINT
        )

    def _drive(
        self, robot: PlayedRobot, handle: Any, goal: str, target: Any, feedback: Feedback
    ) -> tuple[str, float]:
        """Drive ``robot`` to ``target`` (a geometry_msgs/Pose) for ``handle``: the leg planned
        (simulated time standing still meanwhile) and played; how it ended and when."""
        q = target.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        with self.lock:
            preempted = robot.handle
            if preempted is not None and preempted is not handle:  # Nav2: a new goal preempts
                self._stop(robot)
                robot.ends[id(preempted)] = "aborted"
            robot.handle, robot.goal, robot.planning, robot.feedback = handle, goal, True, feedback
            when_ns = self._time_of(self.published)
        try:
            with self.planning:
                leg = self.fleet.leg(
                    robot.name, goal, target.position.x, target.position.y, yaw, when_ns / 1e9
                )
        except ExsceError:
            with self.lock:
                robot.handle, robot.planning = None, False
            return "aborted", when_ns / 1e9
        if leg.succeeded:  # Nav2's planner publishes the global plan of a goal it can reach
            # the path ends at the goal's pose, as a planner's does (a leg ends within tolerance of it)
            xs, ys = np.append(leg.truth.x, target.position.x), np.append(leg.truth.y, target.position.y)
            path = self.topics.plan(self.topics.stamp(when_ns), xs, ys, yaw)
            with self.lock:
                self._publish(robot, "plan", path)
        with self.lock:
            if robot.handle is handle:
                robot.leg, robot.rows, robot.start = leg, leg.rows(), self.published + 1
                robot.remaining = _distance_left(leg)
            robot.planning = False
        return self._await_end(robot, handle)

    def _await_end(self, robot: PlayedRobot, handle: Any) -> tuple[str, float]:
        while True:
            with self.lock:
                outcome = robot.ends.pop(id(handle), None)
                if outcome is None and handle.is_cancel_requested and robot.handle is handle:
                    self._stop(robot)
                    outcome = "canceled"
                if outcome is None and not self.running:
                    outcome = "aborted"
                    if robot.handle is handle:
                        robot.handle = None
                now = self._time_of(self.published) / 1e9
            if outcome is not None:
                return outcome, now
            time.sleep(WAIT)

    def _end(self, robot: PlayedRobot, handle: Any, goal: str, outcome: str, when: float) -> None:
        if outcome == "succeeded":
            handle.succeed()
        elif outcome == "canceled":
            handle.canceled()
        else:
            handle.abort()
        with self.lock:
            self.ended.append(GoalEnd(robot.name, goal, outcome, when))

    def _stop(self, robot: PlayedRobot) -> None:
        """Stop ``robot`` where it is now (holding :attr:`lock`)."""
        leg, k = robot.leg, -1
        if leg is not None and robot.rows is not None:
            k = min(max(self.published - robot.start, -1), len(leg) - 1)
            if k >= 0:
                robot.held = _standing(robot.rows[k])
                robot.held_scan = leg.scans[min(k // SCAN_EVERY, len(leg.scans) - 1)]
        with self.planning:
            self.fleet.stopped(robot.name, robot.goal, k)
        robot.handle, robot.leg, robot.rows, robot.remaining = None, None, None, None

    # -- the clock ---------------------------------------------------------------------------

    def _time_of(self, sample: int) -> int:
        return self.start_ns + sample * DT_NS

    def _run(self) -> None:
        """Publish every sample up to simulated now, each after its ``/clock``; TICK wall seconds a round."""
        base_wall, base_sim = time.monotonic(), self.start_ns
        while self.running:
            now = time.monotonic()
            with self.lock:
                published_ns = self._time_of(self.published)
                planning = any(r.planning for r in self.robots.values())
            if planning:  # simulated time stands still while a leg is planned
                base_wall, base_sim = now, published_ns
                time.sleep(TICK)
                continue
            target = base_sim + int(self.speed_up * (now - base_wall) * 1e9)
            if target - published_ns > MAX_LAG_NS:
                target = published_ns + MAX_LAG_NS
                base_wall, base_sim = now, target
            last = (target - self.start_ns) // DT_NS
            with self.lock:
                while self.published < last:
                    self._publish_clock(self._time_of(self.published + 1))
                    self._publish_sample(self.published + 1)
                    self.published += 1
                if target > self._time_of(self.published):
                    self._publish_clock(target)
            time.sleep(TICK)

    def _publish_clock(self, ns: int) -> None:
        self.clock_publisher.publish(self.topics.clock(ns))
        self.counts["/clock"] = self.counts.get("/clock", 0) + 1

    def _publish(self, robot: PlayedRobot, name: str, message: Any) -> None:
        robot.publishers[name].publish(message)
        key = expand_topic("/{ns}/" + name, robot.namespace)
        self.counts[key] = self.counts.get(key, 0) + 1

    def _publish_sample(self, n: int) -> None:
        t = self._time_of(n)
        for robot in self.robots.values():
            row, scan, k = robot.held, robot.held_scan, -1
            leg, rows = robot.leg, robot.rows
            if leg is not None and rows is not None and n >= robot.start:
                k = n - robot.start
                row, scan = rows[k], leg.scans[min(k // SCAN_EVERY, len(leg.scans) - 1)]
            for name, message in self.topics.sample(n, t, row, scan):
                self._publish(robot, name, message)
            if leg is None or k < 0:
                continue
            if k % FEEDBACK_EVERY == 0 and robot.remaining is not None and robot.feedback is not None:
                robot.feedback(t, row, float(robot.remaining[k]), k)
            if k == len(leg) - 1:
                robot.held, robot.held_scan = _standing(row), scan
                robot.ends[id(robot.handle)] = "succeeded" if leg.succeeded else "aborted"
                robot.handle, robot.leg, robot.rows, robot.remaining = None, None, None, None


def _distance_left(leg: StandInLeg) -> np.ndarray:
    """Metres the leg's path goes on after each of its samples."""
    x, y = leg.truth.x, leg.truth.y
    steps = np.hypot(np.diff(x, prepend=x[0]), np.diff(y, prepend=y[0]))
    return np.asarray(np.cumsum(steps[::-1])[::-1] - steps)


def _standing(row: np.ndarray) -> np.ndarray:
    """A row with its velocities zero: the robot stands where the row has it."""
    held = np.array(row, dtype=float)
    held[9:] = 0.0
    return held


def _no_signal_handlers(rclpy: ModuleType) -> Any:
    """rclpy's option not to install its SIGINT/SIGTERM handlers: exscec's own handle them."""
    return importlib.import_module("rclpy.signals").SignalHandlerOptions.NO
