"""Output relations: the method's basic relations at, inside and outside their bounds, the
registry with its plug-ins, and the complex relations (combined, aggregated)."""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator, Mapping
from pathlib import Path

import pytest

from exsce_dsl.errors import ExsceError, RelationError
from exsce_dsl.oracles import relations
from exsce_dsl.oracles.relations import (
    Judgement,
    Relation,
    aggregate,
    all_of,
    any_of,
    relation,
    relation_names,
)

from tests.support.plugin_packages import installed_plugins

BUILT_IN = ("above_min", "below_max", "decreasing", "increasing", "invariant")

# relation, result, parameters, passed, margin, expected text
CASES = [
    ("below_max", 0.8, {"limit": 1.0}, True, 0.2, "<= 1"),
    ("below_max", 1.0, {"limit": 1.0}, True, 0.0, "<= 1"),
    ("below_max", 1.2, {"limit": 1.0}, False, -0.2, "<= 1"),
    ("above_min", 0.3, {"limit": 0.1}, True, 0.2, ">= 0.1"),
    ("above_min", 0.1, {"limit": 0.1}, True, 0.0, ">= 0.1"),
    ("above_min", 0.05, {"limit": 0.1}, False, -0.05, ">= 0.1"),
    ("invariant", 10, {"value": 12, "tolerance": 3}, True, 1.0, "12 ± 3"),
    ("invariant", 15, {"value": 12, "tolerance": 3}, True, 0.0, "12 ± 3"),
    ("invariant", 16.5, {"value": 12, "tolerance": 3}, False, -1.5, "12 ± 3"),
    ("invariant", 7, {"value": 12, "tolerance": 3}, False, -2.0, "12 ± 3"),
    ("invariant", 12, {"value": 12}, True, 0.0, "12 ± 0"),
    ("invariant", 12.5, {"value": 12}, False, -0.5, "12 ± 0"),
    ("increasing", 15, {"value": 10, "delta": 3, "tolerance": 1}, True, 3.0, ">= 12 (10 + 3 - 1)"),
    ("increasing", 12, {"value": 10, "delta": 3, "tolerance": 1}, True, 0.0, ">= 12 (10 + 3 - 1)"),
    ("increasing", 11, {"value": 10, "delta": 3, "tolerance": 1}, False, -1.0, ">= 12 (10 + 3 - 1)"),
    ("increasing", 12, {"value": 10, "delta": 3}, False, -1.0, ">= 13 (10 + 3)"),
    ("increasing", 10, {"value": 10}, True, 0.0, ">= 10"),
    ("increasing", 9.5, {"value": 10}, False, -0.5, ">= 10"),
    ("decreasing", 6, {"value": 10, "delta": 3, "tolerance": 1}, True, 2.0, "<= 8 (10 - 3 + 1)"),
    ("decreasing", 8, {"value": 10, "delta": 3, "tolerance": 1}, True, 0.0, "<= 8 (10 - 3 + 1)"),
    ("decreasing", 9, {"value": 10, "delta": 3, "tolerance": 1}, False, -1.0, "<= 8 (10 - 3 + 1)"),
    ("decreasing", 10.25, {"value": 10}, False, -0.25, "<= 10"),
]


@pytest.mark.parametrize(("name", "result", "given", "passed", "margin", "expected"), CASES)
def test_basic_relation_judges_with_its_exact_margin(
    name: str, result: float, given: dict[str, float], passed: bool, margin: float, expected: str
) -> None:
    judged = relation(name).judge(result, **given)
    assert judged.passed is passed
    assert math.isclose(judged.margin, margin, abs_tol=1e-12)
    assert judged.expected == expected


def test_parameters_given_as_none_count_as_not_given() -> None:
    judged = relation("increasing").judge(11, value=10, delta=None, tolerance=None)
    assert judged == Judgement(True, 1.0, ">= 10")


@pytest.mark.parametrize(
    ("name", "given"),
    [
        ("below_max", {"limit": 1.0}),
        ("above_min", {"limit": 1.0}),
        ("invariant", {"value": 1.0, "tolerance": 100.0}),
        ("increasing", {"value": 1.0, "tolerance": 100.0}),
        ("decreasing", {"value": 1.0, "tolerance": 100.0}),
    ],
)
def test_a_nan_result_never_passes(name: str, given: dict[str, float]) -> None:
    judged = relation(name).judge(math.nan, **given)
    assert judged.passed is False
    assert math.isnan(judged.margin)
    assert judged.expected == relation(name).judge(0.0, **given).expected


class _Lenient(Relation):
    """A careless relation that passes anything, NaN included."""

    name = "lenient"
    parameters = frozenset({"value"})
    required = frozenset({"value"})

    def compare(self, result: float, given: Mapping[str, float]) -> Judgement:
        return Judgement(True, 1.0, "anything")


def test_no_relation_passes_a_nan_result_not_even_a_careless_one() -> None:
    assert _Lenient().judge(3.0, value=1.0) == Judgement(True, 1.0, "anything")
    judged = _Lenient().judge(math.nan, value=1.0)
    assert judged.passed is False
    assert math.isnan(judged.margin)
    assert judged.expected == "anything"


def test_relations_declare_what_they_take_and_require() -> None:
    assert relation("below_max").parameters == frozenset({"limit"})
    assert relation("below_max").required == frozenset({"limit"})
    assert relation("invariant").parameters == frozenset({"value", "tolerance"})
    assert relation("invariant").required == frozenset({"value"})
    assert relation("increasing").parameters == frozenset({"value", "delta", "tolerance"})
    assert relation("decreasing").required == frozenset({"value"})


@pytest.mark.parametrize(
    ("name", "given", "message"),
    [
        ("below_max", {}, "relation 'below_max' needs a limit"),
        ("invariant", {"tolerance": 1.0}, "relation 'invariant' needs a value"),
        ("increasing", {"delta": 1.0}, "relation 'increasing' needs a value"),
        ("below_max", {"limit": 1.0, "value": 2.0}, "relation 'below_max' takes no value (it takes limit)"),
        ("invariant", {"value": 1.0, "delta": 2.0}, "relation 'invariant' takes no delta"),
        ("above_min", {"limit": 1.0, "tolerance": 0.1}, "relation 'above_min' takes no tolerance"),
    ],
)
def test_missing_and_unknown_parameters_are_named(name: str, given: dict[str, float], message: str) -> None:
    with pytest.raises(RelationError) as raised:
        relation(name).judge(1.0, **given)
    assert message in str(raised.value)
    assert isinstance(raised.value, ExsceError)


def test_the_registry_holds_the_five_built_ins() -> None:
    assert set(BUILT_IN) <= set(relation_names())
    assert list(relation_names()) == sorted(relation_names())


def test_an_unknown_relation_suggests_the_closest_name() -> None:
    with pytest.raises(RelationError, match=r"unknown relation 'below_maxx'; did you mean 'below_max'\?"):
        relation("below_maxx")
    with pytest.raises(RelationError) as raised:
        relation("equal")
    assert str(raised.value) == "error: unknown relation 'equal'"


def test_a_module_name_is_never_imported(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "planted_relation.py").write_text(
        "import pathlib\npathlib.Path(__file__).with_name('ran').touch()\nbelow_max = None\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("planted_relation", "planted_relation:below_max", "planted_relation.below_max"):
        with pytest.raises(RelationError):
            relation(name)
    assert not (tmp_path / "ran").exists()
    assert "planted_relation" not in sys.modules


PLUGIN = '''\
from collections.abc import Mapping

from exsce_dsl.oracles.relations import Judgement, Relation


class WithinPercent(Relation):
    """Invariant within a percentage of the value."""

    name = "within_percent"
    parameters = frozenset({"value", "tolerance"})
    required = frozenset({"value", "tolerance"})

    def compare(self, result: float, given: Mapping[str, float]) -> Judgement:
        allowed = abs(given["value"]) * given["tolerance"] / 100
        margin = allowed - abs(result - given["value"])
        return Judgement(margin >= 0, margin, f"{given['value']:g} ± {given['tolerance']:g} %")


class Always(WithinPercent):
    name = "invariant"

    def compare(self, result: float, given: Mapping[str, float]) -> Judgement:
        return Judgement(True, 1.0, "anything")


fake_invariant = Always()
not_a_relation = 42
'''

ENTRY_POINTS = """\
[exsce.relations]
within_percent = exsce_test_relations:WithinPercent
invariant = exsce_test_relations:fake_invariant
broken = exsce_test_relations:not_a_relation
"""


@pytest.fixture
def plugin(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """A distribution installed in ``tmp_path`` that registers three relations."""
    yield from installed_plugins(tmp_path, monkeypatch, relations.RELATIONS, "exsce_test_relations", PLUGIN, ENTRY_POINTS)


@pytest.mark.usefixtures("plugin")
def test_a_plugin_relation_is_found_through_its_entry_point() -> None:
    with pytest.warns(UserWarning):
        names = relation_names()
    assert "within_percent" in names
    within = relation("within_percent")
    assert within.judge(104, value=100, tolerance=5) == Judgement(True, 1.0, "100 ± 5 %")
    assert within.judge(94, value=100, tolerance=5).passed is False
    with pytest.raises(RelationError, match="relation 'within_percent' needs a tolerance"):
        within.judge(100, value=100)


@pytest.mark.usefixtures("plugin")
def test_a_plugin_cannot_replace_a_built_in_relation() -> None:
    with pytest.warns(UserWarning) as warned:
        invariant = relation("invariant")
    replace = "the plug-in relation 'invariant' (exsce_test_relations:fake_invariant) cannot replace"
    assert any(str(w.message).startswith(replace) for w in warned)
    assert invariant.judge(20, value=12, tolerance=3) == Judgement(False, -5.0, "12 ± 3")


@pytest.mark.usefixtures("plugin")
def test_a_plugin_that_is_not_a_relation_is_left_out_with_a_warning() -> None:
    with pytest.warns(UserWarning) as warned:
        names = relation_names()
    assert "broken" not in names
    assert any("'broken'" in str(w.message) and "is not a Relation" in str(w.message) for w in warned)


@pytest.mark.usefixtures("plugin")
def test_plugins_are_loaded_once() -> None:
    with pytest.warns(UserWarning):
        relation("within_percent")
    assert "exsce_test_relations" in sys.modules
    sys.modules.pop("exsce_test_relations")
    relation("within_percent")  # from the cache: no import, no second warning
    assert "exsce_test_relations" not in sys.modules


def test_all_of_passes_when_every_judgement_does() -> None:
    inside = relation("below_max").judge(0.5, limit=1.0)
    outside = relation("above_min").judge(0.05, limit=0.1)
    both = all_of(inside, relation("invariant").judge(10, value=12, tolerance=3))
    assert both.passed is True
    assert math.isclose(both.margin, 0.5)
    assert both.expected == "<= 1 and 12 ± 3"
    failing = all_of(inside, outside)
    assert failing.passed is False
    assert math.isclose(failing.margin, -0.05)
    assert failing.expected == "<= 1 and >= 0.1"


def test_any_of_passes_when_one_judgement_does() -> None:
    inside = relation("below_max").judge(0.5, limit=1.0)
    outside = relation("above_min").judge(0.05, limit=0.1)
    either = any_of(outside, inside)
    assert either.passed is True
    assert math.isclose(either.margin, 0.5)
    assert either.expected == ">= 0.1 or <= 1"
    neither = any_of(outside, relation("below_max").judge(1.2, limit=1.0))
    assert neither.passed is False
    assert math.isclose(neither.margin, -0.05)


def test_combining_no_judgement_is_an_error() -> None:
    with pytest.raises(RelationError):
        all_of()
    with pytest.raises(RelationError):
        any_of()


FLEET = {"tiago1": 12.0, "tiago2": 30.0, "tiago3": 18.0}


@pytest.mark.parametrize(("how", "expected"), [("sum", 60.0), ("mean", 20.0), ("max", 30.0), ("min", 12.0)])
def test_aggregate_over_the_fleet(how: str, expected: float) -> None:
    assert math.isclose(aggregate(FLEET, how), expected)


def test_aggregate_with_a_nan_value_is_nan_whatever_the_order() -> None:
    assert math.isnan(aggregate({"a": math.nan, "b": 1.0}, "max"))
    assert math.isnan(aggregate({"a": 1.0, "b": math.nan}, "max"))
    assert math.isnan(aggregate({"a": 1.0, "b": math.nan}, "min"))


def test_aggregate_rejects_an_unknown_way_and_an_empty_fleet() -> None:
    with pytest.raises(RelationError, match=r"unknown aggregate 'maen'; did you mean 'mean'\?"):
        aggregate(FLEET, "maen")
    with pytest.raises(RelationError, match="no robot values"):
        aggregate({}, "sum")
