"""Build ``task`` declarations: subtasks of waypoints, each a declared pose or coordinates."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from exsce_dsl.lang.builders.context import BuildContext, Declared, ros_resource
from exsce_dsl.lang.builders.poses import orientation_of, position_of
from exsce_dsl.lang.lexical import quantity_text, read_duration
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Pose, Subtask, Task


def build_task(ctx: BuildContext, d: Declared) -> Task | None:
    """The task ``d`` declares (None: it has errors, reported)."""
    pf, task = d.file, d.obj
    subtasks: list[Subtask] = []
    ok = True
    coordinate_count = 0
    for number, sub in enumerate(task.subtasks, start=1):
        waypoints: list[Pose] = []
        for visit in sub.visits:
            for wp in visit.waypoints:
                if wp.__class__.__name__ == "CoordinateWaypoint":
                    coordinate_count += 1
                    name = f"{task.name}-w{coordinate_count:03d}"
                    position, orientation = position_of(wp.position), orientation_of(wp.orientation)
                    waypoints.append(Pose(name, position, orientation, None, pf.span(wp)))
                    continue
                pose = pose_use(ctx, pf, wp, ctx.task_poses)
                if pose is None:
                    ok = False
                else:
                    waypoints.append(pose)
        if not sub.visits and sub.__class__.__name__ == "Subtask":
            ctx.error(f"subtask {number} of task '{task.name}' has no waypoints", pf.span(sub))
            ok = False
        subtasks.append(Subtask(tuple(waypoints), pf.span(sub)))
    if not task.subtasks:
        ctx.error(f"task '{task.name}' has no waypoints; add 'visit <pose>'", d.name_location)
        ok = False
    timeout, written, fine = timeout_of(ctx, pf, task.timeout, f"task '{task.name}'")
    if not ok or not fine:
        return None
    return Task(task.name, tuple(subtasks), ros_resource(task.source), d.name_location, timeout, written)


def task_pose_candidates(ctx: BuildContext) -> dict[str, Pose | None]:
    """Pose ids a task may name: unambiguous ones map to their pose."""
    table: dict[str, Pose | None] = {}
    for pose_id, found in ctx.poses.items():
        distinct = {(p.position, p.orientation) for _, p in found}
        table[pose_id] = found[0][1] if len(distinct) == 1 else None
    return table


def pose_use(ctx: BuildContext, pf: ParsedFile, use: Any, table: Mapping[str, Pose | None]) -> Pose | None:
    """The pose a waypoint or start names (from ``table``), at the place it is named."""
    name = use.pose.name
    where = pf.span(use.pose)
    if name not in table:
        ctx.unknown_name("pose", name, where, table)
        return None
    pose = table[name]
    if pose is None:
        envs = ", ".join(sorted(e for e, _ in ctx.poses[name]))
        ctx.error(
            f"pose '{name}' is declared differently in environments {envs}; "
            "a task cannot tell which one it means",
            where,
            code="reference",
        )
        return None
    loc = pf.span(use)
    if use.orientation is not None:
        return Pose(pose.id, pose.position, orientation_of(use.orientation), pose.area, loc)
    return Pose(pose.id, pose.position, pose.orientation, pose.area, loc)


def timeout_of(
    ctx: BuildContext, pf: ParsedFile, node: Any, whose: str
) -> tuple[float | None, str | None, bool]:
    """A ``timeout`` in seconds and as written (None, None: none given); False: it was wrong,
    and reported at its number."""
    if node is None:
        return None, None, True
    text = node.duration
    where = pf.lines.span(node._tx_position_end - len(text), node._tx_position_end)
    seconds = read_duration(text)
    if seconds is None:
        ctx.error(f"the timeout of {whose} has no unit; write '{text} s' or '{text} min'", where)
        return None, None, False
    if not seconds > 0:
        ctx.error(f"the timeout of {whose} must be above 0 s, not {quantity_text(text)}", where)
        return None, None, False
    return seconds, text, True
