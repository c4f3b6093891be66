"""The waypoint files the method's waypoint dispatcher reads for one scenario.

Below the output folder: ``mission.yaml`` (the mission type, and per robot
its namespace, start pose and task files in order, then the whole allocation
in execution order) and ``<namespace>/<task id>.yaml`` per allocated task,
in the method's task format (one list of waypoints per subtask, each with
id, x, y, z and yaw).  Robots are found by namespace, as the dispatcher's
topics are (``/<namespace>/waypoint_dispatcher/...``).
"""

from __future__ import annotations

import re
from pathlib import Path, PurePosixPath
from typing import Any

import yaml

from exsce_dsl.codegen.output import write_files
from exsce_dsl.errors import GenerationError
from exsce_dsl.lang import scenario_to_yaml, task_to_yaml
from exsce_dsl.model import Robot, Scenario, Specification, Task
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.templating import render

MISSION_FILE = "mission.yaml"

#: One ROS graph name, no separators: it names a folder of the output.
_PLAIN_ROS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")


def generate_dispatcher_config(
    spec: Specification, scenario_id: str | None, out_dir: Path, overwrite: bool = False
) -> list[Path]:
    """Write the dispatcher's files for the scenario; return the files written, the mission first."""
    scenario = spec.scenario(scenario_id)
    return write_files(out_dir, dispatcher_files(scenario, Path(spec.root).name), overwrite)


def dispatcher_files(scenario: Scenario, source: str) -> dict[str, str]:
    """The files (relative POSIX path → text) for ``scenario``; ``source`` names the spec file in headers."""
    header = {"source": source, "scenario": scenario.id}
    folders = {robot.id: _folder(robot) for robot in scenario.robots}
    files: dict[str, str] = {}
    allocation = []
    for entry in scenario.mission.allocation:
        task = scenario.task(entry.task)
        if entry.robot not in folders or task is None:
            raise GenerationError(
                f"scenario '{scenario.id}' allocates task '{entry.task}' to robot '{entry.robot}', "
                "but does not hold both",
                entry.location,
            )
        robot = scenario.robot(entry.robot)
        assert robot is not None  # folders holds it
        namespace = robot.namespace
        path = _task_file(folders[entry.robot], task)
        if path not in files:
            content = task_to_yaml(task)
            text = render(
                "dispatcher/waypoints.yaml.j2",
                **header,
                task_id=task.id,
                namespace=namespace,
                task=content["task"],
            )
            files[path] = _read_back(path, text, content)
        allocation.append({"robot_namespace": namespace, "file_path": path})

    method_scenario = scenario_to_yaml(scenario)
    start_poses = method_scenario["environment"]["robots"]
    robots = []
    for robot in scenario.robots:
        entry_of_robot: dict[str, Any] = {"robot_id": robot.id, "robot_namespace": robot.namespace}
        if robot.id in start_poses:
            entry_of_robot["start_pose"] = start_poses[robot.id]["start_pose"]
        entry_of_robot["task_files"] = [
            a["file_path"] for a in allocation if a["robot_namespace"] == robot.namespace
        ]
        robots.append(entry_of_robot)
    mission = {
        "scenario": scenario.id,
        "mission": {"id": scenario.mission.id, "type": method_scenario["mission"]["type"]},
        "robots": robots,
        "allocation": allocation,
    }
    text = render("dispatcher/mission.yaml.j2", **header, mission=mission)
    return {MISSION_FILE: _read_back(MISSION_FILE, text, mission), **files}


def _folder(robot: Robot) -> str:
    """The folder of a robot's task files: its namespace, or its id for a robot at the root."""
    folder = robot.namespace or robot.id
    if not _PLAIN_ROS_NAME.fullmatch(folder):
        raise GenerationError(
            f"namespace '{robot.namespace}' of robot '{robot.id}' is not a plain ROS name "
            "(a letter, then letters, digits or '_'); the dispatcher's files of a robot go "
            "in a folder named after its namespace (after its id, at the root)",
            robot.location,
        )
    return folder


def _task_file(namespace: str, task: Task) -> str:
    if not is_valid_name(task.id):
        raise GenerationError(f"task id '{task.id}' cannot name a file", task.location)
    return str(PurePosixPath(namespace, f"{task.id}.yaml"))


def _read_back(path: str, text: str, content: object) -> str:
    """``text`` if a YAML reader gets ``content`` back from it.

    Guards the template and the filters (``yamlnum`` writes ``1e-05`` as
    ``1.0e-05``, which YAML 1.1 readers such as PyYAML and rosparam need):
    a file that would be misread is refused rather than written.
    """
    if yaml.safe_load(text) != content:
        raise GenerationError(
            f"{path}: the generated YAML does not read back as the model ; please report this"
        )
    return text
