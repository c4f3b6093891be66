"""What the language server knows of ``derive`` steps, all from the transformations' records:
each transformation as a snippet, the type of the argument that goes where the point is, and
what each step's first word means (hover)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from exsce_dsl.lang import step_heads
from exsce_dsl.transform import TRANSFORMATIONS, Slot, Word, phrase_parts, shown_phrase, variants

if TYPE_CHECKING:
    from exsce_dsl.transform import Transformation

_PLACEHOLDERS = {"count": "n"}
"""A parameter's placeholder in a snippet, where it is not its type's name."""


def _variants(record: Transformation) -> list[tuple[Word | Slot, ...]]:
    return [v for phrase in record.phrases for v in variants(phrase_parts(phrase))]


def _inner_pairs() -> frozenset[tuple[str, str]]:
    """Two words one after the other inside a step (``swap start``): the second does not
    start a step there."""
    pairs: set[tuple[str, str]] = set()
    for record in TRANSFORMATIONS.values():
        for variant in _variants(record):
            for first, second in zip(variant, variant[1:], strict=False):
                if isinstance(first, Word) and isinstance(second, Word):
                    pairs.add((first.text, second.text))
    return frozenset(pairs)


def current_step(before: Sequence[str]) -> list[str]:
    """The words of the step the point is in (empty: not in one)."""
    heads, inner = step_heads(), _inner_pairs()
    start = None
    for i, token in enumerate(before):
        if token in heads and not (i and (before[i - 1], token) in inner):
            start = i
    return [] if start is None else list(before[start:])


def next_types(step: Sequence[str]) -> set[str]:
    """The types of the arguments that may come after the words of ``step``; inside a block of
    assignments, ``allocation robot`` or ``allocation task``."""
    found: set[str] = set()
    for record in TRANSFORMATIONS.values():
        for variant in _variants(record):
            kind = _next_type(record, variant, step)
            if kind is not None:
                found.add(kind)
    return found


def _next_type(record: Transformation, variant: tuple[Word | Slot, ...], step: Sequence[str]) -> str | None:
    at = 0
    for part in variant:
        if isinstance(part, Word):
            if at == len(step) or step[at] != part.text:
                return None
            at += 1
            continue
        kind = record.type_of(part.parameter)
        if at == len(step):
            return kind
        if kind == "allocation":  # a block: names until its end
            if step[at] != "{" or "}" in step[at:]:
                return None
            return "allocation task" if step[-1] in ("does", "then") else "allocation robot"
        if kind == "position":
            if ")" not in step[at:]:
                return None
            at += step[at:].index(")") + 1
        else:
            at += 1
    return None


def snippet(record: Transformation) -> tuple[str, str]:
    """The step of ``record`` to insert: (snippet, plain text), in its first phrase with no
    optional part."""
    shortest = variants(phrase_parts(record.phrases[0]))[0]
    texts: list[str] = []
    plain: str | None = None
    number = 1
    for part in shortest:
        if isinstance(part, Word):
            texts.append(part.text)
            continue
        kind = record.type_of(part.parameter)
        if plain is None:
            plain = " ".join(texts) + (" {" if kind == "allocation" else " ")
        if kind == "position":
            texts.append(f"(${{{number}:x}}, ${{{number + 1}:y}})")
            number += 2
        elif kind == "allocation":
            texts.append(f"{{\n\t${{{number}:robot}} does ${{{number + 1}:task}}\n}}")
            number += 2
        else:
            texts.append(f"${{{number}:{_PLACEHOLDERS.get(kind, kind)}}}")
            number += 1
    return " ".join(texts), " ".join(texts) if plain is None else plain


def step_meanings() -> dict[str, str]:
    """What hover says of each word a step starts with: the steps it starts, and what they do."""
    said: dict[str, list[str]] = {}
    for record in TRANSFORMATIONS.values():
        for phrase in record.phrases:
            head = phrase.split()[0]
            text = f"`{shown_phrase(record, phrase)}` ({record.name}): {record.help}"
            said.setdefault(head, []).append(text)
    return {head: "; ".join(texts) + "." for head, texts in said.items()}
