"""Hover: what a name stands for (a pose's area and coordinates, a task's waypoints, a
metric's definition and unit, a derived scenario's base and steps), or what a keyword means."""

from __future__ import annotations

import re
from collections.abc import Callable

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang import Symbol, builtin_metrics, declaration_chunks, tokens
from exsce_dsl.lsp.keywords import MEANINGS
from exsce_dsl.lsp.navigation import NameAtPoint, Names
from exsce_dsl.model.metrics import SI_UNIT

_WORD = re.compile(r"[A-Za-z_][\w-]*")


def word_at(text: str, offset: int) -> tuple[str, int, int] | None:
    """The word at ``offset`` (with its start and end), None in a comment or a string."""
    start = offset
    while start > 0 and (text[start - 1].isalnum() or text[start - 1] in "_-"):
        start -= 1
    word = _WORD.match(text, start)
    if word is None or word.end() < offset:
        return None
    chunk_start = max((c.start for c in declaration_chunks(text) if c.start <= start), default=0)
    for token in tokens(text, chunk_start, word.end()):
        if token.start <= start < token.end and token.kind in ("comment", "string"):
            return None
    return word.group(), word.start(), word.end()


def keyword_hover(word: str) -> str | None:
    meaning = MEANINGS.get(word)
    return f"**{word}** (keyword)\n\n{meaning}" if meaning else None


def symbol_hover(
    names: Names, target: NameAtPoint, source: Callable[[SourceLocation], str | None]
) -> str | None:
    """Markdown about what ``target`` names; ``source`` gives the text at a location."""
    found = names.definitions(target)
    if not found:
        if target.kind == "metric" and target.name in builtin_metrics():
            info = builtin_metrics()[target.name]
            unit = SI_UNIT[info.dimension] or "a count"
            said = "each robot" if info.per_robot else "the mission"
            return f"**metric** `{target.name}` (built-in)\n\n{info.meaning}; of {said}; unit: {unit}"
        return f"**{target.kind}** `{target.name}`: not declared in any file known"
    return "\n\n---\n\n".join(_describe(symbol, source) for symbol in found[:3])


def _describe(symbol: Symbol, source: Callable[[SourceLocation], str | None]) -> str:
    title = "derived scenario" if symbol.kind == "scenario" and symbol.fact("derived from") else symbol.kind
    lines = [f"**{title}** `{symbol.name}`"]
    facts = list(symbol.facts)
    if symbol.kind == "metric":
        meaning, unit = symbol.fact("meaning"), symbol.fact("unit")
        if meaning:
            lines.append(meaning + (f" (unit: {unit})" if unit else " (no unit)"))
        text = source(symbol.extent)
        if text:
            lines.append(f"```exsce\n{text}\n```")
            facts = []
    if facts:
        lines.append("\n".join(f"- {label}: `{_code(text)}`" for label, text in facts))
    return "\n\n".join(lines)


def _code(text: str) -> str:
    """``text`` inside a Markdown code span."""
    return text.replace("`", "'")
