"""The store benchmark's synthetic data (bench/store.py): a scenario of two tiagos with two tasks
of five waypoints each in one room, and runs shaped like the method's (every metric per path
segment, per robot and for the mission, the bag's topics, a few hotspots), drawn from a seed."""

from __future__ import annotations

import datetime
import random
import uuid
from collections.abc import Iterator

from exsce_dsl.model import (
    Area,
    Assignment,
    Environment,
    Mission,
    MissionType,
    Orientation,
    Pose,
    Position,
    Robot,
    RobotType,
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.runs import (
    Action,
    ActionId,
    Bag,
    Hotspot,
    MetricScope,
    MetricValue,
    Run,
    TaskExecution,
)

ROBOTS = ("tiago1", "tiago2")
HOTSPOT_FREE = 0.9
"""The share of runs that keep to every safety limit (no hotspot, no violation)."""
WAYPOINTS_PER_TASK = 5
TASKS_PER_ROBOT = 2
SEGMENT_METRICS = ("task_duration", "distance_travelled", "distance_to_obstacles", "max_velocity")
ROBOT_METRICS = (*SEGMENT_METRICS, "waypoints_visited", "violation_duration")
MISSION_METRICS = ("mission_duration", "distance_between_robots", "violation_duration")
TOPICS = {
    "task_duration": ("waypoint_dispatcher/feedback",),
    "waypoints_visited": ("waypoint_dispatcher/result",),
    "distance_travelled": ("distance_travelled",),
    "distance_to_obstacles": ("scan",),
    "max_velocity": ("nav_vel",),
    "violation_duration": ("nav_vel",),
}
MISSION_TOPICS = {
    "mission_duration": "waypoint_dispatcher/feedback",
    "distance_between_robots": "robot_pose",
    "violation_duration": "robot_pose",
}


def synthetic_scenario() -> Scenario:
    """Two tiagos, each with two tasks of five waypoints, in one room of 24 poses."""
    poses = tuple(
        Pose(f"room-w{i:03d}", Position(float(i % 6), float(i // 6), 0.0), Orientation(0.0, 0.0, 0.0), "room")
        for i in range(1, 25)
    )
    environment = Environment("bench_building", areas=(Area("room", poses),))
    tiago = RobotType("tiago", base="pmb2", torso=True)
    robots = tuple(Robot(robot, tiago, robot, start_pose=poses[n]) for n, robot in enumerate(ROBOTS))
    tasks = []
    allocation = []
    for r, robot in enumerate(ROBOTS):
        for k in range(TASKS_PER_ROBOT):
            first = 2 + r * 10 + k * WAYPOINTS_PER_TASK
            waypoints = poses[first : first + WAYPOINTS_PER_TASK]
            task_id = f"task_{robot}_{k + 1}"
            tasks.append(Task(task_id, (Subtask(waypoints),)))
            allocation.append(Assignment(robot, task_id))
    mission = Mission("bench_mission", MissionType.PARALLEL, tuple(allocation))
    return Scenario("bench_scenario", environment, robots, mission, tuple(tasks))


def synthetic_run(scenario: Scenario, rng: random.Random, number: int) -> Run:
    """Run ``number`` of the bench: most runs keep to the safety limits; one in ten has one to
    three hotspots of max_velocity (the first robot's, then the second's), and violated that limit
    as long as they last; a run with three violated the mission's distance between the robots too."""
    start = datetime.datetime(2024, 1, 1) + datetime.timedelta(minutes=10 * number)
    hotspots = tuple(
        Hotspot(
            "max_velocity",
            Position(rng.uniform(0, 6), rng.uniform(0, 4)),
            rng.randint(1, 5),
            rng.uniform(0.1, 3.0),
            robot=ROBOTS[i % 2],
        )
        for i in range(0 if rng.random() < HOTSPOT_FREE else rng.randint(1, 3))
    )
    violated = {robot: sum(h.duration for h in hotspots if h.robot == robot) for robot in ROBOTS}
    tasks: list[TaskExecution] = []
    metrics: list[MetricValue] = []
    clock = start
    topics: list[str] = []
    for robot in scenario.robots:
        ns = f"/{robot.namespace}"
        robot_topics = {m: tuple(f"{ns}/{t}" for t in names) for m, names in TOPICS.items()}
        topics += [
            f"{ns}/{t}"
            for t in (
                "waypoint_dispatcher/feedback",
                "waypoint_dispatcher/result",
                "distance_travelled",
                "scan",
                "nav_vel",
                "robot_pose",
            )
        ]
        previous = robot.start_pose
        assert previous is not None
        for k, task_id in enumerate(scenario.mission.tasks_of(robot.id), start=1):
            task = scenario.task(task_id)
            assert task is not None
            actions = []
            for w, goal in enumerate(task.waypoints(), start=1):
                begin, clock = clock, clock + datetime.timedelta(seconds=rng.uniform(5, 20))
                action = Action(ActionId(robot.id, k, 1, w), previous, goal, start=begin, end=clock)
                actions.append(action)
                for metric in SEGMENT_METRICS:
                    metrics.append(
                        MetricValue(
                            metric,
                            MetricScope.SEGMENT,
                            rng.uniform(0.1, 20.0),
                            robot_topics[metric],
                            action=action.id,
                        )
                    )
                previous = goal
            tasks.append(TaskExecution(robot.id, k, tuple(actions)))
        for metric in ROBOT_METRICS:
            metrics.append(
                MetricValue(
                    metric,
                    MetricScope.ROBOT,
                    violated[robot.id] if metric == "violation_duration" else rng.uniform(0.0, 100.0),
                    robot_topics[metric],
                    robot=robot.id,
                    safety_metric="max_velocity" if metric == "violation_duration" else None,
                )
            )
    for metric, topic in MISSION_TOPICS.items():
        metrics.append(
            MetricValue(
                metric,
                MetricScope.MISSION,
                (rng.uniform(0.5, 5.0) if len(hotspots) == 3 else 0.0)
                if metric == "violation_duration"
                else rng.uniform(0.0, 300.0),
                tuple(f"/{r}/{topic}" for r in ROBOTS),
                safety_metric="distance_between_robots" if metric == "violation_duration" else None,
            )
        )
    run_uuid = str(uuid.UUID(int=rng.getrandbits(128), version=4))
    bag = Bag(f"{start:%Y-%m-%dT%H-%M-%S}_bench_run-{run_uuid[:8]}.bag", tuple(topics))
    return Run(run_uuid, scenario.id, start, clock, bag, tuple(tasks), tuple(metrics), hotspots)


def synthetic_runs(scenario: Scenario, count: int, seed: int = 1) -> Iterator[Run]:
    rng = random.Random(seed)
    for number in range(count):
        yield synthetic_run(scenario, rng, number)
