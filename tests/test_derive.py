"""Input transformations on the semantic model, their compositions, their record and PROV,
and `exscec derive` writing a file that checks clean."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from exsce_dsl.derive.derivation import derive
from exsce_dsl.errors import ExsceError
from exsce_dsl.lang.build import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.derivation import TransformationStep
from exsce_dsl.prov.derivation import compile_derivation

from conftest import EXAMPLES, run_exscec

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


@pytest.fixture(scope="module")
def base() -> Scenario:
    return load_spec(SPEC).scenario("scenario_c")


def allocation(scenario: Scenario) -> list[tuple[str, str]]:
    return [(a.robot, a.task) for a in scenario.mission.allocation]


BASE_ALLOCATION = [
    ("tiago1", "delivery_a"), ("tiago2", "delivery_b"), ("tiago1", "navigate_home_1"), ("tiago2", "navigate_home_2")
]


def test_the_base_is_what_the_tests_expect(base: Scenario) -> None:
    assert allocation(base) == BASE_ALLOCATION and [r.id for r in base.robots] == ["tiago1", "tiago2"]


@pytest.mark.parametrize(
    ("name", "arguments", "expected"),
    [
        ("remove_robot", {"robot": "tiago2"}, [("tiago1", "delivery_a"), ("tiago1", "navigate_home_1")]),
        (
            "remove_robot",
            {"robot": "tiago2", "reassign": "tiago1"},
            [("tiago1", "delivery_a"), ("tiago1", "delivery_b"), ("tiago1", "navigate_home_1"), ("tiago1", "navigate_home_2")],
        ),
        (
            "swap_assignment",
            {"robot": "tiago1", "with": "tiago2"},
            [("tiago2", "delivery_a"), ("tiago1", "delivery_b"), ("tiago2", "navigate_home_1"), ("tiago1", "navigate_home_2")],
        ),
        (
            "reverse_task_order",
            {"robot": "tiago1"},
            [("tiago1", "navigate_home_1"), ("tiago2", "delivery_b"), ("tiago1", "delivery_a"), ("tiago2", "navigate_home_2")],
        ),
        ("remove_task", {"task": "delivery_b"}, [("tiago1", "delivery_a"), ("tiago1", "navigate_home_1"), ("tiago2", "navigate_home_2")]),
        ("remove_task", {"robot": "tiago1"}, [("tiago2", "delivery_b"), ("tiago2", "navigate_home_2")]),
        (
            "add_task",
            {"robot": "tiago2", "task": "delivery_a", "position": "2"},
            # tiago2's 2nd task: just before its former 2nd
            [("tiago1", "delivery_a"), ("tiago2", "delivery_b"), ("tiago1", "navigate_home_1"), ("tiago2", "delivery_a"), ("tiago2", "navigate_home_2")],
        ),
        (
            "substitute_task",
            {"task": "delivery_b", "with": "delivery_a"},
            [("tiago1", "delivery_a"), ("tiago2", "delivery_a"), ("tiago1", "navigate_home_1"), ("tiago2", "navigate_home_2")],
        ),
    ],
)
def test_each_allocation_transformation(base: Scenario, name: str, arguments: dict[str, str], expected: list[tuple[str, str]]) -> None:
    derived = derive(base, [(name, arguments)], "new_one")
    assert allocation(derived.scenario) == expected
    assert derived.scenario.id == "new_one" and derived.scenario.mission.id == "new_one_mission"
    assert [t.id for t in derived.scenario.tasks] == list(dict.fromkeys(task for _, task in expected))
    assert derived.derivation.base == "scenario_c" and derived.derivation.steps[0].transformation == name
    assert allocation(base) == BASE_ALLOCATION  # the base is left as it was


def test_reverse_waypoint_order_makes_a_new_task(base: Scenario) -> None:
    derived = derive(base, [("reverse_waypoint_order", {"task": "delivery_a"})], "rev")
    (task,) = derived.new_tasks
    old = base.task("delivery_a")
    assert old is not None and task.id == "delivery_a_reversed"
    assert [p.id for p in task.waypoints()] == [p.id for p in reversed(list(old.waypoints()))]
    assert ("tiago1", "delivery_a_reversed") in allocation(derived.scenario)
    assert derived.derivation.steps == (
        TransformationStep("reverse_waypoint_order", (("task", "delivery_a"), ("to", "delivery_a_reversed"))),
    )


def test_start_pose_and_robot_transformations(base: Scenario) -> None:
    swapped = derive(base, [("swap_start_poses", {"robot": "tiago1", "with": "tiago2"})], "swapped").scenario
    assert [r.start_pose.id for r in swapped.robots if r.start_pose] == ["classroom_c025-w002", "classroom_c025-w001"]
    added = derive(base, [("add_robot", {"robot": "tiago3", "like": "tiago1", "start": "classroom_c022-w001",
                                          "take_over": "tiago2"})], "three").scenario
    assert [r.id for r in added.robots] == ["tiago1", "tiago2", "tiago3"]
    assert ("tiago3", "delivery_b") in allocation(added) and not any(r == "tiago2" for r, _ in allocation(added))
    replaced = derive(base, [("replace_robot", {"robot": "tiago2", "by": "tiago9"})], "replaced")
    assert [r.id for r in replaced.scenario.robots] == ["tiago1", "tiago9"]
    assert replaced.scenario.robot("tiago9").start_pose.id == "classroom_c025-w002"  # type: ignore[union-attr]
    assert [s.transformation for s in replaced.derivation.steps] == ["add_robot", "substitute_allocation", "remove_robot"]


def test_start_pose_and_allocation_transformations(base: Scenario) -> None:
    alone = derive(
        base,
        [
            ("remove_task", {"robot": "tiago2"}),
            ("remove_start_pose", {"robot": "tiago2"}),
            ("add_start_pose", {"robot": "tiago2", "pose": "classroom_c022-w001"}),
            ("substitute_allocation", {"allocation": "tiago2:delivery_b, tiago1:delivery_a"}),
        ],
        "moved",
    )
    assert alone.scenario.robot("tiago2").start_pose.id == "classroom_c022-w001"  # type: ignore[union-attr]
    assert allocation(alone.scenario) == [("tiago2", "delivery_b"), ("tiago1", "delivery_a")]
    assert alone.derivation.steps[-1] == TransformationStep(
        "substitute_allocation", (("allocation", "tiago2:delivery_b,tiago1:delivery_a"),)
    )
    with pytest.raises(ExsceError, match="'tiago1' has tasks, so it needs a start pose"):
        derive(base, [("remove_start_pose", {"robot": "tiago1"})])
    with pytest.raises(ExsceError, match="starts at 'classroom_c025-w001' already"):
        derive(base, [("add_start_pose", {"robot": "tiago1", "pose": "classroom_c022-w001"})])
    with pytest.raises(ExsceError, match="'tiago1 delivery_a' is not robot:task"):
        derive(base, [("substitute_allocation", {"allocation": "tiago1 delivery_a"})])


def test_compositions_of_two_and_three_apply_in_order(base: Scenario) -> None:
    two = derive(base, [("remove_robot", {"robot": "tiago2", "reassign": "tiago1"}), ("reverse_task_order", {})], "two")
    assert allocation(two.scenario) == [
        ("tiago1", "navigate_home_2"), ("tiago1", "navigate_home_1"), ("tiago1", "delivery_b"), ("tiago1", "delivery_a")
    ]
    three = derive(
        base,
        [
            ("reverse_waypoint_order", {"task": "delivery_a"}),
            ("swap_assignment", {"robot": "tiago1", "with": "tiago2"}),
            ("remove_task", {"task": "navigate_home_2"}),
        ],
    )
    assert allocation(three.scenario) == [("tiago2", "delivery_a_reversed"), ("tiago1", "delivery_b"), ("tiago2", "navigate_home_1")]
    assert three.scenario.id.startswith("scenario_c_") and three.scenario.id == derive(
        base, [("reverse_waypoint_order", {"task": "delivery_a"}), ("swap_assignment", {"robot": "tiago1", "with": "tiago2"}),
               ("remove_task", {"task": "navigate_home_2"})]
    ).scenario.id  # deterministic
    provn = compile_derivation(three.derivation).get_provn()
    for n, name in enumerate(("reverse_waypoint_order", "swap_assignment", "remove_task"), start=1):
        assert f"step_{n:02d}-{name}" in provn
    assert "wasInformedBy" in provn and "wasStartedBy" in provn and "wasEndedBy" in provn
    assert f"used({three.scenario.id}:generation, exsce:scenario_c" in provn


@pytest.mark.parametrize(
    ("requests", "words"),
    [
        ([("remove_robot", {"robot": "tiago2"}), ("remove_robot", {"robot": "tiago1"})], "the last robot"),
        ([("remove_robot", {"robot": "tiago2", "reassign": "tiago7"})], "has no robot 'tiago7'"),
        ([("swap_start_poses", {"robot": "tiago1", "with": "tiago1"})], "with its own"),
        ([("remove_robot", {"robot": "tiago2", "reassign": "tiago2"})], "to itself"),
        ([("remove_robt", {"robot": "tiago2"})], "did you mean 'remove_robot'"),
        ([("remove_robot", {})], "remove_robot needs robot"),
        ([("remove_robot", {"robot": "tiago2", "colour": "red"})], "takes no colour"),
        ([("add_task", {"robot": "tiago1", "task": "delivery_a", "position": "9"})], "position 1 to 3"),
        ([("remove_task", {"task": "delivery_a"}), ("remove_task", {"task": "navigate_home_1"}),
          ("remove_task", {"robot": "tiago2"})], "would allocate no task"),
    ],
)
def test_preconditions_fail_with_clear_errors(base: Scenario, requests: list, words: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(ExsceError, match=words):
        derive(base, requests)


def test_exscec_derive_writes_a_file_that_checks_clean_and_stores_the_generation(in_tmp: Path) -> None:
    shutil.copytree(EXAMPLES / "brsu_building_c", in_tmp / "c")
    made = run_exscec(
        "derive", "c/scenario_c.exsce", "-t", "remove_robot", "--robot", "tiago2", "--reassign", "tiago1",
        "-t", "reverse_waypoint_order", "--task", "delivery_a", "--id", "c_alone", "-o", "c/c_alone.exsce",
        "--add-to-store",
    )
    assert made.returncode == 0, made.stderr
    text = (in_tmp / "c" / "c_alone.exsce").read_text()
    assert text.startswith('import "scenario_c.exsce"\n') and "task delivery_a_reversed {" in text
    assert "tiago1 does delivery_a_reversed then delivery_b then navigate_home_1 then navigate_home_2" in text
    checked = run_exscec("check", "c/c_alone.exsce")
    assert checked.returncode == 0, checked.stdout + checked.stderr
    lineage = run_exscec("query", "derivation", "-p", "scenario=c_alone", "--format", "csv")
    assert lineage.returncode == 0, lineage.stderr
    assert "remove_robot" in lineage.stdout and "reverse_waypoint_order" in lineage.stdout
    again = run_exscec("derive", "c/c_alone.exsce", "-t", "reverse_task_order", "--id", "c_alone_rev",
                       "-o", "c/c_alone_rev.exsce", "--add-to-store")
    assert again.returncode == 0, again.stderr
    tree = run_exscec("lineage", "c_alone")
    assert tree.returncode == 0, tree.stderr
    assert tree.stdout.splitlines() == [
        "scenario_c",
        "  └─ remove_robot(reassign=tiago1 robot=tiago2) → reverse_waypoint_order(task=delivery_a to=delivery_a_reversed)",
        "c_alone  (this one)",
        "  └─ reverse_task_order: c_alone_rev",
    ]
    expected = run_exscec("expect", "c/c_alone.exsce")  # nothing ingested: every segment says so
    assert expected.returncode == 0, expected.stderr
    lines = expected.stdout.splitlines()
    assert lines[0] == "tiago1 distance_travelled: unknown"
    assert lines[1] == "  classroom_c025-w001 → classroom_c018-w001: -  no data, nor for classroom_c025-w002 and classroom_c018-w002 near its ends"
    criteria = run_exscec("derive", "c/scenario_c.exsce", "-t", "reverse_task_order", "--id", "c_expect", "--expect")
    assert criteria.returncode == 0, criteria.stderr  # no runs stored: only the safety clauses are copied
    assert "acceptance for c_expect {" in criteria.stdout and 'scenario "as safe as scenario_c" {' in criteria.stdout
    assert "then each robot max_velocity stays below 1.0 m/s" in criteria.stdout
    assert "0.8 m/s" not in criteria.stdout  # that limit was for a part of a run only
    bad = run_exscec("derive", "c/scenario_c.exsce", "-t", "remove_robot", "--robot", "tiago5")
    assert bad.returncode == 1 and "has no robot 'tiago5'; did you mean" in bad.stderr and "Traceback" not in bad.stderr
