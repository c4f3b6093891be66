"""Lexical facts about exsce text that the parse tree does not keep."""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal

from exsce_dsl.lang.locations import LineIndex

"""A number as the language writes one (the number part of its quantity tokens; no ``nan``,
``inf`` or ``1_000``)."""

# A string literal, or a comment; strings come first so `"//"` is not a comment.
_TOKEN = re.compile(r'"(?:\\.|[^"\\])*"|//[^\n]*|/\*.*?\*/', re.DOTALL)


def has_comments(text: str) -> bool:
    return any(not m.group().startswith('"') for m in _TOKEN.finditer(text))


@dataclass(frozen=True)
class Comment:
    file: str
    line: int
    column: int
    text: str


def comments(text: str, path: str) -> list[Comment]:
    """Every comment of ``text``, with where it starts."""
    index = LineIndex(path, text)
    found = []
    for match in _TOKEN.finditer(text):
        if not match.group().startswith('"'):
            line, col = index.line_col(match.start())
            found.append(Comment(path, line, col, match.group().rstrip()))
    return found


def number_text(value: float) -> str:
    """Shortest text that reads back as the same float (always with a decimal point)."""
    text = repr(float(value))
    mantissa, _, exponent = text.partition("e")
    if exponent and abs(int(exponent)) <= 6:
        text, mantissa, exponent = format(Decimal(text), "f"), "", ""
    if exponent:
        return (mantissa if "." in mantissa else mantissa + ".0") + "e" + exponent
    return text if "." in text else text + ".0"


def string_literal(text: str) -> str:
    """``text`` as a quoted string of the language."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'
