"""What a derived scenario's criteria keep of its base's safety clauses, and the notes on what
they leave out: a robot without a start pose is in no run, so an ``each robot`` limit is written
for the robots that are, a limit between robots needs two of them, and each is said."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from exsce_dsl.derive.kept_clauses import safety_clauses, standing_note
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Acceptance, Scenario
from exsce_dsl.model.acceptance import Expectation, Quantifier
from exsce_dsl.transform.derivation import derive

SPEC = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"
TAKE_OVER = (
    "add_robot",
    {"robot": "new_robot_1", "like": "tiago1", "start": "classroom_c069-w001", "take_over": "tiago1"},
)


def _derived(*steps: tuple[str, dict[str, str]]) -> tuple[Scenario, Acceptance | None]:
    spec = load_spec(SPEC)
    base = spec.scenario("scenario_c")
    return derive(base, list(steps), tasks={t.id: t for t in spec.tasks}).scenario, spec.acceptance_of(
        base.id
    )


def _said(clauses: Sequence[Expectation]) -> set[tuple[str, str, str]]:
    return {(e.subject.robot or e.subject.quantifier.value, e.metric, e.relation.value) for e in clauses}


SCENARIO_C_LIMITS = {
    ("each robot", "max_velocity", "below_max"),
    ("each robot", "distance_to_obstacles", "above_min"),
    ("mission", "distance_between_robots", "above_min"),
    ("each robot", "fast_driving_time", "below_max"),
    ("each robot", "mean_turn_rate", "below_max"),
}
"""scenario_c's safety limits, as its acceptance criteria write them."""


def test_a_robot_standing_by_keeps_every_limit_and_no_note() -> None:
    scenario, base = _derived(TAKE_OVER)
    assert scenario.mission.tasks_of("tiago1") == ()
    clauses, notes = safety_clauses(scenario, base)
    assert _said(clauses) == SCENARIO_C_LIMITS  # tiago1 stands by in the runs: each robot's limits judge it
    assert notes == []


def test_a_robot_without_a_start_pose_is_left_out_of_each_robot_limits_with_a_note() -> None:
    scenario, base = _derived(TAKE_OVER, ("remove_start_pose", {"robot": "tiago1"}))
    clauses, notes = safety_clauses(scenario, base)
    said = _said(clauses)
    assert not any(e.subject.quantifier is Quantifier.EACH_ROBOT for e in clauses)
    assert {("tiago2", "max_velocity", "below_max"), ("new_robot_1", "max_velocity", "below_max")} <= said
    assert not any(who == "tiago1" for who, _, _ in said)
    assert ("mission", "distance_between_robots", "above_min") in said  # tiago2 and new_robot_1 are there
    assert notes == [
        f"tiago1 has no start pose in {scenario.id}: it is in none of its runs, so no clause judges it "
        "(the base's 'each robot' limits are written for each robot that is)"
    ]


def test_a_limit_between_robots_with_one_robot_in_the_runs_is_dropped_with_a_note() -> None:
    scenario, base = _derived(
        ("remove_task", {"task": "delivery_a"}), ("remove_task", {"task": "navigate_home_1"})
    )
    scenario = replace(scenario, robots=tuple(
        replace(r, start_pose=None) if r.id == "tiago1" else r for r in scenario.robots
    ))  # fmt: skip
    clauses, notes = safety_clauses(scenario, base)
    assert not any(e.metric == "distance_between_robots" for e in clauses)
    assert (
        f"distance_between_robots: no clause, fewer than two robots are in the runs of {scenario.id}" in notes
    )


def test_the_standing_note_names_the_robot_the_scenario_and_the_clauses() -> None:
    note = standing_note("tiago1", "c_x")
    assert note.startswith(
        "tiago1 has no tasks in c_x: no waypoints_visited, distance_travelled or task_duration"
    )
    assert "the safety clauses judge it standing by" in note


def test_a_robot_that_drives_nowhere_keeps_its_peaks_not_its_means_or_totals() -> None:
    """A fault-free campaign on scenario_c failed ``remove_task(delivery_a)``: tiago1, left with
    navigate_home_1 from its own home, only turns on the spot for a second, and its mean turn rate
    over that second (0.6–0.9 rad/s) broke the base's 0.5 rad/s, a limit written for a mission."""
    scenario, base = _derived(("remove_task", {"task": "delivery_a"}))
    clauses, notes = safety_clauses(scenario, base)
    said = _said(clauses)
    assert ("each robot", "max_velocity", "below_max") in said  # peaks judge every robot
    assert ("each robot", "distance_to_obstacles", "above_min") in said
    assert ("tiago2", "mean_turn_rate", "below_max") in said and (
        "tiago2",
        "fast_driving_time",
        "below_max",
    ) in said
    assert not any(
        who in ("tiago1", "each robot") and m in ("mean_turn_rate", "fast_driving_time") for who, m, _ in said
    )
    assert notes == [
        f"tiago1 drives nowhere in {scenario.id} (every waypoint of its tasks is where it starts: it only "
        "turns on the spot): no fast_driving_time, mean_turn_rate clause for it, a limit on a mean or a "
        "total is about a mission that drives; the base's other limits judge it"
    ]


def test_a_robot_that_drives_keeps_every_limit() -> None:
    scenario, base = _derived(("remove_task", {"task": "navigate_home_1"}))
    clauses, notes = safety_clauses(scenario, base)
    assert _said(clauses) == SCENARIO_C_LIMITS and notes == []
