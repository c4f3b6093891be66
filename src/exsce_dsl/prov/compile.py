"""Compile a scenario of the semantic model into W3C PROV, in the method's shape.

:func:`compile_scenario` writes one ``ProvDocument`` with the bundles of the
method's published models (``scenarios/scenario_*.prov.json``):

* ``exsce:<scenario>_bundle``: the scenario collection (members: mission,
  environment, robots); the mission entity (``exsce:missionType``); one
  ``prov:Plan`` per allocation entry, ``<mission>:<robot>-task_NN`` numbered
  per robot from 01, member of the mission and derived from its task (a
  ``prov:PrimarySource`` derivation); and each robot's start pose, a
  derivation ``<scenario>:<robot>-start-pose`` of ``<robot>:gazebo_model``
  from the pose (role ``start_pose``, ``exsce:scenario``).
* ``env:<environment>_bundle``: the environment with its map (occupancy grid
  and metadata) and Gazebo world (``ros:pkg``, ``ros:relative_path``).
* ``robot:<robot>_bundle``: the robot, its software and hardware
  configurations, its Gazebo model and its agent.
* ``env:<area>_bundle``, one per area that has poses: the poses the environment declares in
  the area, plus every variant of them (same id, another heading) that the
  scenario uses as start pose or waypoint.  Each pose is a ``geom:Pose`` with
  a ``geom:Point`` and a ``geom:EulerAngles`` as members; a point or an
  orientation shared by several poses of the bundle is written once.
* ``task:<task>_bundle``, one per task: the task plan (``ros:pkg`` and
  ``ros:relative_path`` when it came from a task file), its subtask plans,
  each derived into the task (role ``subtask_NNN``), and each waypoint, a
  derivation ``<task>-subtask_NNN:w_NNN`` of the subtask from the pose (role
  ``waypoint``).  Waypoints given by coordinates (``Pose.area is None``) are
  written, pose, point and orientation, in their task's bundle.

Deliberate differences from the published models, where those are flawed:

* task ids are the DSL ids (``task:delivery_a``), not file names
  (``task:delivery_a.yaml``); pose and orientation ids keep every angle exact
  (see :func:`~exsce_dsl.prov.identifiers.format_angle`);
* every number is an ``xsd:double`` (the published ``coord:z`` and ``angle:yaw``
  are sometimes ``xsd:int``);
* every ``prov:type`` that names a class is a qualified name
  (``prov:type='prov:Plan'``); the published models mostly write the string
  ``"prov:Plan"``, and the qualified name only for ``ros:GazeboModel`` and
  ``ros:Parameter_Server``.  The two types that name no class,
  ``"software-config"`` and ``"hardware-config"``, stay strings.

Additions (facts the published models do not record):

* ``exsce:robotType`` (the robot type's id) on ``robot:<robot>``;
* ``exsce:baseType`` and ``exsce:torso`` (``xsd:boolean``) on
  ``<robot>:hardware-config``, when the robot type states them;
* ``ros:namespace`` (the robot's ROS namespace) on ``<robot>:software-config``;
* obstacles, in the environment bundle: ``<environment>:<obstacle>``, typed
  ``exsce:obstacle``, with ``exsce:model`` and ``exsce:size`` (the sizes, space
  separated) when given, a member of the environment, and derived from its
  pose by ``<environment>:<obstacle>-pose`` (role ``obstacle_pose``);
* start and obstacle poses given by coordinates (no area) are written in the
  scenario's and the environment's bundle respectively.

Compiling is deterministic (no random ids, no timestamps) and linear in the
size of the scenario.
"""

from __future__ import annotations

import gc
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

from prov.constants import (
    PROV_ROLE,
    PROV_TYPE,
)
from prov.identifier import QualifiedName
from prov.model import (
    ProvDocument,
)

from exsce_dsl.errors import ExsceError, SourceLocation
from exsce_dsl.model.environment import Environment, MapModel, RosResource, WorldModel
from exsce_dsl.model.geometry import Orientation, Pose, Position
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.model.tasks import Task
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.prov.records import Attributes, BundleWriter, DocumentWriter

__all__ = ["compile_scenario"]

START_POSE_ROLE = "start_pose"
WAYPOINT_ROLE = "waypoint"
OBSTACLE_POSE_ROLE = "obstacle_pose"
SOFTWARE_CONFIG = ids.SOFTWARE_CONFIG
HARDWARE_CONFIG = ids.HARDWARE_CONFIG
EULER_AXES = "sxyz"


_DOCUMENT_PREFIXES = (ids.ROS, ids.EXSCE, ids.GEOM, ids.COORD, ids.ANGLE, ids.ORACLE)
"""The prefixes the published documents declare at document level."""


def compile_scenario(scenario: Scenario, namespace: str = DEFAULT_NAMESPACE) -> ProvDocument:
    """The PROV document of ``scenario``: its scenario, environment, area, robot and task bundles.

    ``namespace`` is the base namespace (``exsce:``); the method's other
    namespaces (``mission:``, ``env:``, ``pose:``...) are under it.  Raises
    :class:`~exsce_dsl.errors.ExsceError` if the scenario cannot be written
    without two different things sharing one identifier.
    """
    with _collector_paused():
        return _ScenarioCompiler(scenario, Namespaces(namespace)).compile()


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Pause Python's cycle collector while the document is built.

    A compiled document is tens of thousands of small containers that all stay
    alive; the collector would walk them again and again as they pile up (half
    the compile time of a large scenario) and find nothing to free.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()


class _ScenarioCompiler:
    """A scenario's PROV document: the scenario, environment, area, robot and task bundles."""

    def __init__(self, scenario: Scenario, names: Namespaces, checked: bool = False) -> None:
        self.scenario = scenario
        self.writer = DocumentWriter(names, checked)
        self.names = names
        self.prefixes = self.writer.prefixes
        self.document = self.writer.document
        self._orientation_names: dict[Orientation, str] = {}
        for prefix in _DOCUMENT_PREFIXES:
            self.writer.document_namespace(prefix)
        self._positions: dict[str, Position] = {}
        self._tasks = {task.id: task for task in scenario.tasks}
        self._area_locations = {a.id: a.location for a in scenario.environment.areas}

    # -- the document ------------------------------------------------------

    def compile(self) -> ProvDocument:
        scenario = self.scenario
        environment = scenario.environment
        area_poses, loose_start_poses, loose_obstacle_poses = _place_poses(scenario, self.pose_name)
        self._scenario_bundle(loose_start_poses)
        self._environment_bundle(environment, loose_obstacle_poses)
        for area_id, poses in area_poses.items():
            if poses:
                self._area_bundle(area_id, poses)
        for robot in scenario.robots:
            self._robot_bundle(robot)
        for task in scenario.tasks:
            self._task_bundle(task)
        return self.document

    def pose_name(self, pose: Pose) -> str:
        """:func:`~exsce_dsl.prov.identifiers.pose_name`, each orientation formatted once."""
        name = self._orientation_names.get(pose.orientation)
        if name is None:
            name = self._orientation_names[pose.orientation] = ids.orientation_name(pose.orientation)
        return f"{pose.id}-{name}"

    def _bundle(
        self, prefix: str, element_id: str, what: str, location: SourceLocation | None
    ) -> BundleWriter:
        identifier = self.writer.document_namespace(prefix)[ids.bundle_name(element_id)]
        return self.writer.bundle(identifier, what, location)

    # -- poses -------------------------------------------------------------

    def _pose_id(self, writer: BundleWriter, pose: Pose) -> QualifiedName:
        return writer.fixed(ids.POSE)[self.pose_name(pose)]

    def _write_poses(self, writer: BundleWriter, poses: Iterable[Pose]) -> None:
        """Pose, point and orientation entities, and the pose's two memberships."""
        poses = list(poses)
        if not poses:
            return
        pose_ns = writer.fixed(ids.POSE)
        point_ns = writer.fixed(ids.POINT)
        orientation_ns = writer.fixed(ids.ORIENTATION)
        t = writer.term
        pose_type = {PROV_TYPE: t(ids.GEOM_POSE)}
        point_type, euler_type = t(ids.GEOM_POINT), t(ids.GEOM_EULER_ANGLES)
        x, y, z = t(ids.COORD_X), t(ids.COORD_Y), t(ids.COORD_Z)
        roll, pitch, yaw, axes = (
            t(ids.ANGLE_ROLL),
            t(ids.ANGLE_PITCH),
            t(ids.ANGLE_YAW),
            t(ids.GEOM_AXES),
        )
        for pose in poses:
            self._check_position(pose)
            pose_id = pose_ns[self.pose_name(pose)]
            if not writer.entity_once(pose_id, pose_type):
                continue
            point_id = point_ns[ids.point_name(pose)]
            p = pose.position
            writer.entity_once(
                point_id,
                {x: float(p.x), y: float(p.y), z: float(p.z), PROV_TYPE: point_type},
            )
            o = pose.orientation
            orientation_id = orientation_ns[self._orientation_names[o]]
            writer.entity_once(
                orientation_id,
                {
                    roll: float(o.roll),
                    pitch: float(o.pitch),
                    yaw: float(o.yaw),
                    PROV_TYPE: euler_type,
                    axes: EULER_AXES,
                },
            )
            writer.member(pose_id, point_id)
            writer.member(pose_id, orientation_id)

    def _check_position(self, pose: Pose) -> None:
        known = self._positions.setdefault(ids.point_name(pose), pose.position)
        if known != pose.position:
            raise ExsceError(
                f"pose '{pose.id}' is used at two positions, ({known.x}, {known.y}, {known.z}) "
                f"and ({pose.position.x}, {pose.position.y}, {pose.position.z}); "
                "a pose id names one position",
                pose.location,
            )

    # -- bundles -----------------------------------------------------------

    def _scenario_bundle(self, loose_start_poses: list[Pose]) -> None:
        scenario, names = self.scenario, self.names
        mission = scenario.mission
        w = self._bundle(ids.EXSCE, scenario.id, f"scenario '{scenario.id}'", scenario.location)
        t = w.term
        exsce, robot_ns, env_ns = w.fixed(ids.EXSCE), w.fixed(ids.ROBOT), w.fixed(ids.ENV)
        scenario_ns = w.of_element(scenario.id, names.of_scenario(scenario.id), "scenario")
        mission_ns = w.of_element(mission.id, names.of_mission(mission.id), "mission")
        task_ns = w.fixed(ids.TASK)

        scenario_id = exsce[scenario.id]
        mission_id = w.fixed(ids.MISSION)[mission.id]
        w.entity(scenario_id, {PROV_TYPE: t(ids.CONCRETE_SCENARIO)})
        w.entity(
            mission_id,
            {PROV_TYPE: t(ids.MISSION_TYPE_VALUE), t(ids.MISSION_TYPE): mission.type.value},
        )
        robots = {robot.id: robot for robot in scenario.robots}
        plans: list[tuple[QualifiedName, QualifiedName]] = []
        counts: dict[str, int] = {}
        plan_type = {PROV_TYPE: t(ids.PROV_PLAN)}
        for assignment in mission.allocation:
            if assignment.robot not in robots:
                raise ExsceError(
                    f"mission '{mission.id}' allocates a task to robot '{assignment.robot}', "
                    f"which is not in scenario '{scenario.id}'",
                    assignment.location,
                )
            if assignment.task not in self._tasks:
                raise ExsceError(
                    f"mission '{mission.id}' allocates task '{assignment.task}', "
                    f"which is not among the tasks of scenario '{scenario.id}'",
                    assignment.location,
                )
            counts[assignment.robot] = n = counts.get(assignment.robot, 0) + 1
            plan_id = mission_ns[ids.allocation_name(assignment.robot, n)]
            w.entity(plan_id, plan_type)
            plans.append((plan_id, task_ns[assignment.task]))

        w.member(scenario_id, mission_id)
        w.member(scenario_id, env_ns[scenario.environment.id])
        for robot in scenario.robots:
            w.member(scenario_id, robot_ns[ids.robot_name(robot)])
        for plan_id, _ in plans:
            w.member(mission_id, plan_id)

        self._write_poses(w, loose_start_poses)
        role_scenario = {PROV_ROLE: START_POSE_ROLE, t(ids.SCENARIO_ATTR): scenario.id}
        for robot in scenario.robots:
            if robot.start_pose is None:
                continue
            key = ids.robot_name(robot)
            robot_parts = w.of_element(robot.id, names.of_robot(key), "robot")
            w.derivation(
                robot_parts[ids.GAZEBO_MODEL],
                self._pose_id(w, robot.start_pose),
                role_scenario,
                identifier=scenario_ns[ids.start_pose_relation_name(robot.id)],
            )
        primary_source = {PROV_TYPE: t(ids.PROV_PRIMARY_SOURCE)}
        for plan_id, task_id in plans:
            w.derivation(plan_id, task_id, primary_source)

    def _environment_bundle(self, environment: Environment, loose_poses: list[Pose]) -> None:
        w = self._bundle(ids.ENV, environment.id, f"environment '{environment.id}'", environment.location)
        t = w.term
        env_id = w.fixed(ids.ENV)[environment.id]
        parts = w.of_element(environment.id, self.names.of_environment(environment.id), "environment")
        w.entity(env_id, {PROV_TYPE: t(ids.ENVIRONMENT_TYPE)})
        members: list[tuple[QualifiedName, QualifiedName]] = []
        if environment.map is not None:
            map_model: MapModel = environment.map
            map_id = parts[ids.map_entity_name(map_model.name)]
            grid_id, metadata_id = parts[ids.OCCUPANCY_GRID], parts[ids.MAP_METADATA]
            w.entity(map_id, {PROV_TYPE: t(ids.MAP_TYPE), **_ros(w, map_model.source)})
            w.entity(grid_id, {PROV_TYPE: t(ids.ROS_OCCUPANCY_GRID)})
            w.entity(metadata_id, {PROV_TYPE: t(ids.ROS_PARAMETER_SERVER)})
            members += [(map_id, grid_id), (map_id, metadata_id), (env_id, map_id)]
        if environment.world is not None:
            world: WorldModel = environment.world
            world_id = parts[ids.GAZEBO_WORLD]
            w.entity(world_id, {PROV_TYPE: t(ids.ROS_GAZEBO_MODEL), **_ros(w, world.source)})
            members.append((env_id, world_id))
        obstacles = []
        for obstacle in environment.obstacles:
            obstacle_id = parts[obstacle.id]
            attributes: Attributes = {PROV_TYPE: t(ids.OBSTACLE_TYPE)}
            if obstacle.model is not None:
                attributes[t(ids.OBSTACLE_MODEL)] = obstacle.model
            if obstacle.size is not None:
                attributes[t(ids.OBSTACLE_SIZE)] = " ".join(repr(float(s)) for s in obstacle.size)
            w.entity(obstacle_id, attributes)
            members.append((env_id, obstacle_id))
            obstacles.append((obstacle_id, obstacle))
        for collection, member in members:
            w.member(collection, member)
        self._write_poses(w, loose_poses)
        role = {PROV_ROLE: OBSTACLE_POSE_ROLE}
        for obstacle_id, obstacle in obstacles:
            w.derivation(
                obstacle_id,
                self._pose_id(w, obstacle.pose),
                role,
                identifier=parts[ids.obstacle_pose_relation_name(obstacle.id)],
            )

    def _area_bundle(self, area_id: str, poses: dict[str, Pose]) -> None:
        location = self._area_locations.get(area_id)
        w = self._bundle(ids.ENV, area_id, f"area '{area_id}'", location)
        self._write_poses(w, poses.values())

    def _robot_bundle(self, robot: Robot) -> None:
        key = ids.robot_name(robot)
        w = self._bundle(ids.ROBOT, key, f"robot '{robot.id}'", robot.location)
        t = w.term
        robot_id = w.fixed(ids.ROBOT)[key]
        parts = w.of_element(robot.id, self.names.of_robot(key), "robot")
        software, hardware = parts[SOFTWARE_CONFIG], parts[HARDWARE_CONFIG]
        model = parts[ids.GAZEBO_MODEL]
        w.entity(robot_id, {PROV_TYPE: t(ids.ROBOT_TYPE_VALUE), t(ids.ROBOT_TYPE): robot.type.id})
        w.entity(software, {PROV_TYPE: SOFTWARE_CONFIG, t(ids.ROS_NAMESPACE): robot.namespace})
        hardware_facts: Attributes = {PROV_TYPE: HARDWARE_CONFIG}
        if robot.type.base is not None:
            hardware_facts[t(ids.BASE_TYPE)] = robot.type.base
        if robot.type.torso is not None:
            hardware_facts[t(ids.TORSO)] = bool(robot.type.torso)
        w.entity(hardware, hardware_facts)
        w.entity(model, {PROV_TYPE: t(ids.ROS_GAZEBO_MODEL)})
        w.agent(parts[ids.ROBOT_AGENT], {PROV_TYPE: t(ids.PROV_SOFTWARE_AGENT)})
        w.member(robot_id, model)
        w.member(robot_id, software)
        w.member(robot_id, hardware)

    def _task_bundle(self, task: Task) -> None:
        w = self._bundle(ids.TASK, task.id, f"task '{task.id}'", task.location)
        t = w.term
        task_ns = w.fixed(ids.TASK)
        task_id = task_ns[task.id]
        w.entity(task_id, {PROV_TYPE: t(ids.PROV_PLAN), **_ros(w, task.source)})
        plan_type = {PROV_TYPE: t(ids.PROV_PLAN)}
        subtask_ids = [task_ns[ids.subtask_name(task.id, i)] for i in range(1, len(task.subtasks) + 1)]
        for subtask_id in subtask_ids:
            w.entity(subtask_id, plan_type)
        waypoint_role = {PROV_ROLE: WAYPOINT_ROLE}
        for index, (subtask, subtask_id) in enumerate(zip(task.subtasks, subtask_ids, strict=True), start=1):
            w.derivation(task_id, subtask_id, {PROV_ROLE: ids.subtask_role(index)})
            relations = w.of_element(
                ids.subtask_name(task.id, index), self.names.of_subtask(task.id, index), "subtask"
            )
            for number, waypoint in enumerate(subtask.waypoints, start=1):
                w.derivation(
                    subtask_id,
                    self._pose_id(w, waypoint),
                    waypoint_role,
                    identifier=relations[ids.waypoint_relation_name(number)],
                )
        self._write_poses(w, (p for p in task.waypoints() if p.area is None))


def _place_poses(
    scenario: Scenario, pose_name: Callable[[Pose], str]
) -> tuple[dict[str, dict[str, Pose]], list[Pose], list[Pose]]:
    """Which bundle holds each pose: its area's (by ``pose_name``), or (without area) its user's:
    the poses by area, then the start poses and the obstacles' poses that have none."""
    by_area: dict[str, dict[str, Pose]] = {}

    def place(area_id: str, pose: Pose) -> None:
        by_area.setdefault(area_id, {}).setdefault(pose_name(pose), pose)

    for area in scenario.environment.areas:
        by_area.setdefault(area.id, {})
        for pose in area.poses:
            place(area.id, pose)
    loose_start: list[Pose] = []
    for robot in scenario.robots:
        if robot.start_pose is not None:
            if robot.start_pose.area is None:
                loose_start.append(robot.start_pose)
            else:
                place(robot.start_pose.area, robot.start_pose)
    for task in scenario.tasks:
        for waypoint in task.waypoints():
            if waypoint.area is not None:
                place(waypoint.area, waypoint)
    loose_obstacle: list[Pose] = []
    for obstacle in scenario.environment.obstacles:
        if obstacle.pose.area is None:
            loose_obstacle.append(obstacle.pose)
        else:
            place(obstacle.pose.area, obstacle.pose)
    return by_area, loose_start, loose_obstacle


def _ros(w: BundleWriter, source: RosResource | None) -> Attributes:
    """Where a resource lives in a ROS package, as attributes."""
    if source is None:
        return {}
    found: Attributes = {w.term(ids.ROS_PKG): source.package}
    if source.path is not None:
        found[w.term(ids.ROS_RELATIVE_PATH)] = source.path
    return found
