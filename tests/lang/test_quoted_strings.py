"""Quoted strings: a backslash escapes the character after it, so a string may end in a backslash
(``"\\\\"``) and another string may follow it on the same line.  textX's own STRING read ``"\\\\"``
as an escaped quote and ran on to the next one; the grammar's ``Quoted`` does not."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from hypothesis import given
from hypothesis import strategies as st

from exsce_dsl.lang import expression_text, load_spec
from exsce_dsl.lang.lexical import string_literal, string_value
from exsce_dsl.model.messages import Select

METRIC = """metric m for each robot {{
  {meaning}
  reads diag: actionlib_msgs/msg/GoalStatusArray on "/{{ns}}/status"
  value {value}
}}
"""


@given(st.text())
def test_a_string_literal_reads_back_to_its_text(text: str) -> None:
    assert string_value(string_literal(text)) == text


def test_a_selection_by_any_text_prints_back(tmp_path: Path) -> None:
    """Accents and other non-ASCII characters too (they are written as they are, not as \\u escapes)."""
    for text in ("é", "a\\", 'x"y', "tab\there", "日本"):
        written = f"min(diag.status_list[goal_id.id == {string_literal(text)}].status)"
        spec = tmp_path / "m.exsce"
        spec.write_text(METRIC.format(meaning="", value=written), encoding="utf-8")
        (metric,) = load_spec(spec).metrics
        assert [s.value for s in _selections(metric.value)] == [text]
        assert expression_text(metric.value) == written


def test_a_backslash_before_another_character_stays_as_written() -> None:
    assert string_value(r'"\d+"') == "\\d+"
    assert string_value(r"'it\'s'") == "it's"


def test_two_selections_by_a_text_ending_in_a_backslash_parse_and_print_back(tmp_path: Path) -> None:
    """Also a metric's meaning: a backslash and quotes in it, read as written."""
    written = 'min(diag.status_list[goal_id.id == "\\\\"].status) - max(diag.status_list[goal_id.id == "a\\"b"].status)'
    spec = tmp_path / "m.exsce"
    spec.write_text(METRIC.format(meaning='"C:\\\\runs \\"last\\""', value=written))
    (metric,) = load_spec(spec).metrics
    assert metric.meaning == 'C:\\runs "last"'
    selected = [s.value for s in _selections(metric.value)]
    assert selected == ["\\", 'a"b']
    assert expression_text(metric.value) == written


def _selections(value: Any) -> list[Select]:
    """Every selection in an expression, in the order written."""
    if isinstance(value, Select):
        return [value]
    if isinstance(value, list | tuple):
        return [s for item in value for s in _selections(item)]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return [s for f in dataclasses.fields(value) for s in _selections(getattr(value, f.name))]
    return []
