"""The steps of ``derive`` blocks, from the transformations' records: their grammar, and what
a parsed step says (the transformation and its arguments).

Each phrase of a record (:mod:`exsce_dsl.transform.records`) becomes a textX rule, its words
keywords and each ``{parameter}`` an attribute whose rule the parameter's type says (a reference,
a new name, a number, a position, a block of assignments); the rules' alternation is the
grammar's ``Step``, which :func:`step_rules` writes and the parser adds to ``grammar/derive.tx``.
Nothing here knows one transformation from another: a type is all it looks at.
"""

from __future__ import annotations

import functools
import keyword
from dataclasses import dataclass
from typing import Any

from exsce_dsl.lang.lexical import quantity_text, read_length
from exsce_dsl.transform import TRANSFORMATIONS, Group, Part, Slot, Transformation, Word, phrase_parts

REFERENCE_TYPES = frozenset({"robot", "task", "pose", "obstacle"})
"""Types whose argument names something declared (the grammar's ``Ref``)."""

_RULES = {
    "new_robot": "{attr}=Name",
    "new_task": "{attr}=Name",
    "count": "{attr}=INT",
    "position": "{attr}=Position",
    "allocation": "'{{' {attr}+=Assignment '}}'",
}


@dataclass(frozen=True)
class StepRule:
    """The grammar rule of one phrase of a transformation."""

    name: str
    """The rule's name (the class of its parse tree nodes): ``Step_remove_task_2``."""
    record: Transformation
    parts: tuple[Part, ...]

    def attributes(self) -> dict[str, str]:
        """Attribute of the parse tree node -> parameter."""
        return {attribute(p): p for p in _parameters(self.parts)}


def attribute(parameter: str) -> str:
    """The attribute of a parse tree node that holds ``parameter`` (``with`` is ``with_``)."""
    return f"{parameter}_" if keyword.iskeyword(parameter) else parameter


def _parameters(parts: tuple[Part, ...]) -> list[str]:
    found: list[str] = []
    for part in parts:
        if isinstance(part, Slot):
            found.append(part.parameter)
        elif isinstance(part, Group):
            found.extend(_parameters(part.parts))
    return found


@functools.lru_cache(maxsize=1)
def step_rules_by_name() -> dict[str, StepRule]:
    """Every phrase of every transformation, by its rule's name, in the records' order."""
    rules: dict[str, StepRule] = {}
    for record in TRANSFORMATIONS.values():
        for number, phrase in enumerate(record.phrases, start=1):
            name = f"Step_{record.name}" + (f"_{number}" if number > 1 else "")
            rules[name] = StepRule(name, record, phrase_parts(phrase))
    return rules


def _rule_text(record: Transformation, parts: tuple[Part, ...]) -> str:
    written: list[str] = []
    for part in parts:
        if isinstance(part, Word):
            written.append(f"'{part.text}'")
        elif isinstance(part, Slot):
            kind = record.type_of(part.parameter)
            rule = "{attr}=Ref" if kind in REFERENCE_TYPES else _RULES[kind]
            written.append(rule.format(attr=attribute(part.parameter)))
        else:
            written.append(f"({_rule_text(record, part.parts)})?")
    return " ".join(written)


def step_rules() -> str:
    """The textX rules of the steps: ``Step`` and one rule per phrase."""
    rules = step_rules_by_name()
    lines = ["Step:", "  " + " | ".join(rules) + ";", ""]
    lines.extend(f"{name}: {_rule_text(rule.record, rule.parts)};" for name, rule in rules.items())
    return "\n".join(lines) + "\n"


def step_of(node: Any) -> tuple[str, dict[str, str | None]]:
    """The transformation a step of the grammar names, with its arguments (None: not given)."""
    rule = step_rules_by_name()[node.__class__.__name__]
    arguments: dict[str, str | None] = {}
    for attr, parameter in rule.attributes().items():
        arguments[parameter] = _argument(rule.record.type_of(parameter), getattr(node, attr, None))
    return rule.record.name, arguments


def _argument(kind: str, value: Any) -> str | None:
    if value is None or value == "" or value == [] or (kind == "count" and not value):
        return None
    if kind in REFERENCE_TYPES:
        return str(value.name)
    if kind == "position":
        texts = [value.x, value.y] + ([value.z] if value.z is not None else [])
        metres = [read_length(t) for t in texts]
        if len(metres) == 3 and metres[2] == 0.0:  # a z of 0 is not recorded
            metres.pop()
        return ",".join(repr(v) for v in metres)
    if kind == "allocation":
        return ",".join(f"{a.robot.name}:{t.name}" for a in value for t in a.tasks)
    return str(value)


def written_arguments(node: Any) -> tuple[tuple[str, str], ...]:
    """The arguments of a step whose text is not their value's (see ``Step.written``):
    positions, with their units."""
    rule = step_rules_by_name()[node.__class__.__name__]
    written = []
    for attr, parameter in rule.attributes().items():
        value = getattr(node, attr, None)
        if rule.record.type_of(parameter) == "position" and value is not None:
            texts = [value.x, value.y] + ([value.z] if value.z is not None else [])
            written.append((parameter, ", ".join(quantity_text(t) for t in texts)))
    return tuple(written)


def step_references() -> dict[str, dict[str, str]]:
    """For each step rule, its attributes that name something declared, with the kind named."""
    return {
        name: {
            attr: rule.record.type_of(parameter)
            for attr, parameter in rule.attributes().items()
            if rule.record.type_of(parameter) in REFERENCE_TYPES
        }
        for name, rule in step_rules_by_name().items()
    }


def step_words() -> frozenset[str]:
    """Every word of every step's phrases (the keywords the steps add to the language)."""
    found: set[str] = set()
    stack = [rule.parts for rule in step_rules_by_name().values()]
    while stack:
        for part in stack.pop():
            if isinstance(part, Word):
                found.add(part.text)
            elif isinstance(part, Group):
                stack.append(part.parts)
    return frozenset(found)


def step_heads() -> frozenset[str]:
    """The words a step starts with."""
    found: set[str] = set()
    for rule in step_rules_by_name().values():
        first = rule.parts[0]
        if isinstance(first, Word):
            found.add(first.text)
    return frozenset(found)
