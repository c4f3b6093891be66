"""The formatter: semantic model → canonical ``.exsce`` text.

textX has no model-to-text, so we own one.  Printing a parsed file and
parsing the result gives back an equal model (a tested round trip), and
printing is idempotent.  Comments are kept where they were (see :func:`format_document`).

Quantities print as their author wrote them, number and unit (``200 cm``, ``90 deg``,
``7``; one space before the unit): the model keeps that text beside the SI value, and
it is printed as long as it still reads as the value.  A value made otherwise (by an
importer, a transformation) prints in SI, or in the unit the model says it was written in.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping, Sequence

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.expressions import read_quantity
from exsce_dsl.lang.format.acceptance import acceptance_lines
from exsce_dsl.lang.format.derivation import derivation_lines
from exsce_dsl.lang.format.metrics import metric_lines
from exsce_dsl.lang.lexical import Comment, as_written, duration_text, read_angle, read_length
from exsce_dsl.lang.lexical import number_text as _number
from exsce_dsl.lang.lexical import string_literal as _string
from exsce_dsl.model import (
    Acceptance,
    Assignment,
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
from exsce_dsl.model.conventions import CONVENTIONS, METHOD, Signals, Tolerance, hertz
from exsce_dsl.model.derived import DerivedScenario
from exsce_dsl.model.metrics import MetricDefinition

INDENT = "  "

# A line of output and the source location of what it prints (to place comments).
Line = tuple[str, SourceLocation | None]
_LENGTH_UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}


def format_spec_document(
    spec: Specification, path: str | None = None, comments: Sequence[Comment] = ()
) -> str:
    """The canonical text of one file of ``spec`` (the root file by default)."""
    document = spec.root_document if path is None else next(d for d in spec.documents if d.path == path)
    return format_document(document, declared_poses(spec.environments), comments)


def declared_poses(environments: Iterable[Environment]) -> dict[str, Pose]:
    """Pose id → its declaration, to tell a plain pose use from one with another heading."""
    return {p.id: p for env in environments for p in env.poses()}


def format_document(document: Document, poses: Mapping[str, Pose], comments: Sequence[Comment] = ()) -> str:
    """``comments`` (from :func:`exsce_dsl.lang.lexical.comments`) are kept before the
    element that follows them, or at the end of the line they end."""
    blocks: list[list[Line]] = []
    if document.imports:
        blocks.append([(f"import {_string(i.path)}", i.location) for i in document.imports])
    for decl in document.declarations:
        if isinstance(decl, RobotType):
            blocks.append(_robot_type(decl))
        elif isinstance(decl, Environment):
            blocks.append(_environment(decl))
        elif isinstance(decl, Task):
            blocks.append(_task(decl, poses))
        elif isinstance(decl, Acceptance):
            blocks.append(acceptance_lines(decl))
        elif isinstance(decl, DerivedScenario):
            blocks.append(derivation_lines(decl))
        elif isinstance(decl, MetricDefinition):
            blocks.append(metric_lines(decl))
        else:
            blocks.append(_scenario(decl, poses))
    lines: list[Line] = []
    for block in blocks:
        if lines:
            lines.append(("", None))
        lines.extend(block)
    return _with_comments(lines, [c for c in comments if c.file == document.path])


def _with_comments(lines: list[Line], comments: Sequence[Comment]) -> str:
    pending = sorted(comments, key=lambda c: (c.line, c.column))
    out: list[str] = []
    for text, loc in lines:
        if loc is not None and pending:
            indent = text[: len(text) - len(text.lstrip())]
            last_line = None
            while pending and pending[0].line < loc.line:
                comment = pending.pop(0)
                out.append(indent + comment.text)
                last_line = comment.line + comment.text.count("\n")
            if last_line is not None and last_line < loc.line - 1:
                out.append("")  # keep a comment apart from what follows, as written
            trailing = [c for c in pending if c.line == loc.line]
            for comment in trailing:
                pending.remove(comment)
                text += "  " + comment.text
        out.append(text)
    out.extend(c.text for c in pending)
    return "\n".join(out) + "\n"


def _robot_type(rtype: RobotType) -> list[Line]:
    facts: list[Line] = []
    if rtype.base is not None:
        facts.append((f"{INDENT}base {rtype.base}", None))
    if rtype.torso is not None:
        facts.append((f"{INDENT}torso {'yes' if rtype.torso else 'no'}", None))
    if rtype.motion != "planar":
        facts.append((f"{INDENT}motion {rtype.motion}", None))
    facts += [(f"{INDENT}{line}", None) for line in signal_lines(rtype.declared_signals)]
    if not facts:
        return [(f"robot type {rtype.id} {{ }}", rtype.location)]
    return [(f"robot type {rtype.id} {{", rtype.location), *facts, ("}", None)]


def signal_lines(signals: Signals | None, over: Signals | None = None) -> list[str]:
    """A robot type's signal lines: its convention, then what it says otherwise than that; or a
    robot's, ``over`` its type's signals (its convention only if it names another)."""
    if signals is None:
        return []
    lines = []
    if over is None or over.convention != signals.convention:
        base = CONVENTIONS[signals.convention] if signals.convention in CONVENTIONS else METHOD
        if signals.named:
            lines.append(f"convention {signals.convention}")
    else:
        base = over
    if signals.pose != base.pose:
        lines += [f"pose {p.clause()}" for p in signals.pose]
    if signals.velocity != base.velocity:
        lines += [f"velocity {v.clause()}" for v in signals.velocity]
    if signals.scan != base.scan:
        lines += [f"scan {v.clause()}" for v in signals.scan]
    if (signals.navigation, signals.actions) != (base.navigation, base.actions):
        actions = ", ".join(f'"{a}"' for a in signals.actions)
        lines.append(f"navigation {signals.navigation.value}" + (f" on {actions}" if actions else ""))
    if signals.tolerance != base.tolerance:
        lines.append(_arrival(signals.tolerance))
    if signals.window != base.window:
        lines.append(f"window {signals.window.value}")
    if signals.rates != base.rates:
        lines += [f"{signal} at {hertz(rate)}" for signal, rate in signals.rates]
    return lines


def _arrival(tolerance: Tolerance) -> str:
    heading = tolerance.heading
    values = [tolerance.position] + ([heading] if heading is not None else [])
    texts = as_written(values, tolerance.written, _si) or [
        f"{_number(value)} {unit}" for value, unit in zip(values, ("m", "rad"), strict=False)
    ]
    return "arrival within " + " and ".join(texts)


def _si(text: str) -> float:
    return read_quantity(text)[0]


def _environment(env: Environment) -> list[Line]:
    sections: list[list[Line]] = []
    models: list[Line] = []
    if env.map is not None:
        text = f"{INDENT}map {env.map.name}{_from(env.map.source)}"
        if env.map.file is not None:
            text += f" file {_string(_relative_map_file(env))}"
        models.append((text, env.map.location))
    if env.world is not None:
        models.append((f"{INDENT}world {env.world.name}{_from(env.world.source)}", env.world.location))
    if models:
        sections.append(models)
    for area in env.areas:
        body: list[Line] = [(f"{INDENT}area {area.id} {{", area.location)]
        for pose in area.poses:
            body.append(
                (
                    f"{INDENT * 2}pose {pose.id} at {_position(pose.position)}"
                    f"{_orientation(pose.orientation, declared=Orientation())}",
                    pose.location,
                )
            )
        body.append((f"{INDENT}}}", None))
        sections.append(body)
    if env.obstacles:
        obstacles: list[Line] = []
        for ob in env.obstacles:
            text = f"{INDENT}obstacle {ob.id}"
            if ob.model is not None:
                text += f" model {_string(ob.model)}"
            text += f" at {_position(ob.pose.position)}"
            text += _orientation(ob.pose.orientation, declared=Orientation())
            if ob.size is not None:
                size = as_written(ob.size, ob.size_written, read_length) or [_number(v) for v in ob.size]
                text += " size (" + ", ".join(size) + ")"
            obstacles.append((text, ob.location))
        sections.append(obstacles)
    lines: list[Line] = [(f"environment {env.id} {{", env.location)]
    for i, section in enumerate(sections):
        if i:
            lines.append(("", None))
        lines.extend(section)
    lines.append(("}", None))
    return lines


def _relative_map_file(env: Environment) -> str:
    """The map file as written: the builder stores it joined to the file's folder."""
    assert env.map is not None and env.map.file is not None
    if env.location is None:
        return env.map.file
    return os.path.relpath(env.map.file, os.path.dirname(env.location.file) or ".")


def _task(task: Task, poses: Mapping[str, Pose]) -> list[Line]:
    lines: list[Line] = [(f"task {task.id} {{", task.location)]
    if task.source is not None:
        lines.append((f"{INDENT}source{_ros(task.source)}", None))
    if task.timeout is not None:
        lines.append((f"{INDENT}timeout {duration_text(task.timeout, task.timeout_written)}", None))
    if len(task.subtasks) == 1:
        lines.extend((f"{INDENT}visit {_waypoint(w, poses)}", w.location) for w in task.subtasks[0].waypoints)
    else:
        for sub in task.subtasks:
            lines.append((f"{INDENT}subtask {{", sub.location))
            lines.extend((f"{INDENT * 2}visit {_waypoint(w, poses)}", w.location) for w in sub.waypoints)
            lines.append((f"{INDENT}}}", None))
    lines.append(("}", None))
    return lines


def _scenario(sc: Scenario, poses: Mapping[str, Pose]) -> list[Line]:
    lines: list[Line] = [
        (f"scenario {sc.id} in {sc.environment.id} {{", sc.location),
        (f"{INDENT}robots {{", None),
    ]
    for robot in sc.robots:
        text = f"{INDENT * 2}{robot.id}: {robot.type.id}"
        if robot.namespace != robot.id:
            text += f" namespace {_string(robot.namespace)}"
        if robot.start_pose is not None:
            text += f" starts at {_pose_use(robot.start_pose, poses)}"
        own = signal_lines(robot.declared_signals, robot.type.signals)
        if own:
            lines.append((text + " {", robot.location))
            lines += [(f"{INDENT * 3}{line}", None) for line in own]
            lines.append((f"{INDENT * 2}}}", None))
            continue
        lines.append((text, robot.location))
    lines.append((f"{INDENT}}}", None))
    m = sc.mission
    lines.append((f"{INDENT}mission {m.id} {m.type.value} {{", m.location))
    if m.timeout is not None:
        lines.append((f"{INDENT * 2}timeout {duration_text(m.timeout, m.timeout_written)}", None))
    runs: list[list[Assignment]] = []
    for entry in m.allocation:
        if runs and runs[-1][0].robot == entry.robot:
            runs[-1].append(entry)
        else:
            runs.append([entry])
    for run in runs:
        tasks = " then ".join(e.task for e in run)
        lines.append((f"{INDENT * 2}{run[0].robot} does {tasks}", run[0].location))
    lines.append((f"{INDENT}}}", None))
    lines.append(("}", None))
    return lines


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
    if o.is_planar and (yaw := as_written([o.yaw], o.written, read_angle)) is not None:
        return f" facing {yaw[0]}"
    if (angles := as_written([o.roll, o.pitch, o.yaw], o.written, read_angle)) is not None:
        return f" rpy ({', '.join(angles)})"
    unit = o.unit if o.unit in ("rad", "deg") else "rad"
    if o.is_planar:
        return f" facing {_angle(o.yaw, unit)}"
    return f" rpy ({_angle(o.roll, unit)}, {_angle(o.pitch, unit)}, {_angle(o.yaw, unit)})"


def _angle(value: float, unit: str) -> str:
    if unit == "deg":
        degrees = float(_number(round(math.degrees(value), 10)))
        if math.radians(degrees) == value:  # print in degrees only when it reads back exactly
            return f"{_number(degrees)} deg"
    return _number(value)


def _position(p: Position) -> str:
    values = [p.x, p.y] + ([p.z] if p.z != 0.0 or len(p.written) == 3 else [])
    if (written := as_written(values, p.written, read_length)) is not None:
        return "(" + ", ".join(written) + ")"
    values = [p.x, p.y] + ([p.z] if p.z != 0.0 else [])
    scale = _LENGTH_UNITS.get(p.unit, 1.0)
    if scale != 1.0:
        scaled = [float(_number(round(v / scale, 10))) for v in values]
        if all(s * scale == v for s, v in zip(scaled, values, strict=True)):
            return "(" + ", ".join(f"{_number(s)} {p.unit}" for s in scaled) + ")"
    return "(" + ", ".join(_number(v) for v in values) + ")"


def _from(source: RosResource | None) -> str:
    return "" if source is None else f" from{_ros(source)}"


def _ros(source: RosResource) -> str:
    text = f" package {_string(source.package)}"
    if source.path is not None:
        text += f" path {_string(source.path)}"
    return text
