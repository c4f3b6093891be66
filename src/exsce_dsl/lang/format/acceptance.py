"""The canonical text of acceptance criteria (the formatter's part for ``acceptance`` blocks)."""

from __future__ import annotations

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.acceptance import (
    Acceptance,
    AtStartPose,
    BaselineRuns,
    BasicRelation,
    Criterion,
    Expectation,
    Given,
    Quantity,
)
from exsce_dsl.model.metrics import UNITS

INDENT = "  "
Line = tuple[str, SourceLocation | None]


def acceptance_lines(acceptance: Acceptance) -> list[Line]:
    lines: list[Line] = [(f"acceptance for {acceptance.scenario} {{", acceptance.location)]
    for criterion in acceptance.criteria:
        lines.extend(_criterion(criterion))
    lines.append(("}", None))
    return lines


def _criterion(criterion: Criterion) -> list[Line]:
    title = '"' + criterion.title.replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines: list[Line] = [(f"{INDENT}scenario {title} {{", criterion.location)]
    inner = INDENT * 2
    for given in criterion.givens:
        lines.append((f"{inner}given {given_text(given)}", given.location))
    if criterion.when is not None:
        lines.append((f"{inner}when {criterion.when.text()}", criterion.when.location))
    for number, expectation in enumerate(criterion.expectations):
        word = "then" if number == 0 else " and"
        lines.append((f"{inner}{word} {expectation_text(expectation)}", expectation.location))
    lines.append((f"{INDENT}}}", None))
    return lines


def given_text(given: Given) -> str:
    if isinstance(given, BaselineRuns):
        return f"at least {given.runs} baseline runs"
    assert isinstance(given, AtStartPose)
    return f"{given.subject.text()} at its start pose"


def expectation_text(e: Expectation) -> str:
    """``each robot max_velocity stays below 1.0 m/s``: a then clause as written."""
    words = [e.subject.text(), e.metric] if e.subject.text() else [e.metric]
    if e.relation is BasicRelation.BELOW_MAX or e.relation is BasicRelation.ABOVE_MIN:
        assert e.limit is not None
        words += [
            "stays",
            "below" if e.relation is BasicRelation.BELOW_MAX else "above",
            quantity_text(e.limit),
        ]
    else:
        words += ["is", e.relation.value]
        if e.value is not None:
            words += ["around" if e.relation is BasicRelation.INVARIANT else "from", quantity_text(e.value)]
        if e.delta is not None:
            words += ["by", quantity_text(e.delta)]
        if e.tolerance is not None:
            words += ["within", quantity_text(e.tolerance)]
        if e.confidence is not None:
            words += ["at", quantity_text(e.confidence)]
        if e.against is not None:
            words += ["of", e.against]
    if e.window is not None:
        words.append(e.window.text())
    return " ".join(words)


def quantity_text(q: Quantity) -> str:
    """The quantity as written, or (made by an importer) in its unit, shortest."""
    if q.written:
        number = q.written
    else:
        factor = UNITS[q.unit][1] if q.unit in UNITS else 1.0
        number = _shortest(q.value / factor)
    return f"{number} {q.unit}" if q.unit else number


def _shortest(value: float) -> str:
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text
