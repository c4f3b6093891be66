"""What only the language server uses of the language (lang.editor): the index of names and
references with their places (symbols), and what the grammar expects at a point (continuations)."""

from __future__ import annotations

import pytest

from exsce_dsl.lang import continuations_at
from exsce_dsl.lang.editor.symbols import index_file
from exsce_dsl.lang.loader import parse_whole

from tests.support.paths import EXAMPLES


def test_the_index_holds_declarations_and_references_with_places() -> None:
    path = EXAMPLES / "brsu_building_c" / "scenario_c_alone.exsce"
    pf, _ = parse_whole(path.read_text(), "alone.exsce")
    assert pf is not None
    index = index_file(pf)
    (derived,) = index.symbols
    assert (derived.kind, derived.name, derived.fact("derived from")) == (
        "scenario",
        "scenario_c_alone",
        "scenario_c",
    )
    assert [(r.kind, r.name, r.scope, r.location.line, r.location.column) for r in index.references] == [
        ("scenario", "scenario_c", None, 5, 30),
        ("task", "delivery_a", None, 7, 24),
        ("robot", "tiago2", "scenario_c_alone", 6, 16),
        ("robot", "tiago1", "scenario_c_alone", 6, 35),
    ]


@pytest.mark.parametrize(
    ("text", "keywords", "name"),
    [
        ("", {"import", "task", "scenario", "environment", "robot", "metric", "derive", "acceptance"}, False),
        ("task t {\n  visit ", set(), True),
        ("scenario s in e {\n  robots {\n    r1: tiago ", {"namespace", "starts"}, True),
        (
            "derive d from s {\n  ",
            {"remove", "add", "replace", "swap", "reverse", "substitute", "start"},
            False,
        ),
        ('acceptance for s {\n  scenario "x" {\n    then each robot max_velocity ', {"stays", "is"}, False),
    ],
)
def test_what_the_grammar_expects_at_the_end(text: str, keywords: set[str], name: bool) -> None:
    expected = continuations_at(text, len(text))
    assert expected is not None and expected.known
    assert keywords <= set(expected.keywords)
    assert expected.name is name


def test_nothing_is_expected_inside_a_comment_or_a_string() -> None:
    assert continuations_at("task t { // visit ", 18) is None
    assert continuations_at('acceptance for s { scenario "moves sa', 37) is None
