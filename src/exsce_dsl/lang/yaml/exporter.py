"""Export to the method's YAML format: a scenario file and one file per task.

The shapes and key order are those of the method's own files, so that its tools read
what exsce writes. The method's files hold no areas or obstacles (those came from the
floor plan), so only what the scenario uses is written.

One key is exsce's own: a goal timeout (``timeout 2 min`` in a mission or a task), which
the method's files have no place for, is written as ``goal_timeout`` (seconds) in the
scenario file's mission and at the top of the task file, after the method's keys, where
the method's tools, which read the keys they know, pass over it; the import reads it back.
"""

from __future__ import annotations

from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

import yaml

from exsce_dsl.errors import ExportError
from exsce_dsl.model import MapModel, Pose, RosResource, Scenario, Task, WorldModel
from exsce_dsl.model.names import is_valid_name

#: The package named in a scenario file for a task that came from no ROS package.
DEFAULT_TASK_PACKAGE = "exsce"
#: exsce's own key for a mission's or a task's goal timeout, in seconds (see the module).
GOAL_TIMEOUT = "goal_timeout"


def scenario_to_yaml(scenario: Scenario) -> dict[str, Any]:
    """The scenario file's content, keys in the method's order."""
    environment = scenario.environment
    models: dict[str, Any] = {}
    if environment.map is not None:
        models["map"] = _model("map_name", environment.map)
    if environment.world is not None:
        models["gazebo_world"] = _model("model_name", environment.world)
    mission: dict[str, Any] = {
        "id": scenario.mission.id,
        "type": scenario.mission.type.value,
        "allocation": [
            {"robot": a.robot, **_task_reference(scenario, a.task)} for a in scenario.mission.allocation
        ],
    }
    if scenario.mission.timeout is not None:
        mission[GOAL_TIMEOUT] = scenario.mission.timeout
    return {
        "id": scenario.id,
        "mission": mission,
        "environment": {
            "id": environment.id,
            "models": models,
            "robots": {
                r.id: {"start_pose": _start_pose(r.start_pose)}
                for r in scenario.robots
                if r.start_pose is not None
            },
        },
        "robots": [
            {"robot_id": r.id, "robot_namespace": r.namespace, "robot_type": r.type.id}
            for r in scenario.robots
        ],
    }


def task_to_yaml(task: Task) -> dict[str, Any]:
    """The task file's content. The method's waypoints have a heading (yaw) only, so a
    waypoint with roll or pitch cannot be written without loss: ``ExportError``."""
    for waypoint in task.waypoints():
        if not waypoint.orientation.is_planar:
            o = waypoint.orientation
            raise ExportError(
                f"task '{task.id}': waypoint '{waypoint.id}' has roll {o.roll} and pitch "
                f"{o.pitch}, but the method's task files hold only a yaw; "
                "make the waypoint planar to export it",
                waypoint.location,
            )
    content: dict[str, Any] = {
        "task": [{"waypoints": [_waypoint(w) for w in subtask.waypoints]} for subtask in task.subtasks]
    }
    if task.timeout is not None:
        content[GOAL_TIMEOUT] = task.timeout
    return content


def export_yaml(scenario: Scenario, out_dir: Path) -> list[Path]:
    """Write ``scenarios/<id>.yaml`` and every task file under ``out_dir``.

    A task goes to its source path (the ``file_path`` the scenario file names), or to
    ``tasks/<id>.yaml`` when it has none. Everything is checked before anything is
    written. Returns the files written, the scenario first.
    """
    if not is_valid_name(scenario.id):
        raise ExportError(f"scenario id '{scenario.id}' is not a valid exsce id")
    files: dict[PurePosixPath, dict[str, Any]] = {
        PurePosixPath("scenarios", f"{scenario.id}.yaml"): scenario_to_yaml(scenario)
    }
    for task in scenario.tasks:
        relative = _task_file(task)
        if relative in files:
            raise ExportError(
                f"task '{task.id}' would be written to {relative}, "
                "which another file of this export already uses",
                task.location,
            )
        files[relative] = task_to_yaml(task)

    written = []
    for relative, content in files.items():
        target = out_dir.joinpath(*relative.parts)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(yaml.safe_dump(content, sort_keys=False, allow_unicode=True), encoding="utf-8")
        written.append(target)
    return written


def _model(name_key: str, model: MapModel | WorldModel) -> dict[str, Any]:
    entry: dict[str, Any] = {name_key: model.name}
    if model.source is not None:
        entry["pkg"] = model.source.package
        if model.source.path is not None:
            entry["relative_path"] = model.source.path
    return entry


def _task_reference(scenario: Scenario, task_id: str) -> dict[str, str]:
    task = scenario.task(task_id)
    if task is None:
        raise ExportError(
            f"scenario '{scenario.id}' allocates task '{task_id}', which it does not hold",
            scenario.mission.location,
        )
    _task_file(task)  # refuse a path that the export could not write
    source = _task_source(task)
    return {"pkg": source.package, "file_path": source.path or ""}


def _task_source(task: Task) -> RosResource:
    if task.source is None:
        return RosResource(DEFAULT_TASK_PACKAGE, f"tasks/{task.id}.yaml")
    if task.source.path is None:
        return RosResource(task.source.package, f"tasks/{task.id}.yaml")
    return task.source


def _task_file(task: Task) -> PurePosixPath:
    """The task's file, relative to the export folder; never outside it."""
    text = _task_source(task).path or ""
    path = PurePosixPath(text)
    if (
        not text
        or path.is_absolute()
        or PureWindowsPath(text).anchor
        or "\\" in text
        or ".." in path.parts
        or path == PurePosixPath(".")
    ):
        raise ExportError(
            f"task '{task.id}' has source path '{text}'; a task is written at its source "
            "path inside the export folder, so it must be a relative path without '..'",
            task.location,
        )
    return path


def _start_pose(pose: Pose) -> dict[str, Any]:
    p, o = pose.position, pose.orientation
    return {
        "id": pose.id,
        "x": p.x,
        "y": p.y,
        "z": p.z,
        "roll": o.roll,
        "pitch": o.pitch,
        "yaw": o.yaw,
    }


def _waypoint(pose: Pose) -> dict[str, Any]:
    p = pose.position
    return {"id": pose.id, "x": p.x, "y": p.y, "z": p.z, "yaw": pose.orientation.yaw}
