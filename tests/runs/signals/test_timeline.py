"""One timeline per run: bags whose stamps are simulated time (Gazebo, Isaac) beside wall-clock log
time give the values of the same run recorded on one clock, with a specification that names
neither a convention nor a clock (scenario_c as shipped: its robot type says nothing of topics).

The reference bags are the executor's (stamps equal log times, their values checked elsewhere
against rosbags' deserialisation); :func:`tests.support.clock_bags.restamp` moves every stamp of them
onto a simulated clock through rosbags.  Distances and speeds stay as they were; durations scale
by the simulation's rate.  One value is also recomputed here from rosbags alone: each robot's
distance travelled along its odometry between its first goal's start and its last goal's end.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from pyoxigraph import Store
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads, validate
from exsce_dsl.runs.analyse import AnalysedRun, analyse_bag
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.reading import bag_topics, read_bag
from exsce_dsl.runs.signals.timeline import decide_timeline, stamp_catalogue, with_stamps
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import Topic, typestore_for, write_bag
from tests.support.clock_bags import CLOCK, CLOCK_TYPE, restamp

SPEC = Path(__file__).resolve().parents[3] / "examples" / "brsu_building_c" / "scenario_c.exsce"
DURATIONS = {"task_duration", "mission_duration", "violation_duration"}


@dataclass(frozen=True)
class Shape:
    """A recording: which convention and format the executor wrote, and how it is restamped."""

    name: str
    convention: str
    fmt: str
    rate: float = 1.0
    clock_hz: float | None = None

    @property
    def executor_format(self) -> str:
        return {"sqlite3": "ros2"}.get(self.fmt, self.fmt)


SHAPES = [
    Shape("mcap-nav2-no-clock", "nav2", "mcap"),
    Shape("mcap-nav2-clock-half-speed", "nav2", "mcap", rate=0.5, clock_hz=100.0),
    Shape("sqlite3-nav2-clock", "nav2", "sqlite3", clock_hz=50.0),
    Shape("ros1-move_base-no-clock", "move_base", "ros1"),
]


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return load_spec(SPEC).scenario("scenario_c")


@pytest.fixture(scope="module")
def wall_bags(scenario: Scenario, tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], Path]:
    """The executor's bags, one per (convention, format), stamps on the wall clock."""
    folder = tmp_path_factory.mktemp("wall")
    found = {}
    for shape in SHAPES:
        key = (shape.convention, shape.fmt)
        if key not in found:
            executor_format = shape.executor_format
            (run,) = simulate(
                scenario, folder / shape.name, fmt=executor_format, seed=4, convention=shape.convention
            )
            found[key] = run.bag
    return found


@pytest.fixture(scope="module")
def analysed(
    scenario: Scenario, wall_bags: dict[tuple[str, str], Path], tmp_path_factory: pytest.TempPathFactory
) -> dict[str, tuple[AnalysedRun, AnalysedRun]]:
    """Each shape: (the wall bag's run, the restamped bag's run)."""
    folder = tmp_path_factory.mktemp("simulated")
    found = {}
    for shape in SHAPES:
        wall = wall_bags[(shape.convention, shape.fmt)]
        target = folder / (shape.name + (".bag" if shape.fmt == "ros1" else ""))
        restamp(wall, target, shape.fmt, rate=shape.rate, clock_hz=shape.clock_hz)
        found[shape.name] = (analyse_bag(wall, scenario), analyse_bag(target, scenario))
    return found


def _values(run: AnalysedRun) -> dict[tuple[str, str | None, str, str | None], float]:
    return {(v.metric, v.robot, str(v.action), v.safety_metric): v.value for v in run.run.metrics}


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.name)
def test_simulated_stamps_give_the_values_of_the_run_on_one_clock(
    shape: Shape, analysed: dict[str, tuple[AnalysedRun, AnalysedRun]]
) -> None:
    wall, simulated = analysed[shape.name]
    expected, found = _values(wall), _values(simulated)
    assert found.keys() == expected.keys()
    assert len(expected) > 40
    for key, value in expected.items():
        scale = shape.rate if key[0] in DURATIONS else 1.0
        assert found[key] == pytest.approx(value * scale, rel=1e-4, abs=1e-6), key
    assert simulated.timeline is not None and simulated.timeline.simulated
    assert wall.timeline is not None and not wall.timeline.simulated


@pytest.mark.parametrize("shape", SHAPES, ids=lambda s: s.name)
def test_no_robot_drove_zero_metres(
    shape: Shape, analysed: dict[str, tuple[AnalysedRun, AnalysedRun]], wall_bags: dict[tuple[str, str], Path]
) -> None:
    """The distance each robot drove, from rosbags alone: its odometry's path between its first
    goal's start and its last goal's end (the executor's goals, read from the bag's statuses
    through the run's actions, whose times are wall-clock dates in both runs)."""
    wall, simulated = analysed[shape.name]
    bag = wall_bags[(shape.convention, shape.fmt)]
    for robot in ("tiago1", "tiago2"):
        actions = [a for a in simulated.run.actions() if a.id.robot == robot]
        start = min(a.start for a in actions).timestamp()
        end = max(a.end for a in actions).timestamp()
        xy = _odometry(bag, f"/{robot}/odom", start, end)
        reference = float(np.hypot(*np.diff(xy, axis=0).T).sum())
        [value] = [
            v.value
            for v in simulated.run.metrics
            if (v.metric, v.robot, v.action) == ("distance_travelled", robot, None)
        ]
        assert reference > 20.0
        assert value == pytest.approx(reference, rel=1e-3)


def _odometry(bag: Path, topic: str, start: float, end: float) -> np.ndarray:
    found = []
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        for connection, time_ns, raw in reader.messages(connections=connections):
            if start - 1e-6 <= time_ns * 1e-9 <= end + 1e-6:
                position = reader.deserialize(raw, connection.msgtype).pose.pose.position
                found.append((position.x, position.y))
    return np.array(found)


def test_the_run_says_which_clock_each_source_used(
    analysed: dict[str, tuple[AnalysedRun, AnalysedRun]],
) -> None:
    _, with_clock = analysed["mcap-nav2-clock-half-speed"]
    _, without = analysed["mcap-nav2-no-clock"]
    assert with_clock.timeline is not None and without.timeline is not None
    assert with_clock.timeline.by == CLOCK
    assert without.timeline.by.startswith("the offsets of")
    clocks = {c.topic: c for c in with_clock.run.clocks}
    assert (clocks["/tiago1/odom"].clock, clocks["/tiago1/odom"].simulated) == ("header stamps", True)
    assert (clocks["/tiago1/tf"].clock, clocks["/tiago1/tf"].simulated) == ("transform stamps", True)
    assert (clocks["/tiago1/cmd_vel"].clock, clocks["/tiago1/cmd_vel"].simulated) == ("log time", True)
    assert clocks["/tiago1/odom"].offset > 1e9  # wall seconds since 1970 less a quarter hour of simulation


def test_the_convention_is_detected_per_robot_and_said(
    analysed: dict[str, tuple[AnalysedRun, AnalysedRun]],
) -> None:
    _, nav2 = analysed["mcap-nav2-no-clock"]
    _, move_base = analysed["ros1-move_base-no-clock"]
    assert {(r, c) for r, c, _ in nav2.run.conventions} == {("tiago1", "nav2"), ("tiago2", "nav2")}
    assert ("tiago1", "move_base", ("/tiago1/move_base/status",)) in move_base.run.conventions
    assert any(
        "convention nav2 (detected from /tiago1/navigate_to_pose/_action/status)" in d.describe()
        for d in nav2.detected
    )


def test_a_clock_that_goes_back_is_a_jump_of_the_timeline(tmp_path: Path) -> None:
    """A simulation reset while recording: /clock goes from 149 s back to 2 s.  The timeline
    follows /clock up to the jump (1 simulated second per 0.1 s logged) and goes on at that pace,
    so the jump is at 149 + 1 = 150 s on it; the run's coverage says the rest is not on one
    timeline (tests/runs/test_coverage)."""
    store = typestore_for("mcap")
    clock_type, time_type = store.types[CLOCK_TYPE], store.types["builtin_interfaces/msg/Time"]
    start = 1_767_312_000_000_000_000
    ticks = [
        (start + i * 100_000_000, clock_type(clock=time_type(sec=130 + i if i < 20 else i - 18, nanosec=0)))
        for i in range(40)
    ]
    odometry = _odometry_messages(store, start)
    bag = write_bag(tmp_path / "reset", "mcap", [Topic(CLOCK, CLOCK_TYPE, ticks), odometry], store).path
    types = bag_topics(bag)
    wanted = with_stamps({"/tiago1/odom": Wanted(types["/tiago1/odom"], ())}, types, stamp_catalogue())
    timeline = decide_timeline(read_bag(bag, wanted))
    (jump,) = timeline.jumps
    assert (jump.topic, jump.back, jump.at) == (CLOCK, pytest.approx(147.0), pytest.approx(150.0))
    assert timeline.simulated
    assert any("/clock went back 147.000 s" in note for note in timeline.notes)
    later = timeline.from_log(np.array([start * 1e-9 + 3.0]))  # tick 30, after the reset
    assert later[0] == pytest.approx(160.0)  # 150 + 10 × 1.0 s: in order, never back


def _odometry_messages(store: object, start: int) -> Topic:
    from tests.support.bag_factory import ODOMETRY, odometry

    return Topic(
        "/tiago1/odom",
        ODOMETRY,
        [(start + i * 50_000_000, odometry(store, i, start + i * 50_000_000)) for i in range(60)],
    )


def test_stamps_a_few_hundred_milliseconds_behind_are_the_same_clock(
    scenario: Scenario, wall_bags: dict[tuple[str, str], Path], tmp_path: Path
) -> None:
    """TF published 0.3 s late on a wall-clock robot: still the wall clock, timed by its stamps,
    and the distances are those of the bag on time."""
    bag = wall_bags[("nav2", "mcap")]
    late = tmp_path / "late"
    restamp(bag, late, "mcap", lag={"/tiago1/tf": 0.3, "/tiago2/tf": 0.3}, shift_to_simulated=False)
    on_time, lagging = analyse_bag(bag, scenario), analyse_bag(late, scenario)
    assert lagging.timeline is not None and not lagging.timeline.simulated
    clocks = {c.topic: c for c in lagging.run.clocks}
    assert clocks["/tiago1/tf"].clock == "transform stamps"
    assert clocks["/tiago1/tf"].offset == pytest.approx(0.3, abs=0.01)
    assert not any("not synchronised" in p for p in lagging.problems)
    expected, found = _values(on_time), _values(lagging)
    for key, value in expected.items():
        if key[0] == "distance_travelled":
            assert found[key] == pytest.approx(value, rel=1e-6), key


def test_the_runs_prov_says_each_clock_and_each_detected_convention(
    scenario: Scenario, analysed: dict[str, tuple[AnalysedRun, AnalysedRun]]
) -> None:
    """Written out by hand: the bag's timeline, /tiago1/odom timed by simulated header stamps and
    /tiago1/cmd_vel by log time, tiago1's convention derived from its Nav2 status topic; and the
    run's graphs conform to the run shapes."""
    _, simulated = analysed["mcap-nav2-clock-half-speed"]
    quads = list(to_quads(compile_run(simulated.run, scenario)))
    graph = Store()
    graph.extend(quads)
    exsce, prov = "https://www.sesame-project.org/scenarios/", "http://www.w3.org/ns/prov#"
    query = f"""
        PREFIX exsce: <{exsce}> PREFIX prov: <{prov}>
        SELECT ?topic ?clock ?simulated WHERE {{
          ?c a exsce:source_clock ; exsce:clock ?clock ; exsce:simulated_time ?simulated ;
             prov:wasDerivedFrom ?topic .
        }}"""
    found = {
        (str(row["topic"].value).rsplit("topics/", 1)[1], row["clock"].value, row["simulated"].value)
        for row in graph.query(query, use_default_graph_as_union=True)
    }
    assert ("tiago1/odom", "header stamps", "true") in found
    assert ("tiago1/cmd_vel", "log time", "true") in found
    assert ("tiago2/tf", "transform stamps", "true") in found
    conventions = f"""
        PREFIX exsce: <{exsce}> PREFIX prov: <{prov}>
        SELECT ?robot ?convention ?topic WHERE {{
          ?d a exsce:detected_convention ; exsce:robot ?robot ; exsce:convention ?convention ;
             prov:wasDerivedFrom ?topic .
        }}"""
    rows = {
        (row["robot"].value, row["convention"].value, str(row["topic"].value).rsplit("topics/", 1)[1])
        for row in graph.query(conventions, use_default_graph_as_union=True)
    }
    assert rows == {
        ("tiago1", "nav2", "tiago1/navigate_to_pose/_action/status"),
        ("tiago2", "nav2", "tiago2/navigate_to_pose/_action/status"),
    }
    timelines = {
        row["t"].value
        for row in graph.query(
            f"PREFIX exsce: <{exsce}> SELECT ?t WHERE {{ ?b exsce:timeline ?t }}",
            use_default_graph_as_union=True,
        )
    }
    assert timelines == {"simulated time"}
    assert validate(quads, ["runs"]) == []
