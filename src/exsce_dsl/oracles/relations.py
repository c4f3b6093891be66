"""Output relations: how an oracle compares a run's value with what it expects.

The method's basic relations, with its signatures: ``increasing(result, value, delta,
tolerance)``, ``decreasing(...)``, ``invariant(result, value, tolerance)``,
``below_max(result, limit)``, ``above_min(result, limit)``.  Complex relations combine
judgements (:func:`all_of`, :func:`any_of`) or aggregate a fleet's values
(:func:`aggregate`).  What a derived scenario's metrics are expected to do comes from the
stored runs (:mod:`exsce_dsl.derive.expect`), not from a table of transformations.

Third-party packages add relations through the entry-point group ``exsce.relations``
(:mod:`exsce_dsl.plugins`); a relation is never imported from a module name found in a data file.
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from exsce_dsl.errors import RelationError
from exsce_dsl.plugins import Registry
from exsce_dsl.suggest import did_you_mean

__all__ = [
    "RELATIONS",
    "Judgement",
    "Relation",
    "aggregate",
    "all_of",
    "any_of",
    "relation",
    "relation_names",
]

@dataclass(frozen=True)
class Judgement:
    passed: bool
    margin: float
    """How far inside the bound the result is (negative: by how much it is outside)."""
    expected: str
    """The bound in words: ``<= 1``, ``12 ± 3``."""


class Relation(ABC):
    """An output relation.  Plug-ins subclass it and implement :meth:`compare`;
    :meth:`judge` checks parameters and NaN first, so that every relation treats them alike."""

    name: str
    parameters: frozenset[str]
    """Every parameter it takes, among value, limit, delta and tolerance."""
    required: frozenset[str]
    """Those it cannot judge without."""

    def judge(
        self,
        result: float,
        *,
        value: float | None = None,
        limit: float | None = None,
        delta: float | None = None,
        tolerance: float | None = None,
    ) -> Judgement:
        """Judge ``result``; a parameter given as None counts as not given."""
        named = {"value": value, "limit": limit, "delta": delta, "tolerance": tolerance}
        given = {k: float(v) for k, v in named.items() if v is not None}
        takes = ", ".join(sorted(self.parameters)) or "no parameters"
        for unknown in sorted(set(given) - self.parameters):
            raise RelationError(f"relation '{self.name}' takes no {unknown} (it takes {takes})")
        for missing in sorted(self.required - set(given)):
            raise RelationError(f"relation '{self.name}' needs a {missing} (it takes {takes})")
        judged = self.compare(float(result), given)
        if math.isnan(result) or math.isnan(judged.margin):
            return dataclasses.replace(judged, passed=False, margin=math.nan)
        return judged

    @abstractmethod
    def compare(self, result: float, given: Mapping[str, float]) -> Judgement:
        """Judge ``result`` with checked parameters (those not given are absent from ``given``)."""


Check = Callable[[float, Mapping[str, float]], Judgement]


@dataclass(frozen=True)
class _Basic(Relation):
    """A built-in relation: its parameters and the function that compares."""

    name: str
    parameters: frozenset[str]
    required: frozenset[str]
    check: Check

    def compare(self, result: float, given: Mapping[str, float]) -> Judgement:
        return self.check(result, given)


def _g(x: float) -> str:
    return f"{x:g}"


def _below_max(result: float, p: Mapping[str, float]) -> Judgement:
    margin = p["limit"] - result
    return Judgement(margin >= 0, margin, f"<= {_g(p['limit'])}")


def _above_min(result: float, p: Mapping[str, float]) -> Judgement:
    margin = result - p["limit"]
    return Judgement(margin >= 0, margin, f">= {_g(p['limit'])}")


def _invariant(result: float, p: Mapping[str, float]) -> Judgement:
    tolerance = p.get("tolerance", 0.0)
    margin = tolerance - abs(result - p["value"])
    return Judgement(margin >= 0, margin, f"{_g(p['value'])} ± {_g(tolerance)}")


def _changing(sign: float) -> Check:
    """``increasing`` (sign 1) or ``decreasing`` (sign -1): a change of at least delta, less tolerance."""

    def check(result: float, p: Mapping[str, float]) -> Judgement:
        value, delta, tolerance = p["value"], p.get("delta", 0.0), p.get("tolerance", 0.0)
        margin = sign * (result - value) - (delta - tolerance)
        words = f"{'>=' if sign > 0 else '<='} {_g(value + sign * (delta - tolerance))}"
        if delta or tolerance:
            change = f"{'+' if sign > 0 else '-'} {_g(delta)}"
            allowance = f" {'-' if sign > 0 else '+'} {_g(tolerance)}" if tolerance else ""
            words += f" ({_g(value)} {change}{allowance})"
        return Judgement(margin >= 0, margin, words)

    return check


_CHANGE = frozenset({"value", "delta", "tolerance"})
_BUILT_IN: Mapping[str, Relation] = {
    r.name: r
    for r in (
        _Basic("below_max", frozenset({"limit"}), frozenset({"limit"}), _below_max),
        _Basic("above_min", frozenset({"limit"}), frozenset({"limit"}), _above_min),
        _Basic("invariant", frozenset({"value", "tolerance"}), frozenset({"value"}), _invariant),
        _Basic("increasing", _CHANGE, frozenset({"value"}), _changing(1.0)),
        _Basic("decreasing", _CHANGE, frozenset({"value"}), _changing(-1.0)),
    )
}


def _accepted(name: str, loaded: object) -> Relation | None:
    """A plug-in's relation: the object registered, or what calling it (a class) makes."""
    made = loaded if isinstance(loaded, Relation) or not callable(loaded) else loaded()
    return made if isinstance(made, Relation) and made.name == name else None


RELATIONS: Registry[Relation] = Registry("relation", _BUILT_IN.items(), _accepted, "a Relation")
"""The built-ins and the plug-ins' relations (:mod:`exsce_dsl.plugins`: a plug-in that cannot be
used is left out with a warning, so that it does not stop every other oracle)."""


def relation(name: str) -> Relation:
    """The relation called ``name``: a built-in one or a registered plug-in's."""
    known = RELATIONS.entries()
    if name not in known:
        raise RelationError(f"unknown relation '{name}'{did_you_mean(name, known)}")
    return known[name]


def relation_names() -> tuple[str, ...]:
    return tuple(sorted(RELATIONS.entries()))


def all_of(*judgements: Judgement) -> Judgement:
    """Passes when every judgement does; its margin is the smallest."""
    if not judgements:
        raise RelationError("all_of needs at least one judgement")
    return Judgement(
        all(j.passed for j in judgements),
        min(j.margin for j in judgements),
        " and ".join(j.expected for j in judgements),
    )


def any_of(*judgements: Judgement) -> Judgement:
    """Passes when one judgement does; its margin is the largest."""
    if not judgements:
        raise RelationError("any_of needs at least one judgement")
    return Judgement(
        any(j.passed for j in judgements),
        max(j.margin for j in judgements),
        " or ".join(j.expected for j in judgements),
    )


_AGGREGATES: Mapping[str, Callable[[list[float]], float]] = {
    "sum": math.fsum,
    "mean": lambda xs: math.fsum(xs) / len(xs),
    "max": max,
    "min": min,
}


def aggregate(values: Mapping[str, float], how: str) -> float:
    """The fleet's value from each robot's: ``sum``, ``mean``, ``max`` or ``min``.
    NaN if a robot's value is NaN (``max`` and ``min`` would otherwise depend on order)."""
    if how not in _AGGREGATES:
        raise RelationError(f"unknown aggregate '{how}'{did_you_mean(how, _AGGREGATES)}")
    numbers = [float(v) for v in values.values()]
    if not numbers:
        raise RelationError(f"no robot values to aggregate ({how})")
    if any(math.isnan(x) for x in numbers):
        return math.nan
    return _AGGREGATES[how](numbers)
