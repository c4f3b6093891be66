"""Where each node of a compiled scenario comes from in the DSL.

Once a scenario is RDF, source positions are lost; :func:`source_locations`
gives them back: for each IRI that :func:`~exsce_dsl.prov.compile_scenario`
writes (scenario, mission, allocated plans, robots and their parts, start
pose derivations, environment, map, world, obstacles, poses, points,
orientations, tasks, subtasks, waypoint derivations, and the bundles), the
location of the DSL element it was made from.  SHACL violations are reported
through it as ``file:line:col``.

The IRIs are those of :mod:`exsce_dsl.prov.identifiers`, the same rules the
compiler follows.  A node made from several elements takes the first in this
order: for poses, a declaration in the environment before a use with another
heading (a start pose, then a waypoint, then an obstacle); a point is where
its pose is first declared or used; an orientation, where the first pose
that has it is.
"""

from __future__ import annotations

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.geometry import Pose
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces

__all__ = ["source_locations"]


def source_locations(scenario: Scenario, namespace: str = DEFAULT_NAMESPACE) -> dict[str, SourceLocation]:
    """Node IRI → the source location of the DSL element it was compiled from.

    Elements without a location (built in Python rather than parsed) are left
    out; so is everything when the scenario has none.
    """
    names = Namespaces(namespace)
    fixed = names.fixed
    found: dict[str, SourceLocation] = {}

    def put(iri: str, location: SourceLocation | None) -> None:
        if location is not None:
            found.setdefault(iri, location)

    def put_pose(pose: Pose, location: SourceLocation | None) -> None:
        put(fixed[ids.POSE] + ids.pose_name(pose), location)
        put(fixed[ids.POINT] + ids.point_name(pose), location)
        put(fixed[ids.ORIENTATION] + ids.orientation_name(pose.orientation), location)

    # The scenario bundle: scenario, mission, allocated plans.
    put(fixed[ids.EXSCE] + scenario.id, scenario.location)
    put(fixed[ids.EXSCE] + ids.bundle_name(scenario.id), scenario.location)
    mission = scenario.mission
    put(fixed[ids.MISSION] + mission.id, mission.location)
    counts: dict[str, int] = {}
    for assignment in mission.allocation:
        counts[assignment.robot] = n = counts.get(assignment.robot, 0) + 1
        put(names.of_mission(mission.id) + ids.allocation_name(assignment.robot, n), assignment.location)

    # The environment, its models, areas and obstacles.
    environment = scenario.environment
    env_parts = names.of_environment(environment.id)
    put(fixed[ids.ENV] + environment.id, environment.location)
    put(fixed[ids.ENV] + ids.bundle_name(environment.id), environment.location)
    if environment.map is not None:
        where = environment.map.location or environment.location
        for part in (ids.map_entity_name(environment.map.name), ids.OCCUPANCY_GRID, ids.MAP_METADATA):
            put(env_parts + part, where)
    if environment.world is not None:
        put(env_parts + ids.GAZEBO_WORLD, environment.world.location or environment.location)
    for area in environment.areas:
        put(fixed[ids.ENV] + ids.bundle_name(area.id), area.location)
        for pose in area.poses:
            put_pose(pose, pose.location or area.location)
    for obstacle in environment.obstacles:
        put(env_parts + obstacle.id, obstacle.location)
        put(env_parts + ids.obstacle_pose_relation_name(obstacle.id), obstacle.location)

    # Robots, their parts and start poses.
    for robot in scenario.robots:
        key = ids.robot_name(robot)
        put(fixed[ids.ROBOT] + key, robot.location)
        put(fixed[ids.ROBOT] + ids.bundle_name(key), robot.location)
        robot_parts = names.of_robot(key)
        for part in (ids.GAZEBO_MODEL, ids.ROBOT_AGENT, ids.SOFTWARE_CONFIG, ids.HARDWARE_CONFIG):
            put(robot_parts + part, robot.location)
        if robot.start_pose is not None:
            where = robot.start_pose.location or robot.location
            put(names.of_scenario(scenario.id) + ids.start_pose_relation_name(robot.id), where)
            put_pose(robot.start_pose, where)

    # Tasks, subtasks and waypoints.
    for task in scenario.tasks:
        put(fixed[ids.TASK] + task.id, task.location)
        put(fixed[ids.TASK] + ids.bundle_name(task.id), task.location)
        for index, subtask in enumerate(task.subtasks, start=1):
            subtask_where = subtask.location or task.location
            put(fixed[ids.TASK] + ids.subtask_name(task.id, index), subtask_where)
            relations = names.of_subtask(task.id, index)
            for number, waypoint in enumerate(subtask.waypoints, start=1):
                where = waypoint.location or subtask_where
                put(relations + ids.waypoint_relation_name(number), where)
                put_pose(waypoint, where)

    for obstacle in environment.obstacles:
        put_pose(obstacle.pose, obstacle.location)
    return found
