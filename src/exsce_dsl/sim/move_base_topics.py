"""move_base's topics (ROS 1 actionlib): the robot's own (:mod:`exsce_dsl.sim.stack_topics`) and
its ``move_base`` action, one goal per planned waypoint.

| topic | type | when |
|---|---|---|
| ``move_base/goal`` | move_base_msgs/MoveBaseActionGoal (the target pose) | when a goal is sent |
| ``move_base/status`` | actionlib_msgs/GoalStatusArray | at each change and at 5 Hz |
| ``move_base/feedback`` | move_base_msgs/MoveBaseActionFeedback (``base_position``) | 5 Hz while active |
| ``move_base/result`` | move_base_msgs/MoveBaseActionResult | when a goal ends |

Goal ids are actionlib's: ``<client>-<count>-<secs>.<nsecs>`` of the time the goal was sent, the
client named after the action (``/tiago1/move_base-1-1767225601.80000000``).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

from exsce_dsl.sim.batches import Batch
from exsce_dsl.sim.executor import GoalStatus
from exsce_dsl.sim.goals import NavigationGoal, Phase, listed, navigation_goals, status_samples
from exsce_dsl.sim.localisation import Localisation, localise
from exsce_dsl.sim.stack_topics import MAP, stack_messages
from exsce_dsl.sim.values import header, pose_stamped, ros_time, sample_stamps, samples_per
from exsce_dsl.sim.writing import Message, RobotRun

ACTION = "move_base"
GOAL = "move_base_msgs/msg/MoveBaseActionGoal"
FEEDBACK = "move_base_msgs/msg/MoveBaseActionFeedback"
RESULT = "move_base_msgs/msg/MoveBaseActionResult"
STATUS = "actionlib_msgs/msg/GoalStatusArray"
CODES = {
    Phase.ACCEPTED: GoalStatus.PENDING,
    Phase.EXECUTING: GoalStatus.ACTIVE,
    Phase.SUCCEEDED: GoalStatus.SUCCEEDED,
    Phase.ABORTED: GoalStatus.ABORTED,
}
TEXTS = {
    Phase.SUCCEEDED: "Goal reached.",
    Phase.ABORTED: "Failed to find a valid control. Even after executing recovery behaviors.",
}
"""What move_base says when a goal ends."""
STATUS_PERIOD, FEEDBACK_PERIOD = 0.2, 0.2  # seconds: 5 Hz (actionlib's status_frequency)
STATUS_LIST_TIMEOUT = 5.0
"""Seconds a finished goal stays in the status list (actionlib's default)."""
LATCHED = ("tf_static",)


def move_base_messages(run: RobotRun) -> Iterator[Message | Batch]:
    """Every message of one robot driven by move_base."""
    tr = run.execution.trajectories[run.robot]
    stamps = sample_stamps(run.start_ns, len(tr), run.execution.dt)
    frames = localise(tr, run.rng, dt=run.execution.dt)
    yield from stack_messages(run, frames, stamps)
    goals = navigation_goals(run.execution, run.robot, run.rng)
    ids = {goal.number: goal_id(run, goal, stamps) for goal in goals}
    yield from _status(run, goals, ids, stamps)
    for goal in goals:
        yield from _goal_and_result(run, goal, ids[goal.number], stamps)
        yield from _feedback(run, goal, ids[goal.number], frames, stamps)


def goal_id(run: RobotRun, goal: NavigationGoal, stamps: np.ndarray) -> Any:
    """actionlib_msgs/GoalID of a goal, stamped when it was sent."""
    sent = int(stamps[goal.accepted])
    text = f"{run.topic(ACTION)}-{goal.number}-{sent // 1_000_000_000}.{sent % 1_000_000_000}"
    return run.store.types["actionlib_msgs/msg/GoalID"](stamp=ros_time(run.store, sent), id=text)


def _status_of(run: RobotRun, goal_id: Any, phase: Phase) -> Any:
    return run.store.types["actionlib_msgs/msg/GoalStatus"](
        goal_id=goal_id, status=int(CODES[phase]), text=TEXTS.get(phase, "")
    )


def _status(
    run: RobotRun, goals: list[NavigationGoal], ids: dict[int, Any], stamps: np.ndarray
) -> Iterator[Message]:
    T, store = run.store.types, run.store
    every = samples_per(STATUS_PERIOD, run.execution.dt)
    for seq, sample in enumerate(status_samples(goals, len(stamps), every)):
        shown = listed(goals, sample, STATUS_LIST_TIMEOUT, run.execution.dt)
        status_list = [_status_of(run, ids[g.number], phase) for g, phase in shown]
        msg = T[STATUS](header=header(store, int(stamps[sample]), "", seq), status_list=status_list)
        yield run.topic(f"{ACTION}/status"), STATUS, int(stamps[sample]), msg


def _goal_and_result(run: RobotRun, goal: NavigationGoal, gid: Any, stamps: np.ndarray) -> Iterator[Message]:
    T, store = run.store.types, run.store
    sent, ended = int(stamps[goal.accepted]), int(stamps[goal.ended])
    target = goal.target
    target_pose = pose_stamped(
        store, sent, MAP, target.position.x, target.position.y, target.orientation.yaw, target.position.z
    )
    msg = T[GOAL](
        header=header(store, sent, "", goal.number - 1),
        goal_id=gid,
        goal=T["move_base_msgs/msg/MoveBaseGoal"](target_pose=target_pose),
    )
    yield run.topic(f"{ACTION}/goal"), GOAL, sent, msg
    result = T[RESULT](
        header=header(store, ended, "", goal.number - 1),
        status=_status_of(run, gid, goal.outcome),
        result=_empty(run, "move_base_msgs/msg/MoveBaseResult"),
    )
    yield run.topic(f"{ACTION}/result"), RESULT, ended, result


def _feedback(
    run: RobotRun, goal: NavigationGoal, gid: Any, frames: Localisation, stamps: np.ndarray
) -> Iterator[Message]:
    T, store = run.store.types, run.store
    estimate = frames.estimate
    for i in range(goal.executing, goal.ended, samples_per(FEEDBACK_PERIOD, run.execution.dt)):
        position = pose_stamped(store, int(stamps[i]), MAP, estimate.x[i], estimate.y[i], estimate.yaw[i])
        msg = T[FEEDBACK](
            header=header(store, int(stamps[i]), ""),
            status=_status_of(run, gid, Phase.EXECUTING),
            feedback=T["move_base_msgs/msg/MoveBaseFeedback"](base_position=position),
        )
        yield run.topic(f"{ACTION}/feedback"), FEEDBACK, int(stamps[i]), msg


def _empty(run: RobotRun, kind: str) -> Any:
    """An empty message (a typestore may give it rosidl's placeholder member)."""
    fields = run.store.fielddefs[kind][1]
    return run.store.types[kind](**{name: 0 for name, _ in fields})
