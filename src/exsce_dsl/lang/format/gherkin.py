"""Acceptance criteria as Gherkin, for the BDD tools that read ``.feature`` files.

One ``Feature`` per scenario, one Gherkin ``Scenario`` per criterion, its givens as
``Given``/``And`` steps, its *when* as ``When`` and its clauses as ``Then``/``And``,
worded as in the DSL (:func:`exsce_dsl.lang.format.acceptance.expectation_text`).
A step is one line of text, so titles and ids are written on one line.
"""

from __future__ import annotations

from pathlib import Path

from exsce_dsl.errors import ExportError
from exsce_dsl.lang.format.acceptance import expectation_text
from exsce_dsl.model import Scenario, Specification
from exsce_dsl.model.acceptance import Acceptance, BaselineRuns, Criterion, Given, When
from exsce_dsl.model.names import is_valid_name

INDENT = "  "


def gherkin_features(acceptance: Acceptance, scenario: Scenario) -> str:
    """The ``.feature`` text of the acceptance criteria of ``scenario``."""
    robots = ", ".join(r.id for r in scenario.robots)
    lines = [
        f"Feature: Acceptance of {scenario.id}",
        f"{INDENT}What every run of mission {scenario.mission.id} with robots {robots} must show.",
    ]
    for criterion in acceptance.criteria:
        lines += ["", *_scenario(criterion)]
    return "\n".join(lines) + "\n"


def export_gherkin(spec: Specification, out_dir: Path, scenario_id: str | None = None) -> list[Path]:
    """Write ``<scenario>.feature`` under ``out_dir`` for each scenario of ``spec`` with
    acceptance criteria (or for ``scenario_id`` alone); return the files written."""
    scenarios = [spec.scenario(scenario_id)] if scenario_id is not None else list(spec.scenarios)
    features = [(s, a) for s in scenarios if (a := spec.acceptance_of(s.id)) is not None]
    if not features:
        whose = f"scenario '{scenario_id}'" if scenario_id is not None else spec.root
        raise ExportError(f"{whose} has no acceptance criteria: there is nothing to write as Gherkin")
    for scenario, _ in features:
        if not is_valid_name(scenario.id):  # the id becomes a file name
            raise ExportError(f"scenario id '{scenario.id}' is not a valid exsce id", scenario.location)
    written = []
    out_dir.mkdir(parents=True, exist_ok=True)
    for scenario, acceptance in features:
        target = out_dir / f"{scenario.id}.feature"
        target.write_text(gherkin_features(acceptance, scenario), encoding="utf-8")
        written.append(target)
    return written


def _scenario(criterion: Criterion) -> list[str]:
    steps = [("Given", _given(g)) for g in criterion.givens]
    if criterion.when is not None:
        steps.append(("When", _when(criterion.when)))
    steps += [("Then", expectation_text(e)) for e in criterion.expectations]
    lines = [f"{INDENT}Scenario: {_one_line(criterion.title)}"]
    previous = None
    for keyword, text in steps:
        lines.append(f"{INDENT * 2}{'And' if keyword == previous else keyword} {_one_line(text)}")
        previous = keyword
    return lines


def _given(given: Given) -> str:
    if isinstance(given, BaselineRuns):
        return f"at least {given.runs} baseline runs are stored"
    return f"{given.subject.text()} is at its start pose"


def _when(when: When) -> str:
    return f"mission {when.mission} runs" if when.mission else when.text()


def _one_line(text: str) -> str:
    """Gherkin reads a name or a step up to the end of its line."""
    return " ".join(text.split())
