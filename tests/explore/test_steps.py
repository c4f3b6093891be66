"""The applicable single steps of scenario_c: each applies, and every transformation that can
apply to scenario_c is proposed."""

from __future__ import annotations

from exsce_dsl.explore.fingerprint import fingerprint
from exsce_dsl.explore.steps import PROPOSERS, applicable_steps, mint
from exsce_dsl.model import Scenario, Task
from exsce_dsl.model.names import is_valid_name
from exsce_dsl.transform.derivation import derive
from exsce_dsl.transform.transformations import TRANSFORMATIONS

BASE_ROBOTS = {"tiago1", "tiago2"}

# Written out by hand: both robots start somewhere (no add_start_pose) and have tasks (no
# remove_start_pose), and the environment has no obstacle (no move_obstacle).
APPLY_TO_C = {
    "add_task", "remove_task", "substitute_task", "swap_assignment", "reverse_task_order",
    "reverse_waypoint_order", "swap_start_poses", "substitute_allocation", "remove_robot",
    "add_robot", "replace_robot",
}  # fmt: skip


def test_every_transformation_has_a_proposer() -> None:
    assert PROPOSERS.keys() == TRANSFORMATIONS.keys()


def test_the_transformations_that_can_apply_to_scenario_c_are_proposed(
    spec_c: tuple[Scenario, dict[str, Task]],
) -> None:
    base, tasks = spec_c
    assert {s.name for s in applicable_steps(base, tasks)} == APPLY_TO_C


def test_every_proposed_step_derives_what_it_applied(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    steps = applicable_steps(base, tasks)
    assert len(steps) == len({(s.name, s.arguments) for s in steps}) > 50
    for step in steps:
        derived = derive(base, [step.request], tasks=tasks)
        assert fingerprint(derived.scenario, BASE_ROBOTS) == fingerprint(step.applied.scenario, BASE_ROBOTS)


def test_a_robot_without_tasks_may_lose_its_start_pose(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    idle = derive(base, [("remove_task", {"robot": "tiago2"})], tasks=tasks).scenario
    removals = [s.arguments for s in applicable_steps(idle, tasks) if s.name == "remove_start_pose"]
    assert removals == [(("robot", "tiago2"),)]
    parked = derive(base, [("remove_task", {"robot": "tiago2"}), ("remove_start_pose", {"robot": "tiago2"})])
    poses = [
        dict(s.arguments)["pose"]
        for s in applicable_steps(parked.scenario, tasks)
        if s.name == "add_start_pose"
    ]
    assert poses and "classroom_c025-w001" not in poses  # tiago1 starts there


def test_new_ids_are_minted_valid_and_free(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    new = {dict(s.arguments).get("robot") for s in applicable_steps(base, tasks) if s.name == "add_robot"}
    new |= {dict(s.arguments)["by"] for s in applicable_steps(base, tasks) if s.name == "replace_robot"}
    assert new == {"new_robot_1"}
    assert mint("x", ["x_1", "x_2"]) == "x_3" and is_valid_name(mint("robot", []))


def test_a_taken_reversed_id_is_minted_anew(spec_c: tuple[Scenario, dict[str, Task]]) -> None:
    base, tasks = spec_c
    steps = [
        ("reverse_waypoint_order", {"task": "delivery_a"}),
        ("substitute_task", {"task": "delivery_a_reversed", "with": "delivery_a"}),
    ]
    back = derive(base, steps, tasks=tasks)
    known = tasks | {t.id: t for t in back.new_tasks}
    reversals = [
        dict(s.arguments)
        for s in applicable_steps(back.scenario, known)
        if s.name == "reverse_waypoint_order"
    ]
    assert {"task": "delivery_a", "as": "delivery_a_reversed_1"} in reversals
    assert {"task": "delivery_b"} in reversals
