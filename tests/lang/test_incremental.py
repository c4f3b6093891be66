"""Declaration-by-declaration parsing (lang.incremental), what the language server parses with:
the same model at the same places as a whole parse, and only what an edit touched re-parsed."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from exsce_dsl.lang import ParseCache, continuations_at, declaration_chunks
from exsce_dsl.lang.builders.specification import analyse, analyse_files
from exsce_dsl.lang.loader import load_files, parse_whole

from tests.support.paths import EXAMPLES

SPECS = sorted(EXAMPLES.rglob("*.exsce"))


def locations(obj: Any, path: str = "") -> list[tuple[str, Any]]:
    """Every source location in a model (they do not take part in equality)."""
    found: list[tuple[str, Any]] = []
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            value = getattr(obj, f.name)
            if f.name == "location":
                found.append((path, value))
            else:
                found.extend(locations(value, f"{path}.{f.name}"))
    elif isinstance(obj, (tuple, list)):
        for i, value in enumerate(obj):
            found.extend(locations(value, f"{path}[{i}]"))
    return found


def environment_text(areas: int, poses: int) -> str:
    lines = ["environment big {", "  map big"]
    for a in range(areas):
        lines.append(f"  area room_{a:02d} {{")
        lines += [f"    pose room_{a:02d}-w{p:02d} at ({a}.5, {p}.25) facing 0.5" for p in range(poses)]
        lines.append("  }")
    lines.append("  obstacle crate at (1.0, 1.0)")
    return "\n".join(lines) + "\n}\n"


@pytest.mark.parametrize("spec", SPECS, ids=lambda p: p.name)
def test_parsing_by_declaration_builds_the_same_model_at_the_same_places(spec: Path) -> None:
    whole = analyse(spec)
    files, problems = load_files(spec, parse=ParseCache().parse)
    pieces = analyse_files(files, problems)
    assert pieces.diagnostics == whole.diagnostics
    assert pieces.spec == whole.spec
    assert locations(pieces.spec) == locations(whole.spec)


def test_a_long_environment_parsed_area_by_area_is_the_same(tmp_path: Path) -> None:
    text = environment_text(20, 12)
    assert len(text) > 4000  # long enough to be cut into areas
    (tmp_path / "env.exsce").write_text(text)
    whole = analyse(tmp_path / "env.exsce")
    files, problems = load_files(tmp_path / "env.exsce", parse=ParseCache().parse)
    pieces = analyse_files(files, problems)
    assert pieces.spec == whole.spec and pieces.spec is not None
    assert locations(pieces.spec) == locations(whole.spec)


def test_an_edit_reparses_only_what_changed_and_moves_the_rest() -> None:
    cache = ParseCache()
    text = (EXAMPLES / "brsu_building_c" / "tasks" / "deliveries.exsce").read_text()
    before, _ = cache.parse(text, "d.exsce")
    assert before is not None
    last = before.tree.declarations[-1]
    edited = text.replace("task delivery_a {", "// a comment of four lines\n//\n//\n//\ntask delivery_a {")
    after, errors = cache.parse(edited, "d.exsce")
    assert after is not None and errors == ()
    assert after.tree.declarations[-1] is last  # the same object, not parsed again
    assert after.span(last.subtasks[0].visits[0].waypoints[0].pose).line == 24 + 4  # four lines down
    fresh, _ = parse_whole(edited, "d.exsce")
    assert fresh is not None
    assert [after.span(d) for d in after.tree.declarations] == [
        fresh.span(d) for d in fresh.tree.declarations
    ]


def test_a_syntax_error_leaves_the_other_declarations_parsed() -> None:
    text = "task a {\n  visit p1\n}\ntask b {\n  visit p2 facing\n}\ntask c {\n  visit ,\n}\ntask d { visit p4 }\n"
    pf, errors = ParseCache().parse(text, "t.exsce")
    assert pf is not None
    assert [d.name for d in pf.tree.declarations] == ["a", "d"]
    assert [(e.location.line, e.location.column) for e in errors if e.location] == [(6, 1), (8, 9)]
    (first,) = parse_whole(text, "t.exsce")[1]
    assert first == errors[0]  # the first error is the one textX reports for the whole file


def test_a_declaration_left_open_does_not_hide_those_after_it() -> None:
    text = "task a {\n  visit p1\n\ntask b {\n  visit p2\n}\n\nscenario s in e {\n  robots { }\n}\n"
    pf, errors = ParseCache().parse(text, "t.exsce")
    assert pf is not None
    assert [d.name for d in pf.tree.declarations] == ["b", "s"]
    assert [(e.location.line, e.location.column) for e in errors if e.location] == [(4, 1)]
    assert errors[0].message == "expected 'facing', 'rpy', ',', 'visit' or '}', found 'task'"
    assert errors[0] == parse_whole(text, "t.exsce")[1][0]


def test_an_error_in_one_area_of_a_long_environment_keeps_the_others() -> None:
    text = environment_text(20, 12).replace(
        "pose room_07-w03 at (7.5, 3.25)", "pose room_07-w03 at (7.5 3.25)"
    )
    pf, errors = ParseCache().parse(text, "e.exsce")
    assert pf is not None
    (environment,) = pf.tree.declarations
    areas = [m.name for m in environment.members if m.__class__.__name__ == "Area"]
    assert len(areas) == 19 and "room_07" not in areas
    (error,) = errors
    assert error.location is not None and (error.location.line, error.location.column) == (105, 30)
    assert error == parse_whole(text, "e.exsce")[1][0]


def test_typing_a_file_from_its_start_reports_what_the_whole_parse_reports() -> None:
    """At every prefix of scenario_c, the first syntax error is textX's own, at its place."""
    text = (EXAMPLES / "brsu_building_c" / "scenario_c.exsce").read_text()
    cache = ParseCache()
    for end in range(0, len(text) + 1, 5):
        prefix = text[:end]
        _, errors = cache.parse(prefix, "s.exsce")
        whole_errors = parse_whole(prefix, "s.exsce")[1]
        assert bool(errors) == bool(whole_errors), prefix
        if errors:
            assert errors[0] == whole_errors[0], prefix


def test_declarations_start_only_after_a_closed_one() -> None:
    text = 'import "a.exsce"\nmetric m for each robot { value elapsed }\nrobot type t { }\n'
    chunks = declaration_chunks(text)
    assert [(c.keyword, text[c.start : c.end].split()[0]) for c in chunks] == [
        (None, "import"),
        ("metric", "metric"),
        ("robot", "robot"),
    ]


def test_completion_in_a_long_environment_parses_only_the_area_it_is_in() -> None:
    text = environment_text(30, 12)
    at = text.index("    pose room_25-w04")
    expected = continuations_at(text, at)
    assert expected is not None
    assert expected.keywords == ("pose",) and expected.declaration == "environment"
    assert expected.before[:8] == ("environment", "big", "{", "map", "big", "area", "room_25", "{")
    assert "room_24" not in expected.before  # the areas before are left out
    assert expected.before[-1] == "0.5" and expected.before.count("pose") == 4


_WORDS = ["task", "}", "{", "visit", ",", "scenario", "robot type", '"', "//", "area", "import", "(", "at"]


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    spec=st.sampled_from([p for p in SPECS if p.stat().st_size < 4000]),
    at=st.floats(0, 1),
    length=st.integers(0, 12),
    word=st.sampled_from(["", *_WORDS]),
)
def test_a_mutated_file_gives_textx_s_first_error_or_the_same_declarations(
    spec: Path, at: float, length: int, word: str
) -> None:
    text = spec.read_text()
    start = int(at * len(text))
    mutated = text[:start] + word + text[start + length :]
    whole, whole_errors = parse_whole(mutated, "m.exsce")
    pieces, errors = ParseCache().parse(mutated, "m.exsce")
    if whole is not None:
        assert errors == () and pieces is not None
        assert [d.__class__.__name__ for d in pieces.tree.declarations] == [
            d.__class__.__name__ for d in whole.tree.declarations
        ]
        assert [pieces.span(d) for d in pieces.tree.declarations] == [
            whole.span(d) for d in whole.tree.declarations
        ]
    else:
        assert errors and errors[0] == whole_errors[0], mutated
