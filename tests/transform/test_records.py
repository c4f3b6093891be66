"""One record per transformation: everything the language, the editors and the docs know of a
transformation comes from its record, and holds for every record (a new one included)."""

from __future__ import annotations

import re
from dataclasses import replace

import pytest

from exsce_dsl.explore.steps import applicable_steps
from exsce_dsl.lang import load_spec
from exsce_dsl.lang.format.derivation import step_text
from exsce_dsl.lang.parser import parse_text
from exsce_dsl.lang.transformation_syntax import step_of, step_rules_by_name
from exsce_dsl.lsp.derive_steps import current_step, next_types, snippet
from exsce_dsl.model import Obstacle, Pose, Position
from exsce_dsl.model.derived import Step
from exsce_dsl.transform.records import (
    TYPES,
    Parameter,
    Slot,
    Transformation,
    Word,
    markdown_table,
    phrase_parts,
    registry,
    variants,
)
from exsce_dsl.transform.transformations import TRANSFORMATIONS

from tests.support.paths import EXAMPLES, ROOT

# An argument of each type, as a step holds it (the parse needs no declarations).
SAMPLES = {
    "robot": "r1",
    "task": "t1",
    "pose": "p1",
    "obstacle": "o1",
    "new_robot": "r9",
    "new_task": "t9",
    "count": "2",
    "position": "1.5,-2.0",
    "allocation": "r1:t1,r1:t2,r2:t3",
}


def _steps_of_every_phrase() -> list[tuple[str, tuple[tuple[str, str], ...]]]:
    """Each way of writing each transformation, with sample arguments."""
    found = []
    for record in TRANSFORMATIONS.values():
        for phrase in record.phrases:
            for variant in variants(phrase_parts(phrase)):
                given = [p.parameter for p in variant if isinstance(p, Slot)]
                arguments = tuple(sorted((name, SAMPLES[record.type_of(name)]) for name in given))
                found.append((record.name, arguments))
    return found


def test_every_type_has_a_sample() -> None:
    assert SAMPLES.keys() == TYPES.keys()


@pytest.mark.parametrize(("name", "arguments"), _steps_of_every_phrase())
def test_every_phrase_formats_and_parses_back_to_its_step(
    name: str, arguments: tuple[tuple[str, str], ...]
) -> None:
    lines = step_text(Step(name, arguments))
    text = "derive d from s {\n  " + "\n  ".join(lines) + "\n}\n"
    (step,) = parse_text(text, "steps.exsce").tree.declarations[0].steps
    parsed, parsed_arguments = step_of(step)
    assert parsed == name
    assert sorted((k, v) for k, v in parsed_arguments.items() if v is not None) == list(arguments)


def test_the_grammar_has_one_rule_per_phrase() -> None:
    assert [r.record.name for r in step_rules_by_name().values()] == [
        r.name for r in TRANSFORMATIONS.values() for _ in r.phrases
    ]


def test_every_record_is_completed_as_a_snippet_of_its_required_arguments() -> None:
    for record in TRANSFORMATIONS.values():
        written, plain = snippet(record)
        assert written.startswith(plain.rstrip(" {")) and written.count("${") >= len(record.required)


def test_completion_offers_the_type_of_the_next_argument_of_every_phrase() -> None:
    for record in TRANSFORMATIONS.values():
        for phrase in record.phrases:
            words: list[str] = []
            for part in phrase_parts(phrase):
                if not isinstance(part, Word):
                    break
                words.append(part.text)
            first = next((p for p in phrase_parts(phrase) if isinstance(p, Slot)), None)
            if first is None:
                continue
            kind = record.type_of(first.parameter)
            before = ["derive", "d", "from", "s", "{", *words]
            assert kind in next_types(current_step(before)), (record.name, phrase)


def test_the_docs_table_is_the_records() -> None:
    page = (ROOT / "docs" / "deriving.md").read_text(encoding="utf-8")
    found = re.search(
        r"<!-- transformations:[^\n]*-->\n(.*?)<!-- end of transformations -->", page, re.DOTALL
    )
    assert found is not None, "docs/deriving.md lost its table of transformations"
    assert found.group(1) == markdown_table(TRANSFORMATIONS), (
        "write the table of exsce_dsl.transform.records.markdown_table(TRANSFORMATIONS) into docs/deriving.md"
    )


def test_no_transformation_is_named_in_the_code_of_the_language_or_the_editors() -> None:
    """No per-transformation branch: lang/ and lsp/ know transformations by their records only."""
    package = ROOT / "src" / "exsce_dsl"
    sources = [*(package / "lang").rglob("*.py"), *(package / "lsp").rglob("*.py")]
    for path in sources:
        text = path.read_text(encoding="utf-8")
        for name in TRANSFORMATIONS:
            assert f'"{name}"' not in text and f"'{name}'" not in text, (path, name)


def test_every_recorded_step_has_the_shape_its_record_says() -> None:
    """The PROV of a generation: each step's parameters are those its record declares."""
    spec = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    scenario_c = spec.scenario("scenario_c")
    crate = Obstacle("crate", Pose("crate", Position(1.0, 4.0)))  # scenario_c has no obstacle to move
    base = replace(scenario_c, environment=replace(scenario_c.environment, obstacles=(crate,)))
    tasks = {t.id: t for t in spec.tasks}
    seen = set()
    for proposed in applicable_steps(base, tasks):
        seen.add(proposed.name)
        for step in proposed.applied.steps:
            assert {k for k, _ in step.parameters} <= set(TRANSFORMATIONS[step.transformation].records), step
    # scenario_c's robots all start somewhere and have tasks (no add_start_pose, remove_start_pose)
    assert seen >= {
        "add_task", "remove_task", "substitute_task", "swap_assignment", "reverse_task_order",
        "reverse_waypoint_order", "swap_start_poses", "move_obstacle", "substitute_allocation",
        "remove_robot", "add_robot", "replace_robot",
    }  # fmt: skip


def _record(**changes: object) -> Transformation:
    base = TRANSFORMATIONS["remove_robot"]
    return replace(base, **changes)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "record",
    [
        _record(phrases=("remove robot {robot} [reassign to {heir}]",)),  # a parameter it does not have
        _record(phrases=("remove robot {robot}",)),  # reassign written by no phrase
        _record(parameters=(Parameter("robot", "android"), Parameter("reassign", "robot", False))),
    ],
)
def test_a_record_that_does_not_hold_together_is_refused(record: Transformation) -> None:
    with pytest.raises(ValueError, match="remove_robot"):
        registry((record,))


def test_two_records_of_one_name_are_refused() -> None:
    record = TRANSFORMATIONS["remove_robot"]
    with pytest.raises(ValueError, match="two transformations"):
        registry((record,), (record,))
