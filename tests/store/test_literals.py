"""One form for each value, whatever the store wrote: the lexical forms Oxigraph and Virtuoso give
for the same values (seen in tests/store/test_same_answers.py) print alike, and read back as the
same Python values."""

from __future__ import annotations

import datetime

import pytest
from pyoxigraph import Literal, NamedNode

from exsce_dsl.store.base import Rows
from exsce_dsl.store.literals import (
    canonical_literal,
    canonical_rows,
    literal_text,
    literal_value,
    number_text,
)

XSD = "http://www.w3.org/2001/XMLSchema#"


def typed(text: str, local: str) -> Literal:
    return Literal(text, datatype=NamedNode(XSD + local))


@pytest.mark.parametrize(
    ("oxigraph", "virtuoso", "printed"),
    [
        (typed("2026-01-04T01:02:04.62Z", "dateTime"), typed("2026-01-04T01:02:04.620Z", "dateTime"),
         "2026-01-04T01:02:04.620Z"),
        (typed("2026-01-04T01:02:04Z", "dateTime"), typed("2026-01-04T03:02:04.000+02:00", "dateTime"),
         "2026-01-04T01:02:04.000Z"),
        (typed("2026-01-04T01:02:04.123456Z", "dateTime"), typed("2026-01-04T01:02:04.1234567Z", "dateTime"),
         "2026-01-04T01:02:04.123456Z"),
        (typed("0", "double"), typed("0.0", "double"), "0"),
        (typed("1.5E0", "double"), typed("1.5", "decimal"), "1.5"),
        (typed("26.71333332856496", "double"), typed("26.713333328564964", "double"), "26.713333328565"),
        (typed("7", "integer"), typed("7", "int"), "7"),
        (typed("0", "integer"), typed("0.0", "int"), "0"),
        (typed("true", "boolean"), typed("1", "boolean"), "true"),
        (typed("1.0E-7", "double"), typed("0.0000001", "decimal"), "1e-07"),
    ],
)  # fmt: skip
def test_a_value_prints_alike_whatever_the_stores_lexical_form(
    oxigraph: Literal, virtuoso: Literal, printed: str
) -> None:
    assert literal_text(oxigraph) == literal_text(virtuoso) == printed


def test_numbers_have_one_type_and_read_back_exactly() -> None:
    assert canonical_literal(typed("7", "decimal")) == typed("7.0", "double")
    assert canonical_literal(typed("0.0", "int")) == typed("0", "integer")
    assert canonical_literal(typed("12.345678901234567", "double")).value == "12.345678901234567"
    assert literal_value(typed("12.345678901234567", "double")) == 12.345678901234567  # all 17 digits
    assert literal_value(typed("0.0", "int")) == 0 and isinstance(literal_value(typed("0.0", "int")), int)
    assert literal_value(typed("1", "boolean")) is True


def test_a_date_time_reads_back_aware_of_its_zone() -> None:
    moment = literal_value(typed("2026-01-04T03:02:04.5+02:00", "dateTime"))
    assert moment == datetime.datetime(2026, 1, 4, 1, 2, 4, 500000, tzinfo=datetime.timezone.utc)
    assert isinstance(moment, datetime.datetime) and moment.tzinfo is not None
    naive = literal_value(typed("2026-01-04T01:02:04", "dateTime"))
    assert isinstance(naive, datetime.datetime) and naive.tzinfo is None
    assert literal_text(typed("2026-01-04T01:02:04", "dateTime")) == "2026-01-04T01:02:04.000"  # no zone made up


def test_what_is_not_a_number_is_left_as_written() -> None:
    assert literal_text(typed("seven", "double")) == "seven"
    assert literal_text(Literal("7")) == "7" and literal_text(Literal("7.0", language="en")) == "7.0"
    assert [number_text(x) for x in (float("nan"), float("inf"), -float("inf"), -0.0)] == ["NaN", "INF", "-INF", "0"]
    rows = canonical_rows(Rows(("n",), ((typed("3", "long"),), (None,))))
    assert rows.rows == ((typed("3", "integer"),), (None,))
