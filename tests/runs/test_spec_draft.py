"""A specification drafted from a bag (``exscec init --from-bag``, issue 33 item 2) checks and
ingests as written, and says what the bag says, as rosbags reads it (tests/support/draft_references.py).

On the executor's runs of the yard in every convention and format, one restamped onto simulated
time, and on bags of real shapes written here: a robot at the root without goals, one in a
namespace on simulated stamps, TF only, a bag with an OccupancyGrid, and namespaces that are no
valid ids.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import BagError, ExportError
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.grid import FREE, OCCUPIED, UNKNOWN, load_occupancy_grid
from exsce_dsl.model import Specification
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.spec_draft import default_spec_path, draft_spec
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import ODOMETRY, START_NS, Topic, header, quaternion, typestore_for, write_bag
from tests.support.clock_bags import restamp
from tests.support.draft_references import reference, whole_path
from tests.support.real_shapes import ROUTE, SHAPES, pose_topic
from tests.support.yard_spec import yard_text

YARD_GOALS = {"root_robot": [(5.0, 0.0), (5.0, 4.0)], "r2": [(5.0, 8.0)]}
"""Where the yard's tasks send its robots (r1 at the root, r2 in /r2): yard-b, yard-c; yard-e."""


def _yard_bag(folder: Path, convention: str, fmt: str) -> Path:
    spec = folder / "yard.exsce"
    spec.write_text(yard_text("torso no" if convention == "method" else f"convention {convention}"))
    (run,) = simulate(load_spec(spec).scenario(), folder / "bags", fmt=fmt, seed=5, convention=convention)
    return run.bag


def _robot_level(analysed: AnalysedRun) -> dict[tuple[str, str | None], float]:
    return {(v.metric, v.robot): v.value for v in analysed.run.metrics if v.action is None}


def _places(spec: Specification, robot: str) -> list[float]:
    """The positions of a robot's area, its start left out: x, y, x, y..."""
    (env,) = spec.environments
    area = next(a for a in env.areas if a.id == f"{spec.scenario().id}_{robot}_places")
    return [v for p in area.poses if not p.id.endswith("-start") for v in (p.position.x, p.position.y)]


def _flat(points: list[tuple[float, float]] | list[tuple[float, ...]]) -> list[float]:
    return [float(v) for point in points for v in point[:2]]


def _drafted(bag: Path, folder: Path) -> tuple[Specification, AnalysedRun]:
    draft = draft_spec(bag, folder / "draft.exsce")
    spec = load_spec(draft.spec)  # raises on any error the checks find
    return spec, analyse_bag(bag, spec.scenario())


@pytest.mark.parametrize(
    ("convention", "fmt"),
    [(c, f) for c in ("method", "nav2", "move_base") for f in ("ros1", "ros2", "mcap")],
)
def test_a_draft_of_an_executors_bag_checks_and_its_run_has_the_bags_values(
    tmp_path: Path, convention: str, fmt: str
) -> None:
    bag = _yard_bag(tmp_path, convention, fmt)
    spec, analysed = _drafted(bag, tmp_path)
    assert analysed.problems == []
    text = (tmp_path / "draft.exsce").read_text()
    assert f"convention {convention}" in text and 'root_robot: method_robot namespace ""' in text.replace(
        f"{convention}_robot", "method_robot"
    )
    values = _robot_level(analysed)
    for robot, ns in (("root_robot", ""), ("r2", "r2")):
        expected = reference(bag, ns, convention)
        assert _places(spec, robot) == pytest.approx(_flat(expected.targets), abs=1e-4)
        if convention != "method":  # a stack's goals carry their targets: the yard's poses
            assert _places(spec, robot) == pytest.approx(_flat(YARD_GOALS[robot]), abs=1e-4)
        assert values[("distance_travelled", robot)] == pytest.approx(expected.distance, rel=1e-9)
        assert values[("task_duration", robot)] == pytest.approx(expected.duration, abs=0.05)
    mission = spec.scenario().mission
    assert [a.task for a in mission.allocation if a.robot == "r2"] == [f"{spec.scenario().id}_r2_goal_1"]
    assert mission.type.value == "parallel"


def test_a_draft_of_a_bag_on_simulated_time_meets_its_goals(tmp_path: Path) -> None:
    bag = restamp(_yard_bag(tmp_path, "nav2", "mcap"), tmp_path / "simulated", "mcap", clock_hz=50.0)
    spec, analysed = _drafted(bag, tmp_path)
    assert analysed.timeline is not None and analysed.timeline.simulated
    values = _robot_level(analysed)
    for robot, ns in (("root_robot", ""), ("r2", "r2")):
        expected = reference(bag, ns, "nav2")  # log times: the restamped clock runs at rate 1
        assert _places(spec, robot) == pytest.approx(_flat(YARD_GOALS[robot]), abs=1e-4)
        assert values[("distance_travelled", robot)] == pytest.approx(expected.distance, rel=1e-9)
        assert values[("task_duration", robot)] == pytest.approx(expected.duration, abs=0.05)


@pytest.mark.parametrize(
    ("shape", "fmt", "robot", "pose", "signals"),
    [
        ("jackal", "ros1", "root_robot", "/jackal_velocity_controller/odom", ["/cmd_vel"]),
        ("namespaced", "sqlite3", "scout", "/scout/pose", []),
        ("tf_only", "mcap", "root_robot", None, []),
    ],
)
def test_a_draft_of_a_bag_without_goals_spans_each_robots_whole_path(
    tmp_path: Path, shape: str, fmt: str, robot: str, pose: str | None, signals: list[str]
) -> None:
    store = typestore_for(fmt)
    bag = tmp_path / f"{shape}.bag" if fmt == "ros1" else tmp_path / shape
    write_bag(bag, fmt, SHAPES[shape](store), store)
    spec, analysed = _drafted(bag, tmp_path)
    text = (tmp_path / "draft.exsce").read_text()
    assert "window whole recording" in text and "convention" not in text.split("robot type")[1].split("}")[0]
    values = _robot_level(analysed)
    if pose is None:  # TF only: the route itself (map -> odom -> base_link composes it)
        start, far, end = ROUTE.corners[0], ROUTE.corners[2], ROUTE.corners[2]
        assert _places(spec, robot) == pytest.approx(_flat([end]), abs=1e-3)  # farthest is the end
        assert values[("distance_travelled", robot)] == pytest.approx(14.0, abs=0.05)
        assert start == (0.0, 0.0, 0.0) and far == end
        return
    expected = whole_path(bag, pose, [pose, *signals])
    places = (
        expected.targets[1:]
        if np.hypot(*np.subtract(expected.targets[1], expected.targets[2])) > 0.7
        else [expected.targets[2]]
    )
    assert _places(spec, robot) == pytest.approx(_flat(places), abs=1e-4)
    assert values[("distance_travelled", robot)] == pytest.approx(expected.distance, rel=1e-9)
    assert values[("task_duration", robot)] == pytest.approx(expected.duration, abs=0.05)
    assert ('namespace ""' in text) == (robot == "root_robot")


def _grid_message(store: object, fill: int = 0) -> object:
    """400 x 300 cells of 5 cm from (-5, -5): free, an occupied border, an unknown block at
    x 10..12, y 5..8 (away from the route), as a SLAM node publishes it."""
    t = store.types  # type: ignore[attr-defined]
    data = np.full((300, 400), fill, dtype=np.int8)
    data[0, :] = data[-1, :] = data[:, 0] = data[:, -1] = 100
    data[200:260, 300:340] = -1  # rows from the origin's row: y = -5 + row * 0.05
    info = t["nav_msgs/msg/MapMetaData"](
        map_load_time=header(store, 0, "map").stamp,
        resolution=0.05,
        width=400,
        height=300,
        origin=t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=-5.0, y=-5.0, z=0.0), orientation=quaternion(store, 0.0)
        ),
    )
    return t["nav_msgs/msg/OccupancyGrid"](header=header(store, 0, "map"), info=info, data=data.ravel())


def test_a_bags_occupancy_grid_is_written_as_the_map_the_draft_checks_against(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    odom = pose_topic(store, "/odom", ODOMETRY, ROUTE, 20.0, frame="map")
    grid = Topic("/map", "nav_msgs/msg/OccupancyGrid", [(odom.messages[0][0], _grid_message(store))])
    bag = tmp_path / "mapped.bag"
    write_bag(bag, "ros1", [odom, grid], store)
    spec, analysed = _drafted(bag, tmp_path)
    assert [p for p in analysed.problems if "no scan" not in p] == []  # it has none
    (env,) = spec.environments
    assert env.map is not None and Path(env.map.file or "") == tmp_path / "draft_map.yaml"
    with AnyReader([bag]) as reader:
        (connection,) = [c for c in reader.connections if c.topic == "/map"]
        ((_, _, raw),) = list(reader.messages([connection]))
        recorded = reader.deserialize(raw, connection.msgtype)
    written = load_occupancy_grid(tmp_path / "draft_map.yaml")
    assert (written.width, written.height) == (recorded.info.width, recorded.info.height)
    assert written.resolution == pytest.approx(recorded.info.resolution)
    assert written.origin == pytest.approx((-5.0, -5.0, 0.0))
    assert written.state_at(0.0, 0.0) == FREE and written.state_at(8.0, 6.0) == FREE
    assert written.state_at(-4.99, 2.0) == OCCUPIED and written.state_at(14.99, 9.99) == OCCUPIED
    assert written.state_at(11.0, 6.5) == UNKNOWN and written.state_at(9.9, 6.5) == FREE


def test_namespaces_that_are_keywords_become_ids_and_invalid_ones_are_said(tmp_path: Path) -> None:
    store = typestore_for("mcap")
    topics = [
        pose_topic(store, f"/{ns}/odom", ODOMETRY, ROUTE, 20.0, frame="odom")
        for ns in ("robot", "type", "2nd-bot")
    ]
    bag = tmp_path / "odd names!"
    write_bag(bag, "mcap", topics, store)
    assert default_spec_path(bag, tmp_path) == tmp_path / "odd_names_.exsce"
    draft = draft_spec(bag, tmp_path / "draft.exsce")
    assert draft.notes == ("namespace '2nd-bot' is not a valid ROS name: its robot is left out",)
    spec = load_spec(draft.spec)
    assert {r.id: r.namespace for r in spec.scenario().robots} == {"robot_": "robot", "type_": "type"}
    values = _robot_level(analyse_bag(bag, spec.scenario()))
    expected = whole_path(bag, "/robot/odom", ["/robot/odom"]).distance
    assert values[("distance_travelled", "robot_")] == pytest.approx(expected, rel=1e-9)
    assert values[("distance_travelled", "type_")] == pytest.approx(expected, rel=1e-9)


def test_a_draft_never_overwrites_unless_forced(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    bag = tmp_path / "jackal.bag"
    write_bag(bag, "ros1", SHAPES["jackal"](store), store)
    target = tmp_path / "mine.exsce"
    target.write_text("// the user's own\n")
    with pytest.raises(ExportError, match="would overwrite .*mine.exsce; ask to replace the files that exist"):
        draft_spec(bag, target)
    assert target.read_text() == "// the user's own\n"
    draft_spec(bag, target, force=True)
    assert "robot type detected_robot" in target.read_text()


def test_a_map_whose_free_space_misses_the_places_is_written_but_not_referenced(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    odom = pose_topic(store, "/odom", ODOMETRY, ROUTE, 20.0, frame="odom")
    grid = Topic("/map", "nav_msgs/msg/OccupancyGrid", [(odom.messages[0][0], _grid_message(store, fill=-1))])
    bag = tmp_path / "elsewhere.bag"
    write_bag(bag, "ros1", [odom, grid], store)
    draft = draft_spec(bag, tmp_path / "draft.exsce")
    assert draft.map_files == (tmp_path / "draft_map.yaml", tmp_path / "draft_map.pgm")
    # its start and its end (the farthest point from its start): both in unknown space
    assert draft.notes == ("draft_map.yaml written but not referenced: 2 places off its free space",)
    (env,) = load_spec(draft.spec).environments  # checks: no pose is held against the map
    assert env.map is None and "draft_map.yaml is not referenced" in draft.text
    assert load_occupancy_grid(tmp_path / "draft_map.yaml").state_at(0.0, 0.0) == UNKNOWN


def test_a_bag_without_a_robot_says_so_and_writes_nothing(tmp_path: Path) -> None:
    store = typestore_for("ros1")
    battery = [(START_NS + i * 10**9, store.types["std_msgs/msg/Float32"](data=24.0 - i)) for i in range(5)]
    bag = tmp_path / "battery.bag"
    write_bag(bag, "ros1", [Topic("/battery", "std_msgs/msg/Float32", battery)], store)
    with pytest.raises(BagError, match=r"battery.bag: no robot found: .*its pose-like topics: none"):
        draft_spec(bag, tmp_path / "draft.exsce")
    assert not (tmp_path / "draft.exsce").exists()


def test_a_bag_whose_robots_have_no_readable_pose_is_refused_not_drafted_empty(tmp_path: Path) -> None:
    """Stumble: init --from-bag on rosbag.js's turtlesim bag (poses as turtlesim/Pose, TF world ->
    turtle1) exited 0 with a specification of no robots, which check then refused ("mission
    allocates no task")."""
    from tests.support.paths import ROOT

    bag = ROOT / "tests" / "fixtures" / "realbags" / "rosbag.js" / "example.bag"
    with pytest.raises(BagError, match=r"example.bag: no robot to draft .*pose-like topics: /tf \("):
        draft_spec(bag, tmp_path / "draft.exsce")
    assert not (tmp_path / "draft.exsce").exists()
