"""What the grammar allows at a point of a text: for completion.

The declaration around the point is parsed up to the start of the word being
typed, followed by a character nothing matches: textX's syntax error there lists
what could have come instead (keywords, a name, a number...).  Only that one
declaration is parsed (and of a long environment, only the area the point is
in), so this stays fast in long files.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, field
from typing import Any

from textx import TextXSyntaxError

from exsce_dsl.lang.chunks import Chunk, Token, area_spans, declaration_chunks, tokens
from exsce_dsl.lang.parser import new_metamodel

# Nothing in the grammar matches it: the parse fails there and says what it expected.
_STOP = "\u0001"
_WORD_BEFORE = re.compile(r"[\w-]*\Z")
_KEYWORD = re.compile(r"[a-z][a-z0-9_]*")  # nav2, move_base
_OTHER_RULES = {
    "Name": "name",
    "Ref": "name",
    "STRING": "string",
    "Quoted": "string",
    "INT": "number",
    "NUMBER": "number",
    "FLOAT": "number",
    "STRICTFLOAT": "number",
    "Length": "number",
    "Angle": "number",
    "Duration": "number",
    "Quantity": "number",
    "MetricQuantity": "number",
    "MetricUnit": "unit",
    "MessageType": "message type",
    "Word": "word",
}


@dataclass(frozen=True)
class Continuations:
    """What may be written at a point."""

    word_start: int
    """Where the word being typed starts (the point itself if none is)."""
    keywords: tuple[str, ...] = ()
    punctuation: tuple[str, ...] = ()
    others: frozenset[str] = field(default_factory=frozenset)
    """``name``, ``number``, ``string``, ``unit``, ``message type``, ``word``."""
    declaration: str | None = None
    """The keyword of the declaration the point is in (None between declarations)."""
    before: tuple[str, ...] = ()
    """The tokens of that declaration before the word (strings as ``"``, comments left out)."""
    known: bool = True
    """False when the text before the point has a syntax error: only ``before`` is known then."""

    @property
    def name(self) -> bool:
        return "name" in self.others


def continuations_at(text: str, offset: int) -> Continuations | None:
    """What may come at ``offset`` of ``text``; None inside a comment or a string."""
    offset = max(0, min(offset, len(text)))
    window = max(0, offset - 200)
    word = _WORD_BEFORE.search(text[window:offset])
    word_start = window + word.start() if word else offset
    chunk = None
    for candidate in declaration_chunks(text):
        if candidate.start > word_start:
            break
        chunk = candidate
    start = chunk.start if chunk is not None else 0
    source = text[start:word_start]
    if chunk is not None and chunk.keyword == "environment":
        source = _without_areas(text, chunk, word_start)
    prefix_tokens: list[Token] = []
    for token in tokens(source):
        if token.kind != "comment" and token.kind != "string":
            prefix_tokens.append(token)
        elif token.kind == "string" and (len(token.text) > 1 and token.text[-1] == token.text[0]):
            prefix_tokens.append(token)
        elif token.end == len(source) and not token.text.endswith("*/"):
            return None  # the point is inside an open comment or string
    before = tuple('"' if t.kind == "string" else t.text for t in prefix_tokens)
    declaration = before[0] if before and chunk is not None and chunk.keyword == before[0] else None
    try:
        _metamodel().model_from_str(source + " " + _STOP)
    except TextXSyntaxError as exc:
        at_end = (exc.line, exc.col) == _end_position(source + " ")
        if not at_end:
            return Continuations(word_start, declaration=declaration, before=before, known=False)
        return _from_rules(exc.expected_rules or [], word_start, declaration, before)
    return Continuations(word_start, declaration=declaration, before=before)  # pragma: no cover


def _from_rules(
    rules: list[Any], word_start: int, declaration: str | None, before: tuple[str, ...]
) -> Continuations:
    keywords: list[str] = []
    punctuation: list[str] = []
    others: set[str] = set()
    for rule in rules:
        name = getattr(rule, "rule_name", "") or ""
        literal = getattr(rule, "to_match", None)
        if name in _OTHER_RULES:
            others.add(_OTHER_RULES[name])
        elif isinstance(literal, str) and not name.startswith("Comment") and _KEYWORD.fullmatch(literal):
            if literal not in keywords:
                keywords.append(literal)
        elif isinstance(literal, str) and rule.__class__.__name__ == "StrMatch":
            if literal not in punctuation:
                punctuation.append(literal)
        elif name == "EOF":
            continue
    return Continuations(
        word_start, tuple(keywords), tuple(punctuation), frozenset(others), declaration, before
    )


def _without_areas(text: str, chunk: Chunk, end: int) -> str:
    """An environment's text up to ``end`` without the areas that close before ``end``
    (an environment lists its members; dropping some leaves a valid environment)."""
    kept, at = [], chunk.start
    for area_start, area_end in area_spans(text, chunk):
        if area_end > end:
            break
        kept.append(text[at:area_start])
        at = area_end
    kept.append(text[at:end])
    return "".join(kept)


def _end_position(text: str) -> tuple[int, int]:
    lines = text.split("\n")
    return len(lines), len(lines[-1]) + 1


@functools.lru_cache(maxsize=1)
def _metamodel() -> Any:
    """A metamodel of its own: completion runs beside the parses of the analysis."""
    return new_metamodel()
