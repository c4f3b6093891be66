"""``is invariant at 99 %``: a confidence instead of a tolerance, what it builds to, where its
mistakes are reported (file:line:col), and that the formatter prints it back."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.errors import ExportError
from exsce_dsl.lang import analyse, export_oracle_yaml, format_spec_document, load_spec
from exsce_dsl.lang.format.gherkin import gherkin_features
from exsce_dsl.model.acceptance import BasicRelation, Quantity

from tests.support.map_files import write_map

SPEC = """\
robot type tiago {
  base pmb2
  torso yes
}

environment env1 {
  map env1 file "map.yaml"
  area room {
    pose room-p1 at (1.0, 1.0)
    pose room-p2 at (2.0, 1.0)
    pose room-p3 at (3.0, 3.0)
  }
}

task go_p3 {
  visit room-p3
}

scenario s1 in env1 {
  robots {
    r1: tiago starts at room-p1
  }
  mission m1 sequential {
    r1 does go_p3
  }
}

scenario s2 in env1 {
  robots {
    r1: tiago starts at room-p2
  }
  mission m2 sequential {
    r1 does go_p3
  }
}

acceptance for s2 {
  scenario "as before" {
    given at least 10 baseline runs
    when m2 runs
    then mission_duration is invariant at 99 %
     and r1 distance_travelled is invariant at 95.5 % of s1
     and r1 task_duration is invariant within 1 std
  }
}
"""
LINE = SPEC.splitlines().index("    then mission_duration is invariant at 99 %") + 1


@pytest.fixture
def spec_folder(in_tmp: Path) -> Path:
    write_map(in_tmp, occupied=(80, 80, 90, 90))
    (in_tmp / "spec.exsce").write_text(SPEC)
    return in_tmp


def test_a_confidence_builds_to_a_per_cent_and_no_tolerance(spec_folder: Path) -> None:
    acceptance = load_spec("spec.exsce").acceptance_of("s2")
    assert acceptance is not None
    mission, distance, duration = acceptance.criteria[0].expectations
    assert mission.relation is BasicRelation.INVARIANT
    assert (mission.confidence, mission.tolerance, mission.against) == (Quantity(99.0, "%"), None, None)
    assert mission.confidence_level == pytest.approx(0.99)
    assert (distance.confidence, distance.against) == (Quantity(95.5, "%"), "s1")
    assert (duration.confidence, duration.confidence_level) == (None, None)


def test_the_formatter_and_gherkin_print_the_confidence_back(spec_folder: Path) -> None:
    spec = load_spec("spec.exsce")
    text = format_spec_document(spec)
    assert "    then mission_duration is invariant at 99 %\n" in text
    assert "     and r1 distance_travelled is invariant at 95.5 % of s1\n" in text
    (spec_folder / "again.exsce").write_text(text)
    assert load_spec("again.exsce").acceptance == spec.acceptance
    acceptance = spec.acceptance_of("s2")
    assert acceptance is not None
    assert "Then mission_duration is invariant at 99 %" in gherkin_features(acceptance, spec.scenario("s2"))


# (id, replacement of "mission_duration is invariant at 99 %", column of its "at", words the message
# must hold): counted by hand, the clause starts at column 10
MISTAKES = [
    (
        "hundred",
        "mission_duration is invariant at 100 %",
        40,
        "between 50 % and 100 % (exclusive), not '100 %'",
    ),
    ("fifty", "mission_duration is invariant at 50 %", 40, "between 50 % and 100 % (exclusive), not '50 %'"),
    ("tiny", "mission_duration is invariant at 0.99 %", 40, "between 50 % and 100 % (exclusive)"),
    ("fraction", "mission_duration is invariant at 0.99", 40, "a confidence is in per cent ('at 99 %')"),
    ("std", "mission_duration is invariant at 2 std", 40, "a confidence is in per cent"),
    (
        "around",
        "mission_duration is invariant around 60 s at 99 %",
        52,
        "around a fixed value write a tolerance",
    ),
    (
        "increasing",
        "mission_duration is increasing by 2 s at 99 % of s1",
        48,
        "'at 99 %' is for 'is invariant'",
    ),
    (
        "decreasing",
        "mission_duration is decreasing from 1 min at 95 %",
        52,
        "'at 95 %' is for 'is invariant'",
    ),
]


@pytest.mark.parametrize("case", MISTAKES, ids=[c[0] for c in MISTAKES])
def test_a_bad_confidence_is_reported_at_its_line_and_column(spec_folder: Path, case: tuple) -> None:  # type: ignore[type-arg]
    _, new, column, words = case
    (spec_folder / "spec.exsce").write_text(SPEC.replace("mission_duration is invariant at 99 %", new, 1))
    analysis = analyse("spec.exsce")
    found = [(d.location, d.message) for d in analysis.errors]
    at = [m for loc, m in found if loc is not None and (loc.line, loc.column) == (LINE, column)]
    assert analysis.spec is None
    assert any(words in m for m in at), f"wanted {words!r} at {LINE}:{column}, got {found}"


def test_within_and_at_together_are_a_syntax_error(spec_folder: Path) -> None:
    text = SPEC.replace("invariant at 99 %", "invariant within 2 s at 99 %", 1)
    (spec_folder / "spec.exsce").write_text(text)
    analysis = analyse("spec.exsce")
    assert analysis.spec is None and analysis.errors
    assert analysis.errors[0].location is not None and analysis.errors[0].location.line == LINE


def test_the_methods_oracle_file_cannot_hold_a_confidence(spec_folder: Path) -> None:
    spec = load_spec("spec.exsce")
    acceptance = spec.acceptance_of("s2")
    assert acceptance is not None
    baseline = {("mission_duration", None): (60.0, 2.0)}
    with pytest.raises(ExportError) as raised:
        export_oracle_yaml(acceptance, spec.scenario("s2"), baseline)
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.location is not None and diagnostic.location.line == LINE
    assert diagnostic.message.startswith(
        "'mission_duration is invariant at 99 %' takes its tolerance from the baseline's runs at a confidence"
    )
