"""Scenarios built by hand in the semantic model, for tests that need one without the language:
scenario_c as the method's published YAML has it, and large scenarios for scale."""

from __future__ import annotations

from prov.model import ProvDocument
from rdflib import Graph

from exsce_dsl.model import (
    Area,
    Assignment,
    Environment,
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
from exsce_dsl.rdf import to_dataset

# -- scenario_c, written by hand from scenario_c.yaml and its task files -------


def pose(pose_id: str, x: float, y: float, yaw: float = 0.0) -> Pose:
    return Pose(pose_id, Position(x, y, 0.0), Orientation(0.0, 0.0, yaw), pose_id.split("-")[0])


C025_W001 = pose("classroom_c025-w001", 44.80387496948242, 37.15502166748047)
C025_W002 = pose("classroom_c025-w002", 43.432926177978516, 38.493873596191406)
C022_W001 = pose("classroom_c022-w001", 52.82560729980469, 32.562904357910156, 2.269)
C022_W002 = pose("classroom_c022-w002", 54.497589111328125, 31.52023696899414, 2.269)
C018_W001 = pose("classroom_c018-w001", 48.26420974731445, 24.618297576904297, -0.641)
C018_W002 = pose("classroom_c018-w002", 46.25560760498047, 21.586545944213867, -0.641)
HOME = Orientation(0.0, 0.0, 0.925)

TIAGO = RobotType("tiago", base="pmb2", torso=True)


def task(task_id: str, *waypoints: Pose) -> Task:
    source = RosResource("metamorphic_testing", f"config/tasks/{task_id}.yaml")
    return Task(task_id, (Subtask(waypoints),), source)


def environment_c() -> Environment:
    models = RosResource("floorplan-DSL-environments", "maps/")
    worlds = RosResource("floorplan-DSL-environments", "worlds/")
    return Environment(
        "brsu_building_c_with_doors",
        map=MapModel("brsu_building_c_with_doors", models),
        world=WorldModel("brsu_building_c_with_doors", worlds),
        areas=(
            Area("classroom_c025", (C025_W001, C025_W002)),
            Area("classroom_c022", (C022_W001, C022_W002)),
            Area("classroom_c018", (C018_W001, C018_W002)),
        ),
    )


def scenario_c() -> Scenario:
    tasks = (
        task("delivery_a", C022_W001, C018_W001),
        task("delivery_b", C022_W002, C018_W002),
        task("navigate_home_1", C025_W001.with_orientation(HOME)),
        task("navigate_home_2", C025_W002.with_orientation(HOME)),
    )
    robots = (
        Robot("tiago1", TIAGO, "tiago1", start_pose=C025_W001),
        Robot("tiago2", TIAGO, "tiago2", start_pose=C025_W002),
    )
    mission = Mission(
        "mission_c",
        MissionType.PARALLEL,
        (
            Assignment("tiago1", "delivery_a"),
            Assignment("tiago2", "delivery_b"),
            Assignment("tiago1", "navigate_home_1"),
            Assignment("tiago2", "navigate_home_2"),
        ),
    )
    return Scenario("scenario_c", environment_c(), robots, mission, tasks)


def merged(document: ProvDocument) -> Graph:
    """Every triple of the document's PROV-O, whatever its graph."""
    graph = Graph()
    for s, p, o, _ in to_dataset(document).quads():
        graph.add((s, p, o))
    return graph


def large_scenario(robots: int = 100, poses: int = 2000, tasks: int = 500) -> Scenario:
    """``robots`` robots, ``poses`` poses in 50 areas, ``tasks`` tasks of 2×4 waypoints."""
    areas = []
    all_poses: list[Pose] = []
    for a in range(50):
        area_poses = tuple(
            Pose(
                f"room{a}-w{i:03d}",
                Position(a + i * 0.1, i * 0.2),
                Orientation(yaw=i * 0.01),
                f"room{a}",
            )
            for i in range(poses // 50)
        )
        areas.append(Area(f"room{a}", area_poses))
        all_poses.extend(area_poses)
    environment = Environment("big", MapModel("big", RosResource("pkg", "maps/")), areas=tuple(areas))
    task_list = tuple(
        Task(
            f"task{t}",
            tuple(
                Subtask(
                    tuple(
                        all_poses[(t * 7 + s * 3 + w * 11) % len(all_poses)].with_orientation(
                            Orientation(yaw=0.5 * w)
                        )
                        for w in range(4)
                    )
                )
                for s in range(2)
            ),
            RosResource("pkg", f"tasks/task{t}.yaml"),
        )
        for t in range(tasks)
    )
    robot_list = tuple(Robot(f"r{r}", TIAGO, f"r{r}", start_pose=all_poses[r]) for r in range(robots))
    allocation = tuple(Assignment(f"r{t % robots}", f"task{t}") for t in range(tasks))
    return Scenario("big", environment, robot_list, Mission("m", MissionType.PARALLEL, allocation), task_list)
