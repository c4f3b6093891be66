"""Import and export of the method's YAML scenario and task files.

Round trips compare the *parsed* YAML of the method's files with what exsce writes,
after one normalisation: in a pose (a mapping with id, x and y) an absent z, roll or
pitch means 0.0. Comments are not data, and key order is compared separately.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExportError, ImportFormatError
from exsce_dsl.lang import (
    export_yaml,
    import_scenario_yaml,
    import_task_yaml,
    scenario_to_yaml,
    task_to_yaml,
)
from exsce_dsl.model import (
    Area,
    Assignment,
    Document,
    Environment,
    MapModel,
    MissionType,
    Orientation,
    Pose,
    Position,
    RobotType,
    RosResource,
    Scenario,
    Subtask,
    Task,
    WorldModel,
)

MODELS = Path(__file__).parents[2] / "fixtures" / "hbrs-sesame-models"
SCENARIOS = MODELS / "scenarios"
TASKS = MODELS / "tasks" / "brsu_building_c_with_doors"

C025_W001 = Position(44.80387496948242, 37.15502166748047, 0.0)
C025_W002 = Position(43.432926177978516, 38.493873596191406, 0.0)
C022_W001 = Position(52.82560729980469, 32.562904357910156, 0.0)
C022_W002 = Position(54.497589111328125, 31.52023696899414, 0.0)
C018_W001 = Position(48.26420974731445, 24.618297576904297, 0.0)
C018_W002 = Position(46.25560760498047, 21.586545944213867, 0.0)


def import_fixture(name: str) -> tuple[Document, ...]:
    return import_scenario_yaml(SCENARIOS / f"{name}.yaml", [MODELS])


def scenario_of(documents: tuple[Document, ...]) -> Scenario:
    (scenario,) = documents[0].declarations
    assert isinstance(scenario, Scenario)
    return scenario


def normalise(data: Any) -> Any:
    """Absent z, roll and pitch of a pose are 0.0; everything else as parsed."""
    if isinstance(data, dict):
        out = {k: normalise(v) for k, v in data.items()}
        if {"id", "x", "y"} <= out.keys():
            for key in ("z", "roll", "pitch"):
                out.setdefault(key, 0.0)
        return out
    if isinstance(data, list):
        return [normalise(v) for v in data]
    return data


def load(path: Path) -> Any:
    return yaml.safe_load(path.read_text(encoding="utf-8"))


# -- import: what scenario_c becomes, written out by hand -----------------------------


def test_scenario_c_documents_and_imports() -> None:
    documents = import_fixture("scenario_c")

    assert [d.path for d in documents] == [
        "scenario_c.exsce",
        "robots/tiago.exsce",
        "environments/brsu_building_c_with_doors.exsce",
        "tasks/delivery_a.exsce",
        "tasks/delivery_b.exsce",
        "tasks/navigate_home_1.exsce",
        "tasks/navigate_home_2.exsce",
    ]
    assert [i.path for i in documents[0].imports] == [
        "robots/tiago.exsce",
        "environments/brsu_building_c_with_doors.exsce",
        "tasks/delivery_a.exsce",
        "tasks/delivery_b.exsce",
        "tasks/navigate_home_1.exsce",
        "tasks/navigate_home_2.exsce",
    ]
    assert documents[1].declarations == (RobotType("tiago", base="pmb2", torso=True),)
    scenario = scenario_of(documents)
    assert documents[2].declarations == (scenario.environment,)
    assert [d.declarations for d in documents[3:]] == [(t,) for t in scenario.tasks]


def test_scenario_c_robots_and_mission() -> None:
    scenario = scenario_of(import_fixture("scenario_c"))
    tiago = RobotType("tiago", "pmb2", True)

    assert scenario.id == "scenario_c"
    assert [(r.id, r.type, r.namespace) for r in scenario.robots] == [
        ("tiago1", tiago, "tiago1"),
        ("tiago2", tiago, "tiago2"),
    ]
    assert [r.start_pose for r in scenario.robots] == [
        Pose("classroom_c025-w001", C025_W001, Orientation(), "classroom_c025"),
        Pose("classroom_c025-w002", C025_W002, Orientation(), "classroom_c025"),
    ]
    assert scenario.mission.id == "mission_c"
    assert scenario.mission.type is MissionType.PARALLEL
    assert scenario.mission.allocation == (
        Assignment("tiago1", "delivery_a"),
        Assignment("tiago2", "delivery_b"),
        Assignment("tiago1", "navigate_home_1"),
        Assignment("tiago2", "navigate_home_2"),
    )


def test_scenario_c_environment() -> None:
    environment = scenario_of(import_fixture("scenario_c")).environment
    c022 = Orientation(yaw=2.269)
    c018 = Orientation(yaw=-0.641)

    assert environment == Environment(
        "brsu_building_c_with_doors",
        map=MapModel("brsu_building_c_with_doors", RosResource("floorplan-DSL-environments", "maps/")),
        world=WorldModel("brsu_building_c_with_doors", RosResource("floorplan-DSL-environments", "worlds/")),
        areas=(
            # start poses first (as the scenario gives them: yaw 0), then task waypoints
            Area(
                "classroom_c025",
                (
                    Pose("classroom_c025-w001", C025_W001, Orientation(), "classroom_c025"),
                    Pose("classroom_c025-w002", C025_W002, Orientation(), "classroom_c025"),
                ),
            ),
            Area(
                "classroom_c022",
                (
                    Pose("classroom_c022-w001", C022_W001, c022, "classroom_c022"),
                    Pose("classroom_c022-w002", C022_W002, c022, "classroom_c022"),
                ),
            ),
            Area(
                "classroom_c018",
                (
                    Pose("classroom_c018-w001", C018_W001, c018, "classroom_c018"),
                    Pose("classroom_c018-w002", C018_W002, c018, "classroom_c018"),
                ),
            ),
        ),
    )


def test_scenario_c_tasks_carry_their_own_headings() -> None:
    scenario = scenario_of(import_fixture("scenario_c"))

    assert [t.id for t in scenario.tasks] == [
        "delivery_a",
        "delivery_b",
        "navigate_home_1",
        "navigate_home_2",
    ]
    assert scenario.tasks[0] == Task(
        "delivery_a",
        (
            Subtask(
                (
                    Pose("classroom_c022-w001", C022_W001, Orientation(yaw=2.269), "classroom_c022"),
                    Pose("classroom_c018-w001", C018_W001, Orientation(yaw=-0.641), "classroom_c018"),
                )
            ),
        ),
        source=RosResource("metamorphic_testing", "config/tasks/delivery_a.yaml"),
    )
    # navigate_home_1 has no z, and faces another way than the start pose it revisits
    (home,) = scenario.tasks[2].waypoints()
    assert home == Pose("classroom_c025-w001", C025_W001, Orientation(yaw=0.925), "classroom_c025")


def test_scenario_d_and_e() -> None:
    d = scenario_of(import_fixture("scenario_d"))
    assert d.mission.type is MissionType.SEQUENTIAL
    assert [r.id for r in d.robots] == ["tiago1"]
    assert d.mission.tasks_of("tiago1") == ("delivery_a", "delivery_b", "navigate_home_1")

    e = scenario_of(import_fixture("scenario_e"))
    delivery_d = e.task("delivery_d")
    assert delivery_d is not None
    assert [[w.id for w in s.waypoints] for s in delivery_d.subtasks] == [
        ["classroom_c022-w001", "classroom_c018-w001"],
        ["classroom_c022-w002", "classroom_c018-w002"],
    ]
    assert [a.id for a in e.environment.areas] == [
        "classroom_c025",
        "classroom_c022",
        "classroom_c018",
    ]


def test_import_task_yaml_names_the_task_after_its_file() -> None:
    task = import_task_yaml(TASKS / "navigate_home_2.yaml")
    assert task == Task(
        "navigate_home_2",
        (Subtask((Pose("classroom_c025-w002", C025_W002, Orientation(yaw=0.925), "classroom_c025"),)),),
    )
    assert import_task_yaml(TASKS / "navigate_home_2.yaml", "home").id == "home"


# -- round trips -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "task_files"),
    [
        ("scenario_c", ["delivery_a", "delivery_b", "navigate_home_1", "navigate_home_2"]),
        ("scenario_d", ["delivery_a", "delivery_b", "navigate_home_1"]),
        ("scenario_e", ["delivery_c", "delivery_d", "navigate_home_1"]),
    ],
)
def test_import_then_export_gives_back_the_method_files(
    name: str, task_files: list[str], tmp_path: Path
) -> None:
    documents = import_fixture(name)
    written = export_yaml(scenario_of(documents), tmp_path)

    # tasks go where the scenario file says they are: config/tasks/ of the package
    assert written == [
        tmp_path / "scenarios" / f"{name}.yaml",
        *(tmp_path / "config" / "tasks" / f"{t}.yaml" for t in task_files),
    ]
    original = load(SCENARIOS / f"{name}.yaml")
    exported = load(written[0])
    assert normalise(exported) == normalise(original)
    assert list(exported) == ["id", "mission", "environment", "robots"]
    for task_name, path in zip(task_files, written[1:], strict=True):
        assert normalise(load(path)) == normalise(load(TASKS / f"{task_name}.yaml"))

    # and what was written imports to the same model
    again = import_scenario_yaml(written[0], [tmp_path])
    assert again == documents


def test_task_to_yaml_shape() -> None:
    task = import_task_yaml(TASKS / "navigate_home_1.yaml")
    assert task_to_yaml(task) == {
        "task": [
            {
                "waypoints": [
                    {
                        "id": "classroom_c025-w001",
                        "x": 44.80387496948242,
                        "y": 37.15502166748047,
                        "z": 0.0,
                        "yaw": 0.925,
                    }
                ]
            }
        ]
    }


def test_task_without_source_is_exported_under_tasks(tmp_path: Path) -> None:
    scenario = scenario_of(import_fixture("scenario_d"))
    bare = tuple(Task(t.id, t.subtasks) for t in scenario.tasks)
    scenario = Scenario(scenario.id, scenario.environment, scenario.robots, scenario.mission, bare)
    assert scenario_to_yaml(scenario)["mission"]["allocation"][0] == {
        "robot": "tiago1",
        "pkg": "exsce",
        "file_path": "tasks/delivery_a.yaml",
    }
    written = export_yaml(scenario, tmp_path)
    assert written[1] == tmp_path / "tasks" / "delivery_a.yaml"


def test_goal_timeouts_are_exported_under_exsce_s_own_key_and_imported_back(tmp_path: Path) -> None:
    from dataclasses import replace

    scenario = scenario_of(import_fixture("scenario_d"))
    timed = tuple(replace(t, timeout=120.0) if t.id == "delivery_b" else t for t in scenario.tasks)
    scenario = replace(scenario, tasks=timed, mission=replace(scenario.mission, timeout=90.0))
    written = export_yaml(scenario, tmp_path)
    mission = load(written[0])["mission"]
    assert list(mission) == ["id", "type", "allocation", "goal_timeout"] and mission["goal_timeout"] == 90.0
    files = {path.stem: load(path) for path in written[1:]}
    assert files["delivery_b"]["goal_timeout"] == 120.0 and list(files["delivery_b"]) == [
        "task",
        "goal_timeout",
    ]
    assert "goal_timeout" not in files["delivery_a"]
    again = scenario_of(import_scenario_yaml(written[0], [tmp_path]))
    assert again.mission.timeout == 90.0
    assert {t.id: t.timeout for t in again.tasks} == {
        "delivery_a": None,
        "delivery_b": 120.0,
        "navigate_home_1": None,
    }


@pytest.mark.parametrize(
    ("value", "expected"),
    [
        ("-5", "is a goal timeout in seconds: it must be above 0, not -5"),
        ("soon", "goal_timeout should be a number, not str 'soon'"),
    ],
)
def test_a_goal_timeout_that_is_not_a_positive_number_is_an_import_error(
    value: str, expected: str, tmp_path: Path
) -> None:
    task = write(tmp_path / "t.yaml", SMALL_TASK.format(pose="lab-p1", x=1.0) + f"goal_timeout: {value}\n")
    with pytest.raises(ImportFormatError, match=expected) as caught:
        import_task_yaml(task)
    assert f"{task}:" in str(caught.value) and "goal_timeout" in str(caught.value)


# -- task file search ---------------------------------------------------------------------

SMALL_SCENARIO = """\
id: small
mission:
  id: small_mission
  type: parallel
  allocation:
    - robot: r1
      pkg: pkg
      file_path: config/tasks/t.yaml
environment:
  id: lab
  robots:
    r1:
      start_pose:
        id: lab-p1
        x: 1.0
        y: 2.0
robots:
  - robot_id: r1
    robot_namespace: r1
    robot_type: rover
"""

SMALL_TASK = """\
task:
  - waypoints:
    - id: {pose}
      x: {x}
      y: 2.0
      yaw: 0.5
"""


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_task_file_search_order(tmp_path: Path) -> None:
    scenario = write(tmp_path / "scenarios" / "small.yaml", SMALL_SCENARIO)
    write(tmp_path / "a" / "t.yaml", SMALL_TASK.format(pose="lab-by_name_a", x=1.0))
    write(tmp_path / "b" / "t.yaml", SMALL_TASK.format(pose="lab-by_name_b", x=1.0))

    def first_waypoint() -> str:
        task = scenario_of(import_scenario_yaml(scenario, [tmp_path])).tasks[0]
        return next(task.waypoints()).id

    assert first_waypoint() == "lab-by_name_a"  # by name, sorted: a/ before b/
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-path", x=1.0))
    assert first_waypoint() == "lab-path"
    write(tmp_path / "pkg" / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-pkg", x=1))
    assert first_waypoint() == "lab-pkg"


def test_unknown_robot_type_has_no_facts_and_pose_without_dash_is_unassigned(
    tmp_path: Path,
) -> None:
    scenario = write(tmp_path / "small.yaml", SMALL_SCENARIO)
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="hall", x=1.0))
    documents = import_scenario_yaml(scenario)
    assert documents[1].declarations == (RobotType("rover"),)
    environment = scenario_of(documents).environment
    assert [(a.id, [p.id for p in a.poses]) for a in environment.areas] == [
        ("lab", ["lab-p1"]),
        ("unassigned", ["hall"]),
    ]
    assert environment.map is None and environment.world is None


# -- errors -------------------------------------------------------------------------------


def test_missing_task_file_names_the_file_and_the_search_path() -> None:
    with pytest.raises(ImportFormatError) as caught:
        import_fixture("scenario_a")
    error = caught.value
    assert "tasks/brsu_building_c_with_doors/right_long_corridor_task.yaml" in error.message
    assert "floorplan-dsl-environments" in error.message
    assert str(SCENARIOS) in error.message and str(MODELS) in error.message
    assert error.location is not None
    assert (error.location.file, error.location.line, error.location.column) == (
        str(SCENARIOS / "scenario_a.yaml"),
        9,
        18,
    )


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ("robot_id: r1", "robot_id: r 1", "robot id 'r 1' (robots[0].robot_id)"),
        ("id: small\n", "id: scenario\n", "scenario id 'scenario' (id)"),
        ("robot_type: rover", "robot_type: 9rover", "robot type id '9rover'"),
        ("id: lab\n", "id: lab.c\n", "environment id 'lab.c' (environment.id)"),
        ("id: lab-p1", "id: lab-p1-", "pose id 'lab-p1-'"),
        ("id: lab-p1", "id: pose-p1", "area id 'pose'"),
        ("config/tasks/t.yaml", "config/tasks/t.v2.yaml", "task id 't.v2'"),
    ],
)
def test_invalid_id_says_which_id_in_which_file(old: str, new: str, expected: str, tmp_path: Path) -> None:
    scenario = write(tmp_path / "small.yaml", SMALL_SCENARIO.replace(old, new))
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-p2", x=1.0))
    with pytest.raises(ImportFormatError, match="is not a valid exsce id") as caught:
        import_scenario_yaml(scenario)
    assert expected in caught.value.message
    assert caught.value.location is not None
    assert caught.value.location.file == str(scenario)


def test_invalid_id_location_and_reason(tmp_path: Path) -> None:
    text = SMALL_SCENARIO.replace("robot_type: rover", "robot_type: robot")
    scenario = write(tmp_path / "small.yaml", text)
    with pytest.raises(ImportFormatError) as caught:
        import_scenario_yaml(scenario)
    assert "'robot' is a word of the exsce language" in caught.value.message
    assert str(caught.value).startswith(f"{scenario}:20:17: error: robot type id 'robot'")


def test_conflicting_coordinates_name_both_files(tmp_path: Path) -> None:
    scenario = write(tmp_path / "small.yaml", SMALL_SCENARIO)
    task = write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-p1", x=1.5))
    with pytest.raises(ImportFormatError) as caught:
        import_scenario_yaml(scenario)
    error = caught.value
    assert "pose 'lab-p1' is at (1.5, 2.0, 0.0) here but at (1.0, 2.0, 0.0)" in error.message
    assert f"{scenario}:14:" in error.message
    assert error.location is not None
    assert (error.location.file, error.location.line) == (str(task), 3)


def test_same_pose_with_another_heading_is_no_conflict(tmp_path: Path) -> None:
    scenario = write(tmp_path / "small.yaml", SMALL_SCENARIO)
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-p1", x=1.0))
    environment = scenario_of(import_scenario_yaml(scenario)).environment
    (pose,) = environment.poses()
    assert pose.orientation == Orientation()  # the start pose came first


def test_missing_key_names_the_key_and_where(tmp_path: Path) -> None:
    scenario = write(tmp_path / "small.yaml", SMALL_SCENARIO.replace("    robot_namespace: r1\n", ""))
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-p1", x=1.0))
    with pytest.raises(ImportFormatError) as caught:
        import_scenario_yaml(scenario)
    assert str(caught.value) == (f"{scenario}:18:5: error: missing key 'robot_namespace' in robots[0]")


def test_missing_key_in_a_task_file(tmp_path: Path) -> None:
    task = write(tmp_path / "t.yaml", "task:\n  - waypoints:\n    - id: a-1\n      x: 1.0\n")
    with pytest.raises(ImportFormatError) as caught:
        import_task_yaml(task)
    assert str(caught.value) == f"{task}:3:7: error: missing key 'y' in task[0].waypoints[0]"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("task: [1, 2]\n", "task[0] should be a mapping"),
        (
            "task:\n  - waypoints: [{id: a-1, x: one, y: 2}]\n",
            "task[0].waypoints[0].x should be a number",
        ),
        ("!!python/object/apply:os.system [ls]\n", "not valid YAML"),
        ("task: [\n", "not valid YAML"),
        ("", "should be a mapping"),
    ],
)
def test_malformed_task_files(text: str, expected: str, tmp_path: Path) -> None:
    task = write(tmp_path / "t.yaml", textwrap.dedent(text))
    with pytest.raises(ImportFormatError, match=re.escape(expected)):
        import_task_yaml(task)


def test_unknown_mission_type_and_robot(tmp_path: Path) -> None:
    write(tmp_path / "config" / "tasks" / "t.yaml", SMALL_TASK.format(pose="lab-p2", x=1.0))
    scenario = write(tmp_path / "a.yaml", SMALL_SCENARIO.replace("parallel", "round_robin"))
    with pytest.raises(ImportFormatError, match="'round_robin' is not parallel or sequential"):
        import_scenario_yaml(scenario)
    scenario = write(tmp_path / "b.yaml", SMALL_SCENARIO.replace("- robot: r1", "- robot: r2"))
    with pytest.raises(ImportFormatError, match="robot 'r2', which is not in the robots list"):
        import_scenario_yaml(scenario)


# -- export errors ------------------------------------------------------------------------


def test_waypoint_with_roll_cannot_be_exported() -> None:
    tilted = Pose("lab-p1", Position(1.0, 2.0), Orientation(roll=0.1, yaw=0.5), "lab")
    with pytest.raises(ExportError, match="waypoint 'lab-p1' has roll 0.1"):
        task_to_yaml(Task("t", (Subtask((tilted,)),)))


@pytest.mark.parametrize("path", ["../outside.yaml", "/etc/t.yaml", "a/../../t.yaml", ""])
def test_task_source_path_must_stay_inside_the_export_folder(path: str, tmp_path: Path) -> None:
    scenario = scenario_of(import_fixture("scenario_d"))
    first = scenario.tasks[0]
    moved = Task(first.id, first.subtasks, RosResource("pkg", path))
    scenario = Scenario(
        scenario.id,
        scenario.environment,
        scenario.robots,
        scenario.mission,
        (moved, *scenario.tasks[1:]),
    )
    with pytest.raises(ExportError, match="relative path without '..'"):
        export_yaml(scenario, tmp_path / "out")
    assert not (tmp_path / "out").exists()  # nothing written


# -- property: a task written in the method's format reads back the same ---------------

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
planar_waypoints = st.builds(
    lambda area, suffix, x, y, z, yaw: Pose(
        f"{area}-{suffix}", Position(x, y, z), Orientation(yaw=yaw), area
    ),
    st.sampled_from(["classroom_c025", "lab", "_hall"]),
    st.from_regex(r"[A-Za-z0-9_]{1,8}", fullmatch=True),
    finite,
    finite,
    finite,
    finite,
)
tasks = st.builds(
    lambda subtasks, timeout: Task("t", tuple(Subtask(tuple(s)) for s in subtasks), timeout=timeout),
    st.lists(st.lists(planar_waypoints, min_size=1, max_size=4), min_size=1, max_size=3),
    st.none() | st.floats(1e-3, 1e7, allow_nan=False),
)


@settings(max_examples=25, deadline=None)
@given(task=tasks)
def test_task_yaml_round_trip(task: Task, tmp_path_factory: pytest.TempPathFactory) -> None:
    path = tmp_path_factory.mktemp("task") / "t.yaml"
    path.write_text(yaml.safe_dump(task_to_yaml(task), sort_keys=False), encoding="utf-8")
    assert import_task_yaml(path) == task


def test_imported_documents_format_and_load_back_to_the_same_scenario(tmp_path: Path) -> None:
    """The documents are meant to be written as ``.exsce`` files: doing so loses nothing."""
    from exsce_dsl.lang import declared_poses, format_document, load_spec

    documents = import_fixture("scenario_c")
    scenario = scenario_of(documents)
    poses = declared_poses([scenario.environment])
    for document in documents:
        target = tmp_path / document.path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(format_document(document, poses), encoding="utf-8")
    assert load_spec(tmp_path / "scenario_c.exsce").scenario() == scenario


def test_area_is_the_pose_id_up_to_its_first_dash(tmp_path: Path) -> None:
    """The method's corridor poses are `right_long_corridor-point-0`: area `right_long_corridor`."""
    task_file = tmp_path / "corridor.yaml"
    task_file.write_text(
        "task:\n  - waypoints:\n"
        "    - {id: right_long_corridor-point-0, x: 51.12, y: 39.44, yaw: 0.0}\n"
        "    - {id: classroom_c025-w001, x: 1.0, y: 2.0}\n"
    )
    task = import_task_yaml(task_file)
    assert [w.area for w in task.waypoints()] == ["right_long_corridor", "classroom_c025"]


def test_imported_task_files_check_on_their_own(tmp_path: Path) -> None:
    from exsce_dsl.lang import analyse, write_documents

    documents = import_fixture("scenario_c")
    written = write_documents(documents, tmp_path)
    for path in written:
        analysis = analyse(path)
        assert analysis.errors == [], (path, analysis.errors)
