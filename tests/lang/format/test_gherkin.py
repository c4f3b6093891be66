"""Acceptance criteria as Gherkin: what Cucumber's own parser reads in the export."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from gherkin.parser import Parser

from exsce_dsl.errors import ExportError
from exsce_dsl.lang import load_spec
from exsce_dsl.lang.format.gherkin import export_gherkin, gherkin_features
from exsce_dsl.model.acceptance import (
    Acceptance,
    AtStartPose,
    BasicRelation,
    Criterion,
    Expectation,
    Quantifier,
    Quantity,
    Subject,
    When,
)

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"

# The example's criteria, step by step, as a BDD tool reads them.
EXPECTED = {
    "moves safely": [
        ("Given ", "each robot is at its start pose"),
        ("When ", "mission mission_c runs"),
        ("Then ", "each robot max_velocity stays below 1.0 m/s"),
        ("And ", "each robot distance_to_obstacles stays above 0.1 m"),
        ("And ", "distance_between_robots stays above 0.1 m"),
    ],
    "performs as before": [
        ("Given ", "at least 3 baseline runs are stored"),
        ("When ", "mission mission_c runs"),
        ("Then ", "each robot task_duration is invariant within 3 std"),
        ("And ", "each robot distance_travelled is invariant within 5 %"),
        ("And ", "each robot waypoints_visited is invariant within 0"),
        ("And ", "mission_duration is invariant within 10 s"),
    ],
    "delivers gently": [
        ("When ", "tiago1 does delivery_a"),
        ("Then ", "tiago1 max_velocity stays below 0.8 m/s"),
    ],
    "drives calmly": [
        ("When ", "mission mission_c runs"),
        ("Then ", "each robot fast_driving_time stays below 2 s"),
        ("And ", "each robot mean_turn_rate stays below 0.5 rad/s"),
    ],
}


def parsed(text: str) -> Any:
    """The feature of a .feature text, as Cucumber's parser reads it."""
    return Parser().parse(text)["feature"]


def steps(feature: dict[str, Any]) -> dict[str, list[tuple[str, str]]]:
    return {
        child["scenario"]["name"]: [(step["keyword"], step["text"]) for step in child["scenario"]["steps"]]
        for child in feature["children"]
    }


def test_the_example_criteria_read_as_gherkin() -> None:
    spec = load_spec(SCENARIO_C)
    acceptance = spec.acceptance_of("scenario_c")
    assert acceptance is not None
    feature = parsed(gherkin_features(acceptance, spec.scenario("scenario_c")))
    assert feature["keyword"] == "Feature"
    assert feature["name"] == "Acceptance of scenario_c"
    assert feature["description"].strip() == (
        "What every run of mission mission_c with robots tiago1, tiago2 must show."
    )
    assert steps(feature) == EXPECTED


def test_a_title_and_several_givens_stay_one_line_each() -> None:
    spec = load_spec(SCENARIO_C)
    criterion = Criterion(
        'two\nlines and a "quote"',
        (AtStartPose(Subject(Quantifier.ROBOT, "tiago1")), AtStartPose(Subject(Quantifier.ROBOT, "tiago2"))),
        When(robot="tiago2", task="delivery_b"),
        (Expectation(Subject(Quantifier.MISSION), "mission_duration", BasicRelation.INVARIANT,
                     value=Quantity(97.606, "s", "97.606")),),
    )
    text = gherkin_features(Acceptance("scenario_c", (criterion,)), spec.scenario("scenario_c"))
    assert steps(parsed(text)) == {
        'two lines and a "quote"': [
            ("Given ", "tiago1 is at its start pose"),
            ("And ", "tiago2 is at its start pose"),
            ("When ", "tiago2 does delivery_b"),
            ("Then ", "mission_duration is invariant around 97.606 s"),
        ]
    }


def test_a_spec_without_criteria_has_no_features(tmp_path: Path) -> None:
    with pytest.raises(ExportError, match="has no acceptance criteria"):
        export_gherkin(load_spec(EXAMPLES / "brsu_building_c" / "scenario_b.exsce"), tmp_path)
    assert not list(tmp_path.iterdir())


def test_cli_writes_one_feature_per_scenario_with_criteria(tmp_path: Path) -> None:
    result = exscec_here("export", str(SCENARIO_C), "--to", "gherkin", "-o", str(tmp_path / "features"))
    assert result.returncode == 0, result.stderr
    assert [p.name for p in (tmp_path / "features").iterdir()] == ["scenario_c.feature"]
    feature = parsed((tmp_path / "features" / "scenario_c.feature").read_text())
    assert steps(feature) == EXPECTED
