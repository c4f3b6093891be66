"""Estimates scaled by path lengths on the occupancy grid, round walls and through doorways.

The map: 20 m by 10 m (x from -5 to 15 m), a wall 40 cm thick at x 4.8..5.2 m from y 0 to 10 m,
but for one doorway between y 7.0 and 8.5 m.  With the robot's 0.3 m radius, the shortest path
from the west side to the east side below the doorway wraps round the wall's end: a disc of
0.3 m round each of its corners (4.8, 7.0) and (5.2, 7.0), and the 0.4 m between them on top.

Poses: west w1 (2, 1) and w2 (-2, 7.75), east e1 (8, 1) and e2 (12, 7.75).  w1 → e1 is 6 m in a
straight line but 14.34 m round the wall; w2 → e2 runs straight through the doorway, 14 m either
way.  So an estimate of w1 → e1 from w2 → e2 scales by about 1 on the grid and by 6 / 14 in
straight lines (both drives about as long: the fixed cost of a drive, turning on the spot and
speeding up, weighs the same in both).
"""

from __future__ import annotations

import datetime
import math
import re
from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.derive.expect import expected_metric, segment_value
from exsce_dsl.derive.grid_lengths import GridLengths, grid_lengths
from exsce_dsl.maps.grid import load_occupancy_grid
from exsce_dsl.maps.planning import PlanningGrid
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
    Scenario,
    Subtask,
    Task,
)
from exsce_dsl.model.runs import Action, ActionId, Bag, MetricScope, MetricValue, Run, TaskExecution
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

CELL = 0.05  # metres per map cell
WIDTH, HEIGHT = 400, 200  # cells: 20 m by 10 m
WEST = -5.0  # x of the map's origin
RADIUS = 0.3  # the planner's robot radius

W1, W2 = (Pose(f"west-w{n}", Position(x, y), Orientation(), "west") for n, x, y in ((1, 2, 1), (2, -2, 7.75)))
E1, E2 = (Pose(f"east-e{n}", Position(x, y), Orientation(), "east") for n, x, y in ((1, 8, 1), (2, 12, 7.75)))
TIAGO = RobotType("tiago", base="pmb2", torso=True)


def write_walled_map(folder: Path, door: tuple[float, float] | None = (7.0, 8.5)) -> Path:
    """The module's map in map_server format (as tests/support/map_files.py's ``write_map``); ``door`` (y from, to)
    None: the wall is closed."""
    grid = np.full((HEIGHT, WIDTH), 254, dtype=np.uint8)
    wall = np.ones(HEIGHT, dtype=bool)  # by row from the bottom
    if door is not None:
        wall[round(door[0] / CELL) : round(door[1] / CELL)] = False
    rows = np.flatnonzero(wall)
    grid[HEIGHT - 1 - rows, round((4.8 - WEST) / CELL) : round((5.2 - WEST) / CELL)] = 0  # rows from the top
    (folder / "walled.pgm").write_bytes(f"P5\n{WIDTH} {HEIGHT}\n255\n".encode() + grid.tobytes())
    (folder / "walled.yaml").write_text(
        f"image: walled.pgm\nresolution: {CELL}\norigin: [{WEST}, 0.0, 0.0]\n"
        "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return folder / "walled.yaml"


def round_the_wall(a: tuple[float, float], b: tuple[float, float]) -> float:
    """By hand: the shortest path from ``a`` (west, below the doorway) to ``b`` (east, mirrored)
    round the discs of radius RADIUS centred on the wall's upper corners (4.8, 7) and (5.2, 7):
    the tangent from ``a`` to the west disc, the arc over it to its top, 0.4 m across, and the
    same down to ``b``.  Valid for points mirror images of each other about x = 5."""
    centre = (4.8, 7.0)
    d = math.dist(a, centre)
    tangent = math.sqrt(d * d - RADIUS * RADIUS)
    # the tangent point's direction from the centre, on the side facing up the wall
    towards_a = math.atan2(a[1] - centre[1], a[0] - centre[0])
    touch = towards_a - math.acos(RADIUS / d)
    arc = abs(math.remainder(math.pi / 2 - touch, 2 * math.pi)) * RADIUS
    return 2 * (tangent + arc) + 0.4


def test_the_hand_computed_length_round_the_wall_is_what_it_should_be() -> None:
    """The helper itself, against a case worked on paper: from (2, 2), the disc at (4.8, 7) is
    6.621 m away; tangent 6.614 m, touching 64.0° round from its top (arc 0.335 m): 12.51 m."""
    assert round_the_wall((2.0, 2.0), (8.0, 2.0)) == pytest.approx(12.513, abs=0.001)


@pytest.fixture(scope="module")
def lengths(tmp_path_factory: pytest.TempPathFactory) -> GridLengths:
    folder = tmp_path_factory.mktemp("walled")
    return GridLengths(PlanningGrid.from_map(load_occupancy_grid(write_walled_map(folder))))


def test_a_path_behind_a_wall_goes_round_it_through_the_doorway(lengths: GridLengths) -> None:
    for a, b in (((2.0, 2.0), (8.0, 2.0)), ((2.0, 1.0), (8.0, 1.0)), ((2.0, 6.0), (8.0, 6.0))):
        by_hand = round_the_wall(a, b)
        measured = lengths.length(a, b)
        assert measured is not None
        assert measured == pytest.approx(by_hand, abs=0.1), (a, b)  # within a planning cell
        assert measured > math.dist(a, b) + 0.5
    path = lengths.path((2.0, 2.0), (8.0, 2.0))
    assert path is not None and len(path) == 4
    assert all(4.4 < x < 5.6 and 7.2 < y < 7.4 for x, y in path[1:-1])  # just over the wall's end


def test_a_path_in_open_space_is_the_straight_line(lengths: GridLengths) -> None:
    # along the grid, and at 53° to it (8-connected steps alone would make this one 5.24 m)
    for a, b in (((2.0, 2.0), (2.0, 8.0)), ((1.0, 1.0), (4.0, 5.0)), ((6.0, 9.0), (9.0, 5.0))):
        measured = lengths.length(a, b)
        assert measured is not None
        assert measured == pytest.approx(math.dist(a, b), abs=0.02), (a, b)
    assert lengths.length((1.0, 1.0), (1.0, 1.0)) == 0.0
    assert lengths.length((4.0, 5.0), (1.0, 1.0)) == lengths.length((1.0, 1.0), (4.0, 5.0))


def test_no_length_off_the_map_or_across_a_closed_wall(lengths: GridLengths, tmp_path: Path) -> None:
    assert lengths.length((2.0, 2.0), (16.0, 2.0)) is None  # off the map
    # a goal in the wall's margin: reached from the nearest free cell, as the planner does
    beside = lengths.length((2.0, 2.0), (4.6, 3.0))
    assert beside is not None and beside == pytest.approx(math.dist((2.0, 2.0), (4.6, 3.0)), abs=0.05)
    closed = GridLengths(PlanningGrid.from_map(load_occupancy_grid(write_walled_map(tmp_path, None))))
    assert closed.length((2.0, 2.0), (8.0, 2.0)) is None
    assert closed.length((2.0, 2.0), (2.0, 8.0)) == pytest.approx(6.0, abs=0.02)


def scenario(name: str, environment: Environment, start: Pose, *waypoints: Pose) -> Scenario:
    task = Task(f"{name}_task", (Subtask(waypoints),))
    return Scenario(
        name,
        environment,
        (Robot("r1", TIAGO, "r1", start_pose=start),),
        Mission(f"{name}_m", MissionType.SEQUENTIAL, (Assignment("r1", task.id),)),
        (task,),
    )


def environment(map_file: Path | str | None) -> Environment:
    areas = (Area("west", (W1, W2)), Area("east", (E1, E2)))
    model = MapModel("walled", file=str(map_file)) if map_file is not None else None
    return Environment("walled", map=model, areas=areas)


@pytest.fixture(scope="module")
def driven(tmp_path_factory: pytest.TempPathFactory) -> tuple[Scenario, EmbeddedStore, dict[str, float]]:
    """Two executor runs of w1 → e1 → e2 → w2, ingested; and what each segment took in them by the
    executor's own record (the ground truth: its planned path's length and the goal's time)."""
    folder = tmp_path_factory.mktemp("walled-runs")
    base = scenario("walled_base", environment(write_walled_map(folder)), W1, E1, E2, W2)
    store = EmbeddedStore(None)
    runs = list(simulate(base, folder / "runs", 2, seed=7))
    assert not [r for r in ingest_bags([r.bag for r in runs], base, store) if r.failed]
    w1_e1 = [a for r in runs for a in r.execution.actions if (a.start_pose.id, a.goal.id) == (W1.id, E1.id)]
    assert len(w1_e1) == 2
    truth = {
        "distance_travelled": sum(a.path_length for a in w1_e1) / 2,
        "task_duration": sum(a.end - a.start for a in w1_e1) / 2,
    }
    return base, store, truth


@pytest.mark.parametrize("metric", ["distance_travelled", "task_duration"])
def test_a_segment_behind_a_wall_is_estimated_closer_to_the_truth_on_the_grid(
    driven: tuple[Scenario, EmbeddedStore, dict[str, float]], metric: str
) -> None:
    base, store, truth = driven
    held_out = frozenset({frozenset((W1.id, E1.id))})
    on_grid = segment_value(store, base, metric, W1, E1, held_out)
    straight = segment_value(store, base, metric, W1, E1, held_out, on_grid=False)
    without_map = scenario("walled_plain", environment(None), W1, E1)
    plain = segment_value(store, without_map, metric, W1, E1, held_out)
    # w2 → e2 is the one neighbour with data (driven e2 → w2, the other way)
    assert on_grid.how == "estimated from west-w2–east-e2 (grid path lengths)"
    assert straight.how == plain.how == "estimated from west-w2–east-e2 (straight-line lengths)"
    assert straight.value == plain.value
    assert on_grid.value is not None and straight.value is not None
    error_on_grid = abs(on_grid.value - truth[metric]) / truth[metric]
    error_straight = abs(straight.value - truth[metric]) / truth[metric]
    # in straight lines w1 → e1 is 6 / 14 of w2 → e2: less than half the truth
    assert error_straight > 0.5
    # the grid's path is the tightest one; the executor keeps clear of walls (4 % longer round this
    # one) and each drive has a fixed cost (turning on the spot: e2 → w2 starts with a half turn)
    assert error_on_grid < 0.15 and error_on_grid < error_straight / 4
    observed = segment_value(store, base, metric, W1, E1)  # not held out: no estimate at all
    assert observed.how == "observed" and observed.runs == 2


def test_a_map_that_cannot_be_read_gives_straight_line_estimates_and_says_why(
    driven: tuple[Scenario, EmbeddedStore, dict[str, float]], tmp_path: Path
) -> None:
    _, store, _ = driven
    broken = scenario("walled_broken", environment(tmp_path / "missing.yaml"), W1, E1)
    held_out = frozenset({frozenset((W1.id, E1.id))})
    estimate = segment_value(store, broken, "distance_travelled", W1, E1, held_out)
    assert estimate.how.startswith("estimated from west-w2–east-e2 (straight-line lengths: its grid cannot")
    assert "cannot read map file" in estimate.how and "missing.yaml" in estimate.how
    with pytest.raises(Exception, match="cannot read map file"):
        grid_lengths(broken)


DIST = ("/r1/distance_travelled",)


def hand_run(base: Scenario, uuid: str, legs: list[tuple[Pose, Pose, float, float]]) -> Run:
    """A run of ``base`` with the given (from, to, distance, duration) per segment."""
    actions = tuple(Action(ActionId("r1", 1, 1, n), a, b) for n, (a, b, _, _) in enumerate(legs, start=1))
    metrics = tuple(
        MetricValue(metric, MetricScope.SEGMENT, value, DIST, action=action.id)
        for action, (_, _, distance, duration) in zip(actions, legs, strict=True)
        for metric, value in (("distance_travelled", distance), ("task_duration", duration))
    )
    start = datetime.datetime(2024, 7, 1, 9)
    return Run(
        uuid,
        base.id,
        start,
        start + datetime.timedelta(minutes=5),
        Bag(f"{uuid}.bag", DIST),
        (TaskExecution("r1", 1, actions),),
        metrics,
    )


def test_a_neighbour_driven_with_a_detour_is_scaled_per_metre_driven(tmp_path: Path) -> None:
    """e2 → w2 stored at 28 m and 50 s, twice its 14 m path through the doorway (the robot gave
    way, say): w1 → e1 (14.34 m round the wall) is 50 s × 14.34 / 28 ≈ 25.6 s, not
    50 s × 14.34 / 14 ≈ 51 s; its distance is its grid path's length."""
    env = environment(write_walled_map(tmp_path))
    base = scenario("walled_base", env, E2, W2)
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(base))
    add_prov(store, compile_run(hand_run(base, "u1", [(E2, W2, 28.0, 50.0)]), base))
    w1_e1 = round_the_wall((2.0, 1.0), (8.0, 1.0))
    assert w1_e1 == pytest.approx(14.34, abs=0.01)
    duration = segment_value(store, base, "task_duration", W1, E1)
    assert duration.value == pytest.approx(50.0 * w1_e1 / 28.0, rel=0.01)
    said = re.fullmatch(
        r"estimated from west-w2–east-e2 \(grid path lengths; "
        r"west-w2–east-e2 per metre driven, (\d+)% longer than its grid path\)",
        duration.how,
    )
    assert said is not None, duration.how
    assert 99 <= int(said[1]) <= 101  # 28 m against a path of 14 m
    distance = segment_value(store, base, "distance_travelled", W1, E1)
    assert distance.value == pytest.approx(w1_e1, rel=0.01)
    ignored = segment_value(store, base, "task_duration", W1, E1, detour=math.inf)
    assert ignored.value == pytest.approx(50.0 * w1_e1 / 14.0, rel=0.01)
    assert ignored.how == "estimated from west-w2–east-e2 (grid path lengths)"


def test_a_segment_without_neighbours_falls_back_to_the_rate_per_metre_of_grid_path(tmp_path: Path) -> None:
    """w1 → e1 stored at 16 m (14.34 m round the wall: 1.116 per metre of path); e1 → x, x alone
    in its area, north-west of the doorway, has no neighbour to estimate from: its grid path
    (10.9 m: up the east side, round the wall's east corner into the doorway, then straight to x)
    times 1.116, not its straight line (10.4 m) times 16 / 6."""
    x = Pose("north-x", Position(2.0, 9.5), Orientation(), "north")
    env = environment(write_walled_map(tmp_path))
    env = Environment(env.id, env.map, areas=(*env.areas, Area("north", (x,))))
    base = scenario("walled_base", env, W1, E1)
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(base))
    add_prov(store, compile_run(hand_run(base, "u1", [(W1, E1, 16.0, 40.0)]), base))
    expected = expected_metric(store, scenario("walled_x", env, W1, E1, x), "r1", "distance_travelled")
    w1e1, e1x = expected.segments
    assert (w1e1.value, w1e1.how) == (16.0, "observed")
    rate = 16.0 / round_the_wall((2.0, 1.0), (8.0, 1.0))
    # by hand, with the corner of the wall's margin at (5.5, 7.3) taken sharp (rounding it off
    # saves some 7 cm)
    by_hand = math.dist((8.0, 1.0), (5.5, 7.3)) + math.dist((5.5, 7.3), (2.0, 9.5))
    assert e1x.value == pytest.approx(rate * by_hand, rel=0.015)
    assert e1x.how.startswith("no data, and no pose near it to estimate from: ")
    assert (
        "its grid path length × 1.1" in e1x.how and "per metre, as on the robot's other segments" in e1x.how
    )
    assert expected.value == pytest.approx(16.0 + e1x.value)
