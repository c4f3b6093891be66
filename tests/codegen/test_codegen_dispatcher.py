"""The dispatcher-config generator: the waypoint files the method's waypoint dispatcher reads.

Contracts are written out by hand from the method's own files (scenario_c's task files and
start poses); the golden files under ``tests/golden/dispatcher/`` pin the exact text.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.codegen.dispatcher import MISSION_FILE, dispatcher_files, generate_dispatcher_config
from exsce_dsl.errors import GenerationError
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Document, Orientation, Pose, Position, Scenario, Specification, Subtask, Task

from tests.support.paths import EXAMPLES, FIXTURES

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
SCENARIO_D = EXAMPLES / "brsu_building_c" / "scenario_d.exsce"
GOLDEN = Path(__file__).parents[1] / "golden" / "dispatcher"
METHOD_TASKS = FIXTURES / "tasks" / "brsu_building_c_with_doors"


def _files_below(folder: Path) -> dict[str, str]:
    return {p.relative_to(folder).as_posix(): p.read_text() for p in sorted(folder.rglob("*")) if p.is_file()}


def _scenario_c() -> Scenario:
    return load_spec(SCENARIO_C).scenario("scenario_c")


def _spec_of(scenario: Scenario) -> Specification:
    return Specification("made.exsce", (Document("made.exsce", (), (scenario,)),))


def _with_pose(pose: dict[str, Any]) -> dict[str, Any]:
    """The method's task files may leave z out; it means 0.0."""
    return {"z": 0.0, **pose}


def test_scenario_c_mission_file_names_type_namespaces_start_poses_and_task_files(tmp_path: Path) -> None:
    generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path)
    mission = yaml.safe_load((tmp_path / "mission.yaml").read_text())
    assert mission == {
        "scenario": "scenario_c",
        "mission": {"id": "mission_c", "type": "parallel"},
        "robots": [
            {
                "robot_id": "tiago1",
                "robot_namespace": "tiago1",
                "start_pose": {
                    "id": "classroom_c025-w001",
                    "x": 44.80387496948242,
                    "y": 37.15502166748047,
                    "z": 0.0,
                    "roll": 0.0,
                    "pitch": 0.0,
                    "yaw": 0.0,
                },
                "task_files": ["tiago1/delivery_a.yaml", "tiago1/navigate_home_1.yaml"],
            },
            {
                "robot_id": "tiago2",
                "robot_namespace": "tiago2",
                "start_pose": {
                    "id": "classroom_c025-w002",
                    "x": 43.432926177978516,
                    "y": 38.493873596191406,
                    "z": 0.0,
                    "roll": 0.0,
                    "pitch": 0.0,
                    "yaw": 0.0,
                },
                "task_files": ["tiago2/delivery_b.yaml", "tiago2/navigate_home_2.yaml"],
            },
        ],
        "allocation": [
            {"robot_namespace": "tiago1", "file_path": "tiago1/delivery_a.yaml"},
            {"robot_namespace": "tiago2", "file_path": "tiago2/delivery_b.yaml"},
            {"robot_namespace": "tiago1", "file_path": "tiago1/navigate_home_1.yaml"},
            {"robot_namespace": "tiago2", "file_path": "tiago2/navigate_home_2.yaml"},
        ],
    }


@pytest.mark.parametrize(
    ("written", "method_file"),
    [
        ("tiago1/delivery_a.yaml", "delivery_a.yaml"),
        ("tiago2/delivery_b.yaml", "delivery_b.yaml"),
        ("tiago1/navigate_home_1.yaml", "navigate_home_1.yaml"),
        ("tiago2/navigate_home_2.yaml", "navigate_home_2.yaml"),
    ],
)
def test_scenario_c_task_files_hold_the_methods_waypoints(
    tmp_path: Path, written: str, method_file: str
) -> None:
    generate_dispatcher_config(load_spec(SCENARIO_C), "scenario_c", tmp_path)
    ours = yaml.safe_load((tmp_path / written).read_text())
    theirs = yaml.safe_load((METHOD_TASKS / method_file).read_text())
    assert ours == {
        "task": [{"waypoints": [_with_pose(w) for w in sub["waypoints"]]} for sub in theirs["task"]]
    }


def test_task_files_agree_with_the_model(tmp_path: Path) -> None:
    scenario = _scenario_c()
    generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path)
    mission = yaml.safe_load((tmp_path / MISSION_FILE).read_text())
    for robot, entry in zip(scenario.robots, mission["robots"], strict=True):
        task_ids = scenario.mission.tasks_of(robot.id)
        assert entry["task_files"] == [f"{robot.namespace}/{t}.yaml" for t in task_ids]
        for task_id, path in zip(task_ids, entry["task_files"], strict=True):
            task = scenario.task(task_id)
            assert task is not None
            written = yaml.safe_load((tmp_path / path).read_text())["task"]
            assert [[w["id"] for w in s["waypoints"]] for s in written] == [
                [w.id for w in s.waypoints] for s in task.subtasks
            ]
            for w, pose in zip((w for s in written for w in s["waypoints"]), task.waypoints(), strict=True):
                p = pose.position
                assert (w["x"], w["y"], w["z"], w["yaw"]) == (p.x, p.y, p.z, pose.orientation.yaw)


def test_every_file_says_it_is_generated_from_which_spec_and_scenario(tmp_path: Path) -> None:
    written = generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path)
    assert written[0] == tmp_path / "mission.yaml"
    assert len(written) == 5
    for path in written:
        head = path.read_text().splitlines()[:2]
        assert head == [
            '# Generated by exsce (exscec generate dispatcher-config) from "scenario_c.exsce", '
            'scenario "scenario_c".',
            "# Do not edit this file by hand: change the specification and generate again.",
        ]


def test_scenario_c_matches_the_golden_files(tmp_path: Path) -> None:
    """On a wanted change: ``exscec generate dispatcher-config examples/brsu_building_c/scenario_c.exsce
    -o tests/golden/dispatcher/scenario_c --force``, then review the diff."""
    generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path)
    golden = _files_below(GOLDEN / "scenario_c")
    assert sorted(golden) == [
        "mission.yaml",
        "tiago1/delivery_a.yaml",
        "tiago1/navigate_home_1.yaml",
        "tiago2/delivery_b.yaml",
        "tiago2/navigate_home_2.yaml",
    ]
    assert _files_below(tmp_path) == golden


def test_a_sequential_mission_keeps_the_allocation_order(tmp_path: Path) -> None:
    generate_dispatcher_config(load_spec(SCENARIO_D), None, tmp_path)
    mission = yaml.safe_load((tmp_path / MISSION_FILE).read_text())
    assert mission["mission"] == {"id": "mission_d", "type": "sequential"}
    assert [a["file_path"] for a in mission["allocation"]] == [
        "tiago1/delivery_a.yaml",
        "tiago1/delivery_b.yaml",
        "tiago1/navigate_home_1.yaml",
    ]


def test_a_task_given_twice_is_one_file_listed_twice() -> None:
    scenario = _scenario_c()
    twice = (*scenario.mission.allocation, scenario.mission.allocation[0])
    scenario = dataclasses.replace(scenario, mission=dataclasses.replace(scenario.mission, allocation=twice))
    files = dispatcher_files(scenario, "made.exsce")
    assert len(files) == 5
    tiago1 = yaml.safe_load(files[MISSION_FILE])["robots"][0]["task_files"]
    assert tiago1 == ["tiago1/delivery_a.yaml", "tiago1/navigate_home_1.yaml", "tiago1/delivery_a.yaml"]


@pytest.mark.parametrize(
    "namespace", ["../evil", "/fleet/tiago1", "tiago 1", "tiago1/", ".hidden", "1tiago"]
)
def test_a_namespace_that_is_not_a_plain_ros_name_is_refused(tmp_path: Path, namespace: str) -> None:
    scenario = _scenario_c()
    robots = (dataclasses.replace(scenario.robots[0], namespace=namespace), *scenario.robots[1:])
    spec = _spec_of(dataclasses.replace(scenario, robots=robots))
    with pytest.raises(GenerationError, match=r"namespace .* of robot 'tiago1' is not a plain ROS name"):
        generate_dispatcher_config(spec, None, tmp_path / "out")
    assert not (tmp_path / "out").exists()
    assert not any(tmp_path.rglob("*.yaml"))


def test_nothing_is_written_when_a_file_exists_unless_overwrite(tmp_path: Path) -> None:
    (tmp_path / "tiago2").mkdir()
    (tmp_path / "tiago2" / "delivery_b.yaml").write_text("mine\n")
    with pytest.raises(GenerationError, match="would overwrite"):
        generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path)
    assert _files_below(tmp_path) == {"tiago2/delivery_b.yaml": "mine\n"}

    generate_dispatcher_config(load_spec(SCENARIO_C), None, tmp_path, overwrite=True)
    assert (
        yaml.safe_load((tmp_path / "tiago2" / "delivery_b.yaml").read_text())["task"][0]["waypoints"][0]["id"]
        == "classroom_c022-w002"
    )


def _one_waypoint_scenario(waypoint_id: str, x: float) -> Scenario:
    scenario = _scenario_c()
    task = Task("delivery_a", (Subtask((Pose(waypoint_id, Position(x, 1.5), Orientation(yaw=-0.5)),)),))
    tasks = tuple(task if t.id == "delivery_a" else t for t in scenario.tasks)
    return dataclasses.replace(scenario, tasks=tasks)


@pytest.mark.parametrize(
    "waypoint_id", ["yes", "null", "a: b # c", "- x", "'q'", '"dq"', "two\nlines", "~", "1e3"]
)
def test_ids_are_quoted_so_they_read_back_as_written(waypoint_id: str) -> None:
    files = dispatcher_files(_one_waypoint_scenario(waypoint_id, 2.5), "made.exsce")
    waypoint = yaml.safe_load(files["tiago1/delivery_a.yaml"])["task"][0]["waypoints"][0]
    assert waypoint == {"id": waypoint_id, "x": 2.5, "y": 1.5, "z": 0.0, "yaw": -0.5}


def test_a_small_number_is_written_so_that_yaml_1_1_reads_a_number(tmp_path: Path) -> None:
    """Python writes 1e-05 without a '.', which YAML 1.1 readers (PyYAML, rosparam) take for text."""
    spec = _spec_of(_one_waypoint_scenario("w", 1e-05))
    generate_dispatcher_config(spec, None, tmp_path)
    text = (tmp_path / "tiago1" / "delivery_a.yaml").read_text()
    assert "x: 1.0e-05" in text
    assert yaml.safe_load(text)["task"][0]["waypoints"][0]["x"] == 1e-05


@settings(max_examples=80, deadline=None)
@given(
    waypoint_id=st.text(min_size=1, max_size=12),
    x=st.floats(allow_nan=False, allow_infinity=False),
)
def test_a_file_is_either_read_back_as_the_model_or_refused(waypoint_id: str, x: float) -> None:
    try:
        files = dispatcher_files(_one_waypoint_scenario(waypoint_id, x), "made.exsce")
    except GenerationError:
        return
    waypoint = yaml.safe_load(files["tiago1/delivery_a.yaml"])["task"][0]["waypoints"][0]
    assert waypoint["id"] == waypoint_id
    assert waypoint["x"] == x and math.copysign(1.0, waypoint["x"]) == math.copysign(1.0, x)


def test_a_robot_at_the_root_has_its_task_files_in_a_folder_named_after_it(tmp_path: Path) -> None:
    """namespace "": its topics are /waypoint_dispatcher/...; its files go in tiago1/."""
    scenario = _scenario_c()
    robots = (dataclasses.replace(scenario.robots[0], namespace=""), *scenario.robots[1:])
    generate_dispatcher_config(_spec_of(dataclasses.replace(scenario, robots=robots)), None, tmp_path / "out")
    mission = yaml.safe_load((tmp_path / "out" / "mission.yaml").read_text())
    root = next(r for r in mission["robots"] if r["robot_id"] == "tiago1")
    assert root["robot_namespace"] == ""
    assert root["task_files"] == ["tiago1/delivery_a.yaml", "tiago1/navigate_home_1.yaml"]
    assert (tmp_path / "out" / "tiago1" / "delivery_a.yaml").is_file()
