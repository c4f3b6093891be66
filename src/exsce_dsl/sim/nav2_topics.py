"""Nav2's topics: the robot's own (:mod:`exsce_dsl.sim.stack_topics`) and its
``navigate_to_pose`` action, one goal per planned waypoint.

| topic | type | when |
|---|---|---|
| ``navigate_to_pose/_action/status`` | action_msgs/GoalStatusArray | at each change, 1 Hz; latched |
| ``navigate_to_pose/_action/feedback`` | nav2_msgs/action/NavigateToPose_FeedbackMessage | 5 Hz, executing |
| ``plan`` | nav_msgs/Path, ending at the goal's target | once at each goal's start |

A goal's target is on no action topic (the goal is sent through a service), so a reader finds it
as the last pose of the plan published when the goal starts, as Nav2's planner publishes it.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np

from exsce_dsl.messages.navigation import stored_name
from exsce_dsl.model.goals import ActionGoalStatus
from exsce_dsl.sim.batches import Batch
from exsce_dsl.sim.goals import NavigationGoal, Phase, listed, navigation_goals, status_samples
from exsce_dsl.sim.localisation import Localisation, localise
from exsce_dsl.sim.stack_topics import MAP, stack_messages
from exsce_dsl.sim.values import duration, header, pose, ros_time, sample_stamps, samples_per
from exsce_dsl.sim.writing import Message, RobotRun

ACTION = "navigate_to_pose"
FEEDBACK = "nav2_msgs/action/NavigateToPose_FeedbackMessage"
FEEDBACK_FIELDS = "nav2_msgs/action/NavigateToPose_Feedback"
STATUS = "action_msgs/msg/GoalStatusArray"
CODES = {
    Phase.ACCEPTED: ActionGoalStatus.ACCEPTED,
    Phase.EXECUTING: ActionGoalStatus.EXECUTING,
    Phase.SUCCEEDED: ActionGoalStatus.SUCCEEDED,
    Phase.ABORTED: ActionGoalStatus.ABORTED,
}
"""action_msgs/GoalStatus values (CANCELED is never reached: the executor cancels nothing)."""
STATUS_PERIOD, FEEDBACK_PERIOD = 1.0, 0.2  # seconds: 1 Hz, 5 Hz
RESULT_TIMEOUT = 900.0
"""Seconds a finished goal stays in the status list (rcl_action's default result timeout)."""
PLAN_SPACING = 0.05  # metres between the poses of a published plan (a grid planner's cell)
LATCHED = ("tf_static", f"{ACTION}/_action/status")


def nav2_messages(run: RobotRun) -> Iterator[Message | Batch]:
    """Every message of one robot driven by Nav2."""
    tr = run.execution.trajectories[run.robot]
    stamps = sample_stamps(run.start_ns, len(tr), run.execution.dt)
    frames = localise(tr, run.rng, dt=run.execution.dt)
    yield from stack_messages(run, frames, stamps)
    goals = navigation_goals(run.execution, run.robot, run.rng)
    yield from _status(run, goals, stamps)
    for goal in goals:
        yield run.topic("plan"), "nav_msgs/msg/Path", int(stamps[goal.accepted]), plan(run, goal, stamps)
        yield from _feedback(run, goal, frames, stamps)


def plan(run: RobotRun, goal: NavigationGoal, stamps: np.ndarray) -> Any:
    """The goal's path in ``map``, a pose every PLAN_SPACING metres facing along it; the last pose
    is the target, with its heading."""
    T, store, stamp = run.store.types, run.store, int(stamps[goal.accepted])
    target = goal.target
    points = np.asarray(goal.path or ((target.position.x, target.position.y),), dtype=np.float64)
    dense = _densified(points)
    headings = np.arctan2(np.diff(dense[:, 1]), np.diff(dense[:, 0]))
    poses = [
        T["geometry_msgs/msg/PoseStamped"](header=header(store, stamp, MAP), pose=pose(store, x, y, yaw))
        for (x, y), yaw in zip(dense[:-1].tolist(), headings.tolist(), strict=True)
    ]
    end = pose(store, target.position.x, target.position.y, target.orientation.yaw, target.position.z)
    poses.append(T["geometry_msgs/msg/PoseStamped"](header=header(store, stamp, MAP), pose=end))
    return T["nav_msgs/msg/Path"](header=header(store, stamp, MAP), poses=poses)


def _status(run: RobotRun, goals: list[NavigationGoal], stamps: np.ndarray) -> Iterator[Message]:
    T, store = run.store.types, run.store
    topic = run.topic(f"{ACTION}/_action/status")
    for sample in status_samples(goals, len(stamps), samples_per(STATUS_PERIOD, run.execution.dt)):
        status_list = [
            T["action_msgs/msg/GoalStatus"](
                goal_info=T["action_msgs/msg/GoalInfo"](
                    goal_id=_uuid(run, goal), stamp=ros_time(store, int(stamps[goal.accepted]))
                ),
                status=CODES[phase],
            )
            for goal, phase in listed(goals, sample, RESULT_TIMEOUT, run.execution.dt)
        ]
        yield topic, STATUS, int(stamps[sample]), T[STATUS](status_list=status_list)


def _feedback(
    run: RobotRun, goal: NavigationGoal, frames: Localisation, stamps: np.ndarray
) -> Iterator[Message]:
    T, store = run.store.types, run.store
    kind, fields = stored_name(store, FEEDBACK), stored_name(store, FEEDBACK_FIELDS)
    samples = np.arange(goal.executing, goal.ended, samples_per(FEEDBACK_PERIOD, run.execution.dt))
    if not len(samples):
        return
    estimate = frames.estimate
    remaining = _remaining(np.asarray(goal.path, dtype=np.float64), estimate.x[samples], estimate.y[samples])
    for i, left in zip(samples.tolist(), remaining.tolist(), strict=True):
        speed = abs(float(frames.v[i]))
        eta = left / speed if speed > 0.01 and left > 0.1 else 0.0  # as Nav2 estimates it
        feedback = T[fields](
            current_pose=T["geometry_msgs/msg/PoseStamped"](
                header=header(store, int(stamps[i]), MAP),
                pose=pose(store, estimate.x[i], estimate.y[i], estimate.yaw[i]),
            ),
            navigation_time=duration(store, (i - goal.accepted) * run.execution.dt),
            estimated_time_remaining=duration(store, eta),
            number_of_recoveries=0,
            distance_remaining=left,
        )
        msg = T[kind](goal_id=_uuid(run, goal), feedback=feedback)
        yield run.topic(f"{ACTION}/_action/feedback"), kind, int(stamps[i]), msg


def _uuid(run: RobotRun, goal: NavigationGoal) -> Any:
    return run.store.types["unique_identifier_msgs/msg/UUID"](uuid=np.frombuffer(goal.uuid, dtype=np.uint8))


def _densified(points: np.ndarray) -> np.ndarray:
    """The polyline with a point at least every PLAN_SPACING metres (its corners kept)."""
    out = [points[:1]]
    for a, b in zip(points[:-1], points[1:], strict=True):
        steps = max(int(math.ceil(float(np.hypot(*(b - a))) / PLAN_SPACING)), 1)
        out.append(a + (b - a) * (np.arange(1, steps + 1) / steps)[:, None])
    dense: np.ndarray = np.concatenate(out)
    return dense


def _remaining(path: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Length of ``path`` left from the point of it nearest to each (x, y)."""
    if len(path) < 2:
        return np.zeros(len(x))
    a, ab = path[:-1], np.diff(path, axis=0)
    length = np.hypot(ab[:, 0], ab[:, 1])
    after = np.concatenate([np.cumsum(length[::-1])[::-1][1:], [0.0]])  # path left after each segment
    p = np.column_stack([x, y])[:, None, :]
    t = np.clip(((p - a) * ab).sum(axis=2) / np.maximum(length**2, 1e-12), 0.0, 1.0)
    gap = np.hypot(*np.moveaxis(a + t[..., None] * ab - p, 2, 0))
    nearest = np.argmin(gap, axis=1)
    rows = np.arange(len(x))
    left: np.ndarray = after[nearest] + (1.0 - t[rows, nearest]) * length[nearest]
    return left
