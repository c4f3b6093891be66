"""Path segments from the waypoint dispatcher's goal statuses.

Each robot's dispatcher runs one goal per subtask, with one status per
waypoint that moves PENDING → ACTIVE → SUCCEEDED/ABORTED.  An action (a path
segment) is one waypoint from the update where it became ACTIVE to the one
where it reached a final status; it starts at the robot's previous pose.
Goals are matched, in order, to the subtasks the mission allocates to the
robot: a bag whose waypoint ids differ is from another scenario.
"""

from __future__ import annotations

from exsce_dsl.errors import SegmentError
from exsce_dsl.model import Pose, Scenario
from exsce_dsl.model.goals import ACTIONLIB_FINAL, GoalStatus, actionlib_names
from exsce_dsl.runs.segments.recorded import RecordedAction
from exsce_dsl.runs.signals.dispatcher_statuses import StatusUpdate
from exsce_dsl.wording import counted

ACTIVE, SUCCEEDED = GoalStatus.ACTIVE, GoalStatus.SUCCEEDED
FINAL = {code: name for code, name in actionlib_names().items() if code in ACTIONLIB_FINAL}


def segments(scenario: Scenario, robot: str, updates: list[StatusUpdate]) -> list[RecordedAction]:
    """The actions of ``robot`` in a run, from its dispatcher feedback ``updates`` (time order)."""
    plan = planned_goals(scenario, robot)
    goals = dispatcher_goals(updates)
    if len(goals) > len(plan):
        raise SegmentError(
            f"robot '{robot}' ran {counted(len(goals), 'dispatcher goal')} but scenario '{scenario.id}' "
            f"gives it {counted(len(plan), 'subtask')}: the bag is from another scenario"
        )
    out: list[RecordedAction] = []
    robot_decl = scenario.robot(robot)
    previous = robot_decl.start_pose if robot_decl is not None else None
    for index, (allocation, task, subtask, poses) in enumerate(plan):
        history = goals[index] if index < len(goals) else []
        ids = tuple(p.id for p in poses)
        if history and history[0].waypoints != ids:
            raise SegmentError(
                f"robot '{robot}': goal {index + 1} has waypoints {', '.join(history[0].waypoints)}, "
                f"but task '{task}' subtask {subtask} visits {', '.join(ids)}: "
                "the bag is from another scenario"
            )
        for w, goal in enumerate(poses):
            start = next((u.t for u in history if u.statuses[w] == ACTIVE), None)
            final = next(((u.t, u.statuses[w]) for u in history if u.statuses[w] in FINAL), None)
            status = FINAL[final[1]] if final else ("ACTIVE" if start is not None else "NOT_STARTED")
            assert previous is not None  # the checks ensure robots with tasks have a start pose
            out.append(
                RecordedAction(
                    robot,
                    allocation,
                    task,
                    subtask,
                    w + 1,
                    previous,
                    goal,
                    start,
                    final[0] if final else None,
                    status,
                )
            )
            if status == "SUCCEEDED":
                previous = goal
    return out


def planned_goals(scenario: Scenario, robot: str) -> list[tuple[int, str, int, tuple[Pose, ...]]]:
    plan = []
    allocation = 0
    for entry in scenario.mission.allocation:
        if entry.robot != robot:
            continue
        allocation += 1
        task = scenario.task(entry.task)
        assert task is not None
        for s, subtask in enumerate(task.subtasks, start=1):
            plan.append((allocation, task.id, s, subtask.waypoints))
    return plan


def succeeded_waypoints(final: list[StatusUpdate] | None) -> int | None:
    """Waypoints the dispatcher's results say SUCCEEDED (None: the bag has no result topic)."""
    return None if final is None else sum(s == SUCCEEDED for u in final for s in u.statuses)


def dispatcher_goals(updates: list[StatusUpdate]) -> list[list[StatusUpdate]]:
    """Group updates by goal: a new goal starts when the goal id or the waypoint list changes."""
    goals: list[list[StatusUpdate]] = []
    for update in updates:
        current = goals[-1] if goals else None
        same = (
            current is not None
            and current[-1].goal == update.goal
            and current[-1].waypoints == update.waypoints
        )
        restarted = (
            current is not None
            and all(s == 0 for s in update.statuses)
            and any(s != 0 for s in current[-1].statuses)
        )
        if same and not restarted:
            current.append(update)  # type: ignore[union-attr]
        else:
            goals.append([update])
    return goals
