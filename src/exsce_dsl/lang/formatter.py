"""The formatter: semantic model → canonical ``.exsce`` text.

textX has no model-to-text, so we own one.  Printing a parsed file and
parsing the result gives back an equal model (a tested round trip), and
printing is idempotent.  Comments are not part of the model and are not kept.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from decimal import Decimal

from exsce_dsl.model import (
    Document,
    Environment,
    Orientation,
    Pose,
    Position,
    RobotType,
    RosResource,
    Scenario,
    Specification,
    Task,
)

INDENT = "  "
_LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}


def format_spec_document(spec: Specification, path: str | None = None) -> str:
    """The canonical text of one file of ``spec`` (the root file by default)."""
    document = spec.root_document if path is None else next(
        d for d in spec.documents if d.path == path
    )
    return format_document(document, declared_poses(spec.environments))


def declared_poses(environments: Iterable[Environment]) -> dict[str, Pose]:
    """Pose id → its declaration, to tell a plain pose use from one with another heading."""
    return {p.id: p for env in environments for p in env.poses()}


def format_document(document: Document, poses: Mapping[str, Pose]) -> str:
    blocks: list[str] = []
    if document.imports:
        blocks.append("\n".join(f"import {_string(i.path)}" for i in document.imports))
    for decl in document.declarations:
        if isinstance(decl, RobotType):
            blocks.append(_robot_type(decl))
        elif isinstance(decl, Environment):
            blocks.append(_environment(decl))
        elif isinstance(decl, Task):
            blocks.append(_task(decl, poses))
        else:
            blocks.append(_scenario(decl, poses))
    return "\n\n".join(blocks) + "\n"


def _robot_type(rtype: RobotType) -> str:
    facts = []
    if rtype.base is not None:
        facts.append(f"{INDENT}base {rtype.base}")
    if rtype.torso is not None:
        facts.append(f"{INDENT}torso {'yes' if rtype.torso else 'no'}")
    if not facts:
        return f"robot type {rtype.id} {{ }}"
    return "\n".join([f"robot type {rtype.id} {{", *facts, "}"])


def _environment(env: Environment) -> str:
    lines = [f"environment {env.id} {{"]
    models = []
    if env.map is not None:
        text = f"{INDENT}map {env.map.name}{_from(env.map.source)}"
        if env.map.file is not None:
            text += f" file {_string(_relative_map_file(env))}"
        models.append(text)
    if env.world is not None:
        models.append(f"{INDENT}world {env.world.name}{_from(env.world.source)}")
    sections = ["\n".join(models)] if models else []
    for area in env.areas:
        body = [f"{INDENT}area {area.id} {{"]
        for pose in area.poses:
            body.append(
                f"{INDENT * 2}pose {pose.id} at {_position(pose.position)}"
                f"{_orientation(pose.orientation, declared=Orientation())}"
            )
        body.append(f"{INDENT}}}")
        sections.append("\n".join(body))
    if env.obstacles:
        obstacles = []
        for ob in env.obstacles:
            text = f"{INDENT}obstacle {ob.id}"
            if ob.model is not None:
                text += f" model {_string(ob.model)}"
            text += f" at {_position(ob.pose.position)}"
            text += _orientation(ob.pose.orientation, declared=Orientation())
            if ob.size is not None:
                text += " size (" + ", ".join(_number(v) for v in ob.size) + ")"
            obstacles.append(text)
        sections.append("\n".join(obstacles))
    lines.append("\n\n".join(sections))
    lines.append("}")
    return "\n".join(line for line in lines if line)


def _relative_map_file(env: Environment) -> str:
    """The map file as written: builders store it joined to the file's folder."""
    assert env.map is not None and env.map.file is not None
    if env.location is None:
        return env.map.file
    import os

    return os.path.relpath(env.map.file, os.path.dirname(env.location.file) or ".")


def _task(task: Task, poses: Mapping[str, Pose]) -> str:
    lines = [f"task {task.id} {{"]
    if task.source is not None:
        lines.append(f"{INDENT}source{_ros(task.source)}")
    if len(task.subtasks) == 1:
        lines.extend(f"{INDENT}visit {_waypoint(w, poses)}" for w in task.subtasks[0].waypoints)
    else:
        for sub in task.subtasks:
            lines.append(f"{INDENT}subtask {{")
            lines.extend(f"{INDENT * 2}visit {_waypoint(w, poses)}" for w in sub.waypoints)
            lines.append(f"{INDENT}}}")
    lines.append("}")
    return "\n".join(lines)


def _scenario(sc: Scenario, poses: Mapping[str, Pose]) -> str:
    lines = [f"scenario {sc.id} in {sc.environment.id} {{", f"{INDENT}robots {{"]
    for robot in sc.robots:
        text = f"{INDENT * 2}{robot.id}: {robot.type.id}"
        if robot.namespace != robot.id:
            text += f" namespace {_string(robot.namespace)}"
        if robot.start_pose is not None:
            text += f" starts at {_pose_use(robot.start_pose, poses)}"
        lines.append(text)
    lines.append(f"{INDENT}}}")
    m = sc.mission
    lines.append(f"{INDENT}mission {m.id} {m.type.value} {{")
    run: list[str] = []
    robot = None
    for entry in m.allocation:
        if entry.robot != robot and run:
            lines.append(f"{INDENT * 2}{robot} does {' then '.join(run)}")
            run = []
        robot = entry.robot
        run.append(entry.task)
    if run:
        lines.append(f"{INDENT * 2}{robot} does {' then '.join(run)}")
    lines.append(f"{INDENT}}}")
    lines.append("}")
    return "\n".join(lines)


def _waypoint(pose: Pose, poses: Mapping[str, Pose]) -> str:
    if pose.area is None:  # given by coordinates
        return _position(pose.position) + _orientation(pose.orientation, declared=Orientation())
    return _pose_use(pose, poses)


def _pose_use(pose: Pose, poses: Mapping[str, Pose]) -> str:
    declared = poses.get(pose.id)
    base = declared.orientation if declared is not None else Orientation()
    return pose.id + _orientation(pose.orientation, declared=base, always=declared is None)


def _orientation(o: Orientation, declared: Orientation, always: bool = False) -> str:
    if o == declared and not always:
        return ""
    unit = o.unit if o.unit in ("rad", "deg") else "rad"
    if o.is_planar:
        return f" facing {_angle(o.yaw, unit)}"
    return f" rpy ({_angle(o.roll, unit)}, {_angle(o.pitch, unit)}, {_angle(o.yaw, unit)})"


def _angle(value: float, unit: str) -> str:
    if unit == "deg":
        return f"{_number(round(math.degrees(value), 10))} deg"
    return _number(value)


def _position(p: Position) -> str:
    unit = p.unit if p.unit in _LENGTH_UNITS else "m"
    scale = _LENGTH_UNITS[unit]
    values = [p.x, p.y] + ([p.z] if p.z != 0.0 else [])
    suffix = "" if unit == "m" else f" {unit}"
    return "(" + ", ".join(_number(round(v / scale, 10) if scale != 1.0 else v) + suffix for v in values) + ")"


def _number(value: float) -> str:
    """Shortest text that reads back as the same float, never in exponent form."""
    text = format(Decimal(repr(float(value))), "f")
    if "." not in text:
        text += ".0"
    return text


def _string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _from(source: RosResource | None) -> str:
    return "" if source is None else f" from{_ros(source)}"


def _ros(source: RosResource) -> str:
    text = f" package {_string(source.package)}"
    if source.path is not None:
        text += f" path {_string(source.path)}"
    return text
