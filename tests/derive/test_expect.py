"""Expected values from stored path segments, and the estimate for a segment no run drove.

One room: a (0, 0), b (3, 4), c (6, 8), d (0, 8).  Scenario ``base``: r1 drives a → b
(10 m, then 12 m in a second run) and b → c (5 m).  Scenario ``longer`` (r1: a → b → c → d)
is expected to travel 11 (a → b, the mean) + 5 (b → c) + an estimate for c → d, which no
run drove: the poses nearest c and d (other than c, d) are both b; of (b, d), (c, b), (b, b)
only c → b has data, the other way (b → c, 5 m over 5 m), so c → d (6 m) ≈ 5 × 6 / 5 = 6.
"""

from __future__ import annotations

import datetime
import math

from exsce_dsl.derive.expect import expected_metric, robot_path
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
from exsce_dsl.model.runs import Action, ActionId, Bag, MetricScope, MetricValue, Run, TaskExecution
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.run import compile_run
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.writing import add_prov

A, B, C, D = (
    Pose(f"room-{n}", Position(x, y), Orientation(), "room")
    for n, x, y in (("a", 0, 0), ("b", 3, 4), ("c", 6, 8), ("d", 0, 8))
)
ROOM = Environment("house", areas=(Area("room", (A, B, C, D)),))
TIAGO = RobotType("tiago", base="pmb2", torso=True)


def scenario(name: str, *waypoints: Pose) -> Scenario:
    task = Task(f"{name}_task", (Subtask(waypoints),))
    return Scenario(
        name,
        ROOM,
        (Robot("r1", TIAGO, "r1", start_pose=A),),
        Mission(f"{name}_m", MissionType.SEQUENTIAL, (Assignment("r1", task.id),)),
        (task,),
    )


BASE, LONGER = scenario("base", B, C), scenario("longer", B, C, D)
DIST = ("/r1/distance_travelled",)


def run(uuid: str, a_to_b: float) -> Run:
    actions = (Action(ActionId("r1", 1, 1, 1), A, B), Action(ActionId("r1", 1, 1, 2), B, C))
    metrics = tuple(
        MetricValue("distance_travelled", MetricScope.SEGMENT, v, DIST, action=a.id)
        for a, v in zip(actions, (a_to_b, 5.0), strict=True)
    ) + (MetricValue("distance_travelled", MetricScope.ROBOT, a_to_b + 5.0, DIST, robot="r1"),)
    start = datetime.datetime(2024, 7, 1, 9)
    return Run(
        uuid,
        "base",
        start,
        start + datetime.timedelta(minutes=2),
        Bag(f"{uuid}.bag", DIST),
        (TaskExecution("r1", 1, actions),),
        metrics,
    )


def test_observed_segments_and_an_estimate_add_up() -> None:
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(BASE))
    for uuid, a_to_b in (("u1", 10.0), ("u2", 12.0)):
        add_prov(store, compile_run(run(uuid, a_to_b), BASE))
    assert [(s.id, g.id) for s, g in robot_path(LONGER, "r1")] == [
        ("room-a", "room-b"),
        ("room-b", "room-c"),
        ("room-c", "room-d"),
    ]
    expected = expected_metric(store, LONGER, "r1", "distance_travelled")
    ab, bc, cd = expected.segments
    assert (ab.value, ab.how, ab.runs) == (11.0, "observed", 2)
    assert (bc.value, bc.how, bc.runs) == (5.0, "observed", 2)
    assert cd.value is not None and math.isclose(cd.value, 6.0)
    assert cd.how == "estimated from room-c–room-b (straight-line lengths)" and cd.runs == 2  # no map
    assert expected.value is not None and math.isclose(expected.value, 22.0)


def test_without_any_data_nearby_there_is_no_expected_value() -> None:
    store = EmbeddedStore(None)
    expected = expected_metric(store, LONGER, "r1", "task_duration")
    assert expected.value is None
    assert expected.segments[0].how == "no data, nor for room-d and room-c near its ends"


def test_a_segment_with_no_neighbour_data_falls_back_to_the_robot_s_rate_per_metre() -> None:
    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(BASE))
    add_prov(store, compile_run(run("u1", 10.0), BASE))
    # b → hall-x: the hall has no other pose to estimate from, so the fallback applies
    lonely = Environment(
        "house",
        areas=(
            Area("room", (A, B, C, D)),
            Area("hall", (Pose("hall-x", Position(0, 20), Orientation(), "hall"),)),
        ),
    )
    far = Scenario(
        "far",
        lonely,
        (Robot("r1", TIAGO, "r1", start_pose=A),),
        Mission("far_m", MissionType.SEQUENTIAL, (Assignment("r1", "far_task"),)),
        (Task("far_task", (Subtask((B, lonely.areas[1].poses[0])),)),),
    )
    expected = expected_metric(store, far, "r1", "distance_travelled")
    ab, bx = expected.segments
    assert ab.value == 10.0 and ab.how == "observed"
    # b (3, 4) → x (0, 20): 16.28 m in a straight line, at 10 m per 5 m
    assert bx.value is not None and math.isclose(bx.value, 2.0 * math.dist((3, 4), (0, 20)))
    assert "straight length × 2 per metre" in bx.how
    assert expected.value is not None and math.isclose(expected.value, 10.0 + bx.value)


def test_the_derived_scenario_s_criteria_follow_from_the_expected_change() -> None:
    from exsce_dsl.derive.expect import derived_criteria
    from exsce_dsl.lang import expectation_text
    from exsce_dsl.model.acceptance import (
        Acceptance,
        BasicRelation,
        Criterion,
        Expectation,
        Quantifier,
        Quantity,
        Subject,
    )

    store = EmbeddedStore(None)
    add_prov(store, compile_scenario(BASE))
    for uuid, a_to_b in (("u1", 10.0), ("u2", 12.0)):
        add_prov(store, compile_run(run(uuid, a_to_b), BASE))
    speed = Expectation(Subject(Quantifier.EACH_ROBOT), "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(1.0, "m/s", "1.0"))
    base_criteria = Acceptance("base", (Criterion("safe", (), None, (speed,)),))
    made = derived_criteria(store, BASE, LONGER, base_criteria).acceptance
    assert made.scenario == "longer"
    assert [c.title for c in made.criteria] == ["as safe as base", "as expected from base"]
    assert [expectation_text(e) for e in made.expectations()] == [
        "each robot max_velocity stays below 1.0 m/s",
        # expected 22 m (the method's Listing 35: the new scenario's own baseline, both ways) ...
        "r1 distance_travelled is invariant around 22 m within 10 %",
        # ... against the base's mean of 16 m: 6 m more, less 10 % of 22 m
        "r1 distance_travelled is increasing by 6 m within 2.2 m of base",
    ]
    # 16 m of the 22 are observed (a→b, b→c): they allow 10 % at most whatever the tolerance;
    # c→d (6 m) is estimated and allows the whole tolerance: 1.6 + 6 × 80 % = 6.4 m, 29.091 % of 22
    small = derived_criteria(store, BASE, LONGER, None, tolerance_percent=80.0).acceptance
    assert [expectation_text(e) for e in small.expectations()] == [
        "r1 distance_travelled is invariant around 22 m within 29.091 %",
        # a change (6 m) within the allowance (6.4 m): runs may be 6.4 m either side of 22 m, so
        # up to 6 + 6.4 m from the base's 16 m
        "r1 distance_travelled is invariant within 12.4 m of base",
    ]
    wide = derived_criteria(store, BASE, LONGER, None, tolerance_percent=30.0).acceptance
    assert [expectation_text(e) for e in wide.expectations()][0] == (
        "r1 distance_travelled is invariant around 22 m within 15.455 %"  # (1.6 + 1.8 m) / 22 m
    )


def test_a_segment_is_read_whatever_heading_its_poses_were_driven_with() -> None:
    """The base's task faced room-b north (another pose IRI, the same point): the new path,
    which names room-b with its declared heading, still finds those drives."""
    north = B.with_orientation(Orientation(yaw=1.5708))
    store = EmbeddedStore(None)
    base = scenario("base", north, C)
    add_prov(store, compile_scenario(base))
    actions = (Action(ActionId("r1", 1, 1, 1), A, north),)
    metrics = (MetricValue("distance_travelled", MetricScope.SEGMENT, 7.5, DIST, action=actions[0].id),)
    start = datetime.datetime(2024, 7, 1, 9)
    add_prov(
        store,
        compile_run(
            Run("u9", "base", start, start + datetime.timedelta(minutes=1), Bag("u9.bag", DIST),
                (TaskExecution("r1", 1, actions),), metrics),
            base,
        ),
    )
    ab = expected_metric(store, scenario("plain", B), "r1", "distance_travelled").segments[0]
    assert (ab.value, ab.how, ab.runs) == (7.5, "observed", 1)
    ba = expected_metric(store, Scenario("back", ROOM, (Robot("r1", TIAGO, "r1", start_pose=B),),
                                         Mission("back_m", MissionType.SEQUENTIAL, (Assignment("r1", "t"),)),
                                         (Task("t", (Subtask((A,)),)),)), "r1", "distance_travelled").segments[0]
    assert (ba.value, ba.how) == (7.5, "observed the other way")


def test_a_clause_between_robots_is_not_copied_to_a_scenario_of_one_robot() -> None:
    from exsce_dsl.derive.expect import derived_criteria
    from exsce_dsl.model.acceptance import (
        Acceptance,
        BasicRelation,
        Criterion,
        Expectation,
        Quantifier,
        Quantity,
        Subject,
    )

    apart = Expectation(Subject(Quantifier.MISSION), "distance_between_robots", BasicRelation.ABOVE_MIN, limit=Quantity(0.1, "m", "0.1"))
    made = derived_criteria(EmbeddedStore(None), BASE, LONGER, Acceptance("base", (Criterion("apart", (), None, (apart,)),))).acceptance
    assert made.criteria == ()  # one robot: nothing between robots to judge, and no runs to expect from


def test_derive_expect_keeps_a_user_safety_clause_on_mean_speed() -> None:
    """Issue 48, item 6: ``derive --expect`` dropped ``mean_speed stays below`` (a limit on a mean,
    which it took for a clause about the base's own mission) from the derived "as safe as"
    criteria; every limit the user wrote is carried, on any metric, below or above."""
    from exsce_dsl.derive.expect import derived_criteria
    from exsce_dsl.lang import expectation_text
    from exsce_dsl.model.acceptance import (
        Acceptance,
        BasicRelation,
        Criterion,
        Expectation,
        Quantifier,
        Quantity,
        Subject,
    )

    def limit(metric: str, relation: BasicRelation, value: float, unit: str) -> Expectation:
        quantity = Quantity(value, unit, f"{value}")
        return Expectation(Subject(Quantifier.EACH_ROBOT), metric, relation, limit=quantity)

    clauses = (
        limit("max_velocity", BasicRelation.BELOW_MAX, 1.0, "m/s"),
        limit("mean_speed", BasicRelation.BELOW_MAX, 2.0, "m/s"),
        limit("fast_driving_time", BasicRelation.BELOW_MAX, 2.0, "s"),
        limit("mean_clearance", BasicRelation.ABOVE_MIN, 0.3, "m"),
    )
    base_criteria = Acceptance("base", (Criterion("moves safely", (), None, clauses),))
    made = derived_criteria(EmbeddedStore(None), BASE, LONGER, base_criteria).acceptance
    [safe] = [c for c in made.criteria if c.title == "as safe as base"]
    assert [expectation_text(e) for e in safe.expectations] == [
        "each robot max_velocity stays below 1.0 m/s",
        "each robot mean_speed stays below 2.0 m/s",
        "each robot fast_driving_time stays below 2.0 s",
        "each robot mean_clearance stays above 0.3 m",
    ]
