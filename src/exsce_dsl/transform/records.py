"""What one input transformation is, as one record: its name, its parameters and their types,
the function that applies it, the shape of the step it records, how a ``derive`` block writes it
(its phrases), and the text editors and the docs show of it.

A transformation's module declares it over its function (:func:`transformation`), so that the
record and the code it describes are read together.  Everything else is driven by these
records, with no per-transformation code: the grammar of ``derive`` steps and the builder
(:mod:`exsce_dsl.lang.transformation_syntax`), the formatter, the language server's completion
and hover, ``exscec derive --list``, the table of ``docs/deriving.md``, the words the VS Code
grammar highlights.  A parameter's *type* is all they need to know of it (:data:`TYPES`).

A phrase is the step's words, ``{parameter}`` where an argument goes and ``[...]`` around an
optional part: ``remove robot {robot} [reassign to {reassign}]``.  A transformation written in
more than one way has one phrase for each, the most specific first (the formatter writes a step
with the first phrase that holds its arguments).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

from exsce_dsl.model import Scenario, Task
from exsce_dsl.transform.applied import Applied

Arguments = Mapping[str, str]
Apply = Callable[[Scenario, Arguments, Mapping[str, Task]], Applied]
Proposer = Callable[[Scenario, Mapping[str, Task]], Iterator[Arguments]]

TYPES: dict[str, str] = {
    "robot": "a robot of the scenario",
    "task": "a task the specification declares",
    "pose": "a pose of the environment",
    "obstacle": "an obstacle of the environment",
    "new_robot": "the id of a new robot",
    "new_task": "the id of a new task",
    "count": "a whole number from 1",
    "position": "x,y or x,y,z in metres; a step writes (x, y[, z]) with units",
    "allocation": "robot:task,robot:task,... in order; a step writes a reallocate { ... } block",
}
"""The types a parameter may have, and what an argument of each is."""


@dataclass(frozen=True)
class Parameter:
    name: str
    type: str
    """One of :data:`TYPES`."""
    required: bool = True


@dataclass(frozen=True)
class Word:
    text: str


@dataclass(frozen=True)
class Slot:
    parameter: str


@dataclass(frozen=True)
class Group:
    parts: tuple[Part, ...]


Part = Word | Slot | Group
_PHRASE_TOKEN = re.compile(r"\[|\]|\{(\w+)\}|[^\s\[\]{}]+")


def phrase_parts(phrase: str) -> tuple[Part, ...]:
    """A phrase's words, slots and optional groups."""
    stack: list[list[Part]] = [[]]
    for token in _PHRASE_TOKEN.finditer(phrase):
        text = token.group()
        if text == "[":
            stack.append([])
        elif text == "]":
            group = Group(tuple(stack.pop()))
            stack[-1].append(group)
        elif token.group(1):
            stack[-1].append(Slot(token.group(1)))
        else:
            stack[-1].append(Word(text))
    if len(stack) != 1:
        raise ValueError(f"unbalanced [ ] in phrase {phrase!r}")
    return tuple(stack[0])


def slots(parts: tuple[Part, ...], optional: bool = False) -> Iterator[tuple[str, bool]]:
    """The parameters a phrase names, each with whether it is inside an optional group."""
    for part in parts:
        if isinstance(part, Slot):
            yield part.parameter, optional
        elif isinstance(part, Group):
            yield from slots(part.parts, True)


def variants(parts: tuple[Part, ...]) -> list[tuple[Word | Slot, ...]]:
    """Every way a phrase can be written: each optional group left out or put in."""
    found: list[tuple[Word | Slot, ...]] = [()]
    for part in parts:
        if isinstance(part, Group):
            inner = variants(part.parts)
            found = [f + i for f in found for i in [(), *inner]]
        else:
            found = [f + (part,) for f in found]
    return found


@dataclass(frozen=True)
class Transformation:
    """One input transformation, all that is known of it."""

    name: str
    """The method's name (``remove_robot``), in code, the DSL's records, the CLI and RDF alike."""
    apply: Callable[[Scenario, Arguments, Mapping[str, Task]], Applied]
    parameters: tuple[Parameter, ...]
    help: str
    """What it does, in a line: completion, hover, ``derive --list`` and the docs show it;
    parameters in capitals."""
    phrases: tuple[str, ...]
    """How a ``derive`` step writes it (see the module's docstring)."""
    records: tuple[str, ...]
    """The parameters the step it records (in the PROV of a generation) may have; a composite
    records the basic steps it is made of, and none of its own."""
    propose: Proposer | None = None
    """The arguments worth trying on a scenario (``exscec explore``); built-ins have theirs
    in :mod:`exsce_dsl.explore.steps`."""

    @property
    def required(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters if p.required)

    @property
    def optional(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters if not p.required)

    def type_of(self, parameter: str) -> str:
        return next(p.type for p in self.parameters if p.name == parameter)

    def usage(self) -> str:
        """``add_task --robot X --task X [--position X]``: how ``exscec derive -t`` takes it."""
        arguments = [f"--{a} X" for a in self.required] + [f"[--{a} X]" for a in self.optional]
        return " ".join([self.name, *arguments])


def transformation(
    table: list[Transformation],
    phrases: str | tuple[str, ...],
    parameters: str,
    *,
    records: str,
    help: str,  # noqa: A002 - the record's field
    propose: Proposer | None = None,
) -> Callable[[Apply], Apply]:
    """Declare the function below as a transformation (named as it is) and add its record to
    ``table``: ``parameters`` are ``name: type`` (``?`` after the type: optional), ``records`` the
    names its step may record, space-separated."""

    def declare(apply: Apply) -> Apply:
        declared = []
        for item in parameters.split(","):
            name, _, kind = (part.strip() for part in item.partition(":"))
            declared.append(Parameter(name, kind.rstrip("?"), not kind.endswith("?")))
        said = (phrases,) if isinstance(phrases, str) else phrases
        recorded = tuple(records.split())
        table.append(Transformation(apply.__name__, apply, tuple(declared), help, said, recorded, propose))
        return apply

    return declare


def registry(*tables: Sequence[Transformation]) -> dict[str, Transformation]:
    """The transformations of ``tables`` by name, each checked to be consistent (a phrase
    names only its parameters, each parameter has a known type and is written by a phrase)."""
    found: dict[str, Transformation] = {}
    for record in (r for table in tables for r in table):
        if record.name in found:
            raise ValueError(f"two transformations are called {record.name!r}")
        names = {p.name for p in record.parameters}
        written: set[str] = set()
        for phrase in record.phrases:
            named = {s for s, _ in slots(phrase_parts(phrase))}
            if not named <= names:
                raise ValueError(f"{record.name}: {phrase!r} names {sorted(named - names)}")
            written |= named
        if names != written or any(p.type not in TYPES for p in record.parameters):
            raise ValueError(f"{record.name}: each parameter needs a type of TYPES and a phrase")
        found[record.name] = record
    return found


def markdown_table(records: Mapping[str, Transformation]) -> str:
    """The table of transformations ``docs/deriving.md`` shows."""
    rows = ["| in a `derive` block | `exscec derive -t` | what it does |", "|---|---|---|"]
    for record in records.values():
        written = "<br>".join(f"`{shown_phrase(record, p)}`" for p in record.phrases)
        rows.append(f"| {written} | `{record.usage()}` | {record.help} |")
    return "\n".join(rows) + "\n"


_SHOWN = {"position": "(X, Y[, Z])", "allocation": "{ ROBOT does TASK then TASK ... }"}
"""How the phrases people read show an argument of these types (others: the parameter's name)."""


def shown_phrase(record: Transformation, phrase: str) -> str:
    """A phrase as people read it: ``remove robot ROBOT [reassign to REASSIGN]``."""
    return re.sub(r"\{(\w+)\}", lambda m: _SHOWN.get(record.type_of(m.group(1)), m.group(1).upper()), phrase)
