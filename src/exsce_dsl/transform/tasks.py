"""The transformations of a task's plan: a new task made from one, in place of it."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario, Task
from exsce_dsl.model.derivation import TaskOrigin
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.transform.applied import Applied, recorded, with_allocation
from exsce_dsl.transform.records import Arguments, Parameter, Transformation


def reverse_waypoint_order(scenario: Scenario, a: Arguments, tasks: Mapping[str, Task]) -> Applied:
    """A new task with the waypoints of ``task`` in reverse order, substituted for it."""
    old = scenario.task(a["task"])
    if old is None:
        raise ExsceError(f"mission '{scenario.mission.id}' allocates no task '{a['task']}'")
    new_id = a.get("as", f"{old.id}_reversed")
    if not is_valid_name(new_id):
        raise ExsceError(f"'{new_id}' cannot be a task id")
    if new_id in tasks or scenario.task(new_id) is not None:
        raise ExsceError(f"there is a task '{new_id}' already; name the reversed one with 'as'")
    subtasks = tuple(replace(s, waypoints=tuple(reversed(s.waypoints))) for s in reversed(old.subtasks))
    # not the source file of the old task any more; the same time for each goal
    reversed_task = Task(new_id, subtasks, timeout=old.timeout, timeout_written=old.timeout_written)
    allocation = [replace(e, task=new_id) if e.task == old.id else e for e in scenario.mission.allocation]
    new = with_allocation(scenario, allocation, {new_id: reversed_task})
    step = recorded("reverse_waypoint_order", task=old.id, to=new_id)
    return Applied(new, (reversed_task,), (step,), (TaskOrigin(new_id, old.id, 1),))


TASKS: tuple[Transformation, ...] = (
    Transformation(
        "reverse_waypoint_order",
        (Parameter("task", "task"), Parameter("as", "new_task", False)),
        reverse_waypoint_order,
        "a new task AS: TASK's waypoints reversed",
        ("reverse waypoints of {task} [as {as}]",),
        ("task", "to"),
    ),
)
