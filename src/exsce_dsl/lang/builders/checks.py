"""Semantic checks on built scenarios and environments.

Each check returns diagnostics instead of raising, so that one pass reports
every problem it finds.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from exsce_dsl.errors import Diagnostic, ExsceError, Severity
from exsce_dsl.maps.grid import FREE, OUTSIDE, OccupancyGrid, load_occupancy_grid, map_image
from exsce_dsl.model import Environment, Pose, Scenario
from exsce_dsl.model.metrics import ComputedFor
from exsce_dsl.model.names import is_ros_namespace

# ROS graph resource names (namespaces): letters, digits, _ and / separators.


def check_scenario(scenario: Scenario) -> list[Diagnostic]:
    found: list[Diagnostic] = []
    env = scenario.environment
    env_pose_ids = {p.id for p in env.poses()}
    busy = {a.robot for a in scenario.mission.allocation}

    namespaces: dict[str, str] = {}
    starts: dict[str, str] = {}
    for robot in scenario.robots:
        if not is_ros_namespace(robot.namespace):
            found.append(
                Diagnostic(
                    f"namespace '{robot.namespace}' of robot '{robot.id}' is not a valid ROS name",
                    robot.location,
                )
            )
        if robot.namespace in namespaces:
            found.append(
                Diagnostic(
                    f"robots '{namespaces[robot.namespace]}' and '{robot.id}' share the namespace "
                    f"'{robot.namespace}'; their topics would mix",
                    robot.location,
                )
            )
        namespaces.setdefault(robot.namespace, robot.id)
        if robot.start_pose is None:
            if robot.id in busy:
                found.append(
                    Diagnostic(
                        f"robot '{robot.id}' has tasks in mission '{scenario.mission.id}' but no start "
                        "pose; add 'starts at <pose>'",
                        robot.location,
                    )
                )
        else:
            other = starts.get(robot.start_pose.id)
            if other is not None:
                found.append(
                    Diagnostic(
                        f"robots '{other}' and '{robot.id}' both start at '{robot.start_pose.id}'",
                        robot.start_pose.location or robot.location,
                    )
                )
            starts.setdefault(robot.start_pose.id, robot.id)
        if robot.id not in busy:
            found.append(
                Diagnostic(
                    f"robot '{robot.id}' has no task in mission '{scenario.mission.id}'",
                    robot.location,
                    severity=Severity.WARNING,
                )
            )

    for entry in scenario.mission.allocation:
        task = scenario.task(entry.task)
        if task is None:
            continue
        for waypoint in task.waypoints():
            if waypoint.area is not None and waypoint.id not in env_pose_ids:
                found.append(
                    Diagnostic(
                        f"task '{task.id}' visits pose '{waypoint.id}', which is not in environment "
                        f"'{env.id}' of scenario '{scenario.id}'",
                        entry.location,
                    )
                )
        if env.map is not None and env.map.file is not None:
            grid = _grid_or_none(env.map.file)
            if grid is not None:
                for waypoint in task.waypoints():
                    if waypoint.area is None:
                        problem = _pose_problem(grid, waypoint, env.map.name)
                        if problem:
                            found.append(Diagnostic(problem, waypoint.location))
    return found + check_metric_topics(scenario)


def check_metric_topics(scenario: Scenario) -> list[Diagnostic]:
    """A metric of each robot reads each robot's own topics, so its topics name the robot's
    namespace (``"/{ns}/odom"``); one that does not (``"groundtruth"``) is the same topic for
    every robot, which only a robot at the root (``namespace ""``) may read as its own."""
    namespaced = [r for r in scenario.robots if r.namespace.strip("/")]
    if not namespaced:
        return []
    robot = namespaced[0]
    return [
        Diagnostic(
            f"a topic of each robot needs '{{ns}}' in its name: '{read.topic}' (robot '{robot.id}' of "
            f"scenario '{scenario.id}' is in namespace '{robot.namespace}'; only a robot at the root, "
            'namespace "", may read a topic without it)',
            read.location,
        )
        for metric in scenario.metrics
        if metric.subject is not ComputedFor.MISSION
        for read in metric.reads
        if not read.signal and "{ns}" not in read.topic
    ]


def check_environment_map(env: Environment) -> list[Diagnostic]:
    """Every declared pose and obstacle must lie in the free space of a known map."""
    if env.map is None or env.map.file is None:
        return []
    try:
        grid = _grid(env.map.file)
    except ExsceError as exc:
        return [Diagnostic(exc.message, env.map.location)]
    found = []
    for pose in env.poses():
        problem = _pose_problem(grid, pose, env.map.name)
        if problem:
            found.append(Diagnostic(problem, pose.location))
    for obstacle in env.obstacles:
        if grid.state_at(obstacle.pose.position.x, obstacle.pose.position.y) == OUTSIDE:
            found.append(
                Diagnostic(
                    f"obstacle '{obstacle.id}' is outside the map '{env.map.name}'{_bounds(grid)}",
                    obstacle.location,
                )
            )
    return found


def _pose_problem(grid: OccupancyGrid, pose: Pose, map_name: str) -> str | None:
    x, y = pose.position.x, pose.position.y
    state = grid.state_at(x, y)
    if state == FREE:
        return None
    where = f"pose '{pose.id}' at ({x:g}, {y:g})"
    if state == OUTSIDE:
        return f"{where} is outside the map '{map_name}'{_bounds(grid)}"
    return f"{where} is in {state} space of the map '{map_name}', not in free space"


def _bounds(grid: OccupancyGrid) -> str:
    x0, x1, y0, y1 = grid.bounds()
    return f" (x from {x0:.2f} to {x1:.2f}, y from {y0:.2f} to {y1:.2f})"


def _grid(path: str) -> OccupancyGrid:
    """The map at ``path``, read again when its YAML or image changed (an editor's session
    outlives many edits of a map)."""
    return _read_grid(path, _map_signature(path))


@lru_cache(maxsize=8)
def _read_grid(path: str, signature: tuple[tuple[str, int, int], ...]) -> OccupancyGrid:
    return load_occupancy_grid(Path(path))


def _map_signature(path: str) -> tuple[tuple[str, int, int], ...]:
    found = []
    for file in (Path(path), map_image(Path(path))):
        try:
            stat = file.stat() if file is not None else None
        except OSError:
            stat = None
        found.append((str(file), stat.st_mtime_ns if stat else -1, stat.st_size if stat else -1))
    return tuple(found)


def _grid_or_none(path: str) -> OccupancyGrid | None:
    try:
        return _grid(path)
    except ExsceError:
        return None
