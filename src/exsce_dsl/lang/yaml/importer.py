"""Import of the method's YAML format: a scenario file and the task files it names.

The method described a scenario in one YAML file whose allocation names each task by
ROS package and path (``pkg``, ``file_path``). Here those files are found on disk,
read, and turned into the semantic model, split the way a person would write the
``.exsce`` files: one document per robot type, one for the environment, one per task
and one for the scenario. The environment's areas are not in the method's files: they
are rebuilt from the poses the scenario uses, the area being the pose id's prefix
before its last ``-`` (``classroom_c025-w001`` is in ``classroom_c025``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from exsce_dsl.errors import ImportFormatError
from exsce_dsl.lang.yaml.exporter import GOAL_TIMEOUT
from exsce_dsl.lang.yaml.located import YamlFile, YamlNode, check_name, why_not_a_name
from exsce_dsl.model import (
    Area,
    Assignment,
    Document,
    Environment,
    Import,
    MapModel,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    RosResource,
    Scenario,
    Subtask,
    Task,
    WorldModel,
)
from exsce_dsl.model.names import is_valid_name

#: Hardware facts of the robot types the method used (PAL Robotics): base, torso.
KNOWN_ROBOT_TYPES: Mapping[str, tuple[str, bool]] = {
    "tiago": ("pmb2", True),
    "pmb2": ("pmb2", False),
    "omni_base": ("omni_base", False),
}

#: The area of a pose whose id has no ``-`` (so no area prefix).
UNASSIGNED_AREA = "unassigned"


def import_scenario_yaml(path: Path, task_search_path: Sequence[Path] = ()) -> tuple[Document, ...]:
    """Read a scenario YAML file and the task files it names, as ``.exsce`` documents.

    Each task file is looked for, in every folder D of [the scenario's folder,
    *task_search_path], at D/pkg/file_path, then D/file_path, then as any file under D
    with the same name (sorted, first wins). The documents come back with paths
    relative to the scenario document, which is first.
    """
    root = YamlFile.read(path).root_node()
    scenario_id = root.get("id").ident("scenario")
    environment_node = root.get("environment")
    mission_node = root.get("mission")
    robot_types, robot_rows = _read_robots(root.get("robots"))
    robot_ids = [row[1] for row in robot_rows]
    read_starts = _read_starts(environment_node, robot_ids)

    # What else the scenario file says, checked before any task file is read.
    environment_id = environment_node.get("id").ident("environment")
    map_model = _read_map(environment_node)
    world_model = _read_world(environment_node)
    mission_id = mission_node.get("id").ident("mission")
    mission_type = _mission_type(mission_node.get("type"))

    finder = _TaskFinder([path.parent, *task_search_path])
    tasks, allocation = _read_allocation(mission_node, robot_ids, finder)

    # Every pose used, declared once where it first occurs.
    poses = _PoseTable()
    for robot_id in robot_ids:
        if robot_id in read_starts:
            poses.add(read_starts[robot_id])
    for task in tasks.values():
        for waypoint in task.waypoints():
            poses.add(waypoint)

    environment = Environment(
        id=environment_id,
        map=map_model,
        world=world_model,
        areas=poses.areas(),
        location=environment_node.location,
    )
    robots = tuple(
        Robot(robot_id, robot_type, namespace, read_starts.get(robot_id), entry.location)
        for entry, robot_id, robot_type, namespace in robot_rows
    )
    mission = Mission(
        id=mission_id,
        type=mission_type,
        allocation=tuple(allocation),
        location=mission_node.location,
        timeout=_goal_timeout(mission_node),
    )
    scenario = Scenario(scenario_id, environment, robots, mission, tuple(tasks.values()), root.location)
    return _documents(scenario, robot_types.values())


_RobotRow = tuple[YamlNode, str, RobotType, str]
"""A robot of the scenario file: its entry, id, type and namespace."""


def _read_robots(robots_node: YamlNode) -> tuple[dict[str, RobotType], list[_RobotRow]]:
    """Robots and their types, in the order of the YAML list."""
    robot_types: dict[str, RobotType] = {}
    robot_rows: list[_RobotRow] = []
    for entry in robots_node.items_of_list():
        robot_id = entry.get("robot_id").ident("robot")
        if any(robot_id == row[1] for row in robot_rows):
            raise entry.error(f"robot '{robot_id}' is listed twice")
        type_id = entry.get("robot_type").ident("robot type")
        if type_id not in robot_types:
            base, torso = KNOWN_ROBOT_TYPES.get(type_id, (None, None))
            robot_types[type_id] = RobotType(type_id, base, torso, entry.location)
        namespace = entry.get("robot_namespace").text()
        robot_rows.append((entry, robot_id, robot_types[type_id], namespace))
    return robot_types, robot_rows


def _read_starts(environment_node: YamlNode, robot_ids: list[str]) -> dict[str, Pose]:
    """Start poses, keyed by robot."""
    read_starts: dict[str, Pose] = {}
    starts = environment_node.opt("robots")
    for robot_id, entry in starts.items_of_mapping() if starts else ():
        if robot_id not in robot_ids:
            raise entry.error(
                f"start pose for robot '{robot_id}', which is not in the robots list ({', '.join(robot_ids)})"
            )
        read_starts[robot_id] = _read_pose(entry.get("start_pose"))
    return read_starts


def _read_allocation(
    mission_node: YamlNode, robot_ids: list[str], finder: _TaskFinder
) -> tuple[dict[str, Task], list[Assignment]]:
    """The allocation, and each task once, in order of first use."""
    tasks: dict[str, Task] = {}
    allocation: list[Assignment] = []
    for entry in mission_node.get("allocation").items_of_list():
        robot_node = entry.get("robot")
        robot_id = robot_node.ident("robot")
        if robot_id not in robot_ids:
            raise robot_node.error(
                f"allocation names robot '{robot_id}', which is not in the robots list "
                f"({', '.join(robot_ids)})"
            )
        source = RosResource(entry.get("pkg").text(), entry.get("file_path").text())
        task_id = _task_id_of(entry.get("file_path"))
        known = tasks.get(task_id)
        if known is None:
            task_file = finder.find(entry)
            tasks[task_id] = _read_task(YamlFile.read(task_file), task_id, source)
        elif known.source != source:
            raise entry.error(
                f"task '{task_id}' comes from package {source.package} path {source.path} "
                f"here, but from package {_describe(known.source)} at {known.location}; "
                "tasks are named after their file, so two files cannot share a name"
            )
        allocation.append(Assignment(robot_id, task_id, entry.location))
    return tasks, allocation


def _documents(scenario: Scenario, robot_types: Iterable[RobotType]) -> tuple[Document, ...]:
    """The scenario split as a person would write it: the scenario's document first, then one
    per robot type, the environment's, and one per task."""
    environment = scenario.environment
    parts: list[Document] = [
        *(Document(f"robots/{t.id}.exsce", (), (t,)) for t in robot_types),
        Document(f"environments/{environment.id}.exsce", (), (environment,)),
        # a task names poses, so its file imports the environment that declares them
        *(
            Document(f"tasks/{t.id}.exsce", (Import(f"../environments/{environment.id}.exsce"),), (t,))
            for t in scenario.tasks
        ),
    ]
    main = Document(f"{scenario.id}.exsce", tuple(Import(d.path) for d in parts), (scenario,))
    return (main, *parts)


def import_task_yaml(path: Path, task_id: str | None = None, *, source: RosResource | None = None) -> Task:
    """Read one task file of the method. The task id defaults to the file's name
    without ``.yaml``; each waypoint's area is its id's prefix (see the module)."""
    file = YamlFile.read(path)
    if task_id is None:
        task_id = _strip_yaml_suffix(path.name)
        check_name(task_id, "task", f"the name of file {path}", file.root_node())
    elif not is_valid_name(task_id):
        raise ImportFormatError(f"task id '{task_id}' is not a valid exsce id: {why_not_a_name(task_id)}")
    return _read_task(file, task_id, source)


# -- finding and reading task files -----------------------------------------------------


class _TaskFinder:
    def __init__(self, folders: Sequence[Path]) -> None:
        self.folders = list(dict.fromkeys(folders))
        self._by_name: dict[Path, dict[str, list[Path]]] = {}

    def find(self, entry: YamlNode) -> Path:
        package = entry.get("pkg").text()
        file_path = entry.get("file_path").text()
        name = Path(file_path).name
        for folder in self.folders:
            for candidate in (folder / package / file_path, folder / file_path):
                if candidate.is_file():
                    return candidate
            found = self._files_named(folder).get(name)
            if found:
                return found[0]
        tried = ", ".join(str(f) for f in self.folders)
        raise entry.get("file_path").error(
            f"task file '{file_path}' of package '{package}' not found: looked for "
            f"D/{package}/{file_path}, D/{file_path} and any file named '{name}' under D, "
            f"for each folder D of the task search path [{tried}]; "
            "add the folder that holds it to the task search path"
        )

    def _files_named(self, folder: Path) -> dict[str, list[Path]]:
        """Every file under ``folder`` by name, each list sorted; listed once per folder."""
        index = self._by_name.get(folder)
        if index is None:
            index = {}
            for parent, dirs, files in os.walk(folder):
                dirs.sort()
                for file in sorted(files):
                    index.setdefault(file, []).append(Path(parent) / file)
            for paths in index.values():
                paths.sort()
            self._by_name[folder] = index
        return index


def _strip_yaml_suffix(name: str) -> str:
    for suffix in (".yaml", ".yml"):
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return name


def _task_id_of(file_path: YamlNode) -> str:
    task_id = _strip_yaml_suffix(Path(file_path.text()).name)
    check_name(task_id, "task", f"the name of file {file_path.text()}", file_path)
    return task_id


def _read_task(file: YamlFile, task_id: str, source: RosResource | None) -> Task:
    root = file.root_node()
    subtasks = tuple(
        Subtask(
            tuple(_read_pose(w) for w in entry.get("waypoints").items_of_list()),
            entry.location,
        )
        for entry in root.get("task").items_of_list()
    )
    return Task(task_id, subtasks, source, root.location, _goal_timeout(root))


def _goal_timeout(node: YamlNode) -> float | None:
    """exsce's ``goal_timeout`` key (seconds; see :mod:`.exporter`), if there is one."""
    found = node.opt(GOAL_TIMEOUT)
    if found is None:
        return None
    seconds = found.number()
    if not seconds > 0:
        raise found.error(f"{found.where} is a goal timeout in seconds: it must be above 0, not {seconds:g}")
    return seconds


def _read_pose(node: YamlNode) -> Pose:
    """A pose as the method wrote it: id, x, y, and optionally z, roll, pitch, yaw."""
    pose_id = node.get("id").ident("pose")

    def coordinate(key: str) -> float:
        value = node.opt(key)
        return value.number() if value is not None else 0.0

    position = Position(node.get("x").number(), node.get("y").number(), coordinate("z"))
    orientation = Orientation(coordinate("roll"), coordinate("pitch"), coordinate("yaw"))
    return Pose(pose_id, position, orientation, _area_of(pose_id, node), node.location)


def _area_of(pose_id: str, node: YamlNode) -> str:
    if "-" not in pose_id:
        return UNASSIGNED_AREA
    # The method names poses <area>-<point>: `classroom_c025-w001`, and also
    # `right_long_corridor-point-0`, so the area ends at the first '-'.
    area = pose_id.split("-", 1)[0]
    check_name(area, "area", f"the part of pose id '{pose_id}' before its first '-'", node)
    return area


class _PoseTable:
    """The poses of an environment, each declared where it first occurs."""

    def __init__(self) -> None:
        self._poses: dict[str, Pose] = {}

    def add(self, pose: Pose) -> None:
        first = self._poses.setdefault(pose.id, pose)
        if first.position != pose.position:
            raise ImportFormatError(
                f"pose '{pose.id}' is at {_xyz(pose.position)} here but at "
                f"{_xyz(first.position)} in {first.location}; a pose id names one place",
                pose.location,
            )

    def areas(self) -> tuple[Area, ...]:
        by_area: dict[str, list[Pose]] = {}
        for pose in self._poses.values():
            by_area.setdefault(pose.area or UNASSIGNED_AREA, []).append(pose)
        return tuple(Area(area, tuple(poses)) for area, poses in by_area.items())


def _xyz(p: Position) -> str:
    return f"({p.x}, {p.y}, {p.z})"


def _describe(source: RosResource | None) -> str:
    return f"{source.package} path {source.path}" if source else "(none)"


# -- the rest of a scenario --------------------------------------------------------------


def _mission_type(node: YamlNode) -> MissionType:
    text = node.text()
    try:
        return MissionType(text)
    except ValueError:
        kinds = " or ".join(t.value for t in MissionType)
        raise node.error(f"mission type '{text}' is not {kinds}") from None


def _model(environment: YamlNode, key: str, name_key: str) -> tuple[str, RosResource | None, YamlNode]:
    node = environment.get("models").get(key)
    name = node.get(name_key).ident(f"{key} model")
    package = node.opt("pkg")
    path = node.opt("relative_path")
    source = RosResource(package.text(), path.text() if path else None) if package else None
    return name, source, node


def _read_map(environment: YamlNode) -> MapModel | None:
    models = environment.opt("models")
    if models is None or models.opt("map") is None:
        return None
    name, source, node = _model(environment, "map", "map_name")
    return MapModel(name, source, location=node.location)


def _read_world(environment: YamlNode) -> WorldModel | None:
    models = environment.opt("models")
    if models is None or models.opt("gazebo_world") is None:
        return None
    name, source, node = _model(environment, "gazebo_world", "model_name")
    return WorldModel(name, source, node.location)
