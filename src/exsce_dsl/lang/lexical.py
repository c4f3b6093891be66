"""Lexical facts about exsce text that the parse tree does not keep."""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from decimal import Decimal

from exsce_dsl.lang.locations import LineIndex

"""A number as the language writes one (the number part of its quantity tokens; no ``nan``,
``inf`` or ``1_000``)."""

# A string literal, or a comment; strings come first so `"//"` is not a comment.
_TOKEN = re.compile(r'"(?:\\.|[^"\\])*"|//[^\n]*|/\*.*?\*/', re.DOTALL)


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


_ESCAPED = re.compile(r"""\\([\\"'])""")


def string_value(literal: str) -> str:
    """The text a quoted string of the language (the grammar's ``Quoted``, quotes included)
    stands for: the inverse of :func:`string_literal`.  A backslash before any other character
    stays, as it is written (``"\\d"`` is two characters)."""
    return _ESCAPED.sub(r"\1", literal[1:-1])


# A quantity token of the grammar (``Length``, ``Angle``, ``Quantity``, ``MetricQuantity``): a
# number and, after optional spaces, a unit.
_QUANTITY = re.compile(r"([-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?)\s*(\S+)?")
_LENGTH_SCALE = {None: 1.0, "m": 1.0, "cm": 0.01, "mm": 0.001}
DURATION_SCALE = {"ms": 0.001, "s": 1.0, "min": 60.0, "h": 3600.0}
"""Seconds per unit of a ``Duration`` token."""


def quantity_parts(text: str) -> tuple[str, str | None]:
    """The number and the unit (None if there is none) of a quantity token, as written."""
    match = _QUANTITY.fullmatch(text.strip())
    assert match is not None, text  # the grammar only lets such tokens through
    return match.group(1), match.group(2)


def quantity_text(text: str) -> str:
    """A quantity token as the formatter writes it: as written, one space before its unit."""
    number, unit = quantity_parts(text)
    return f"{number} {unit}" if unit else number


def read_length(text: str) -> float:
    """A ``Length`` token (``150 cm``, ``-0.5``) in metres."""
    number, unit = quantity_parts(text)
    return float(number) * _LENGTH_SCALE[unit]


def read_angle(text: str) -> float:
    """An ``Angle`` token (``90 deg``, ``1.57``) in radians."""
    number, unit = quantity_parts(text)
    return math.radians(float(number)) if unit == "deg" else float(number)


def read_duration(text: str) -> float | None:
    """A ``Duration`` token (``2 min``) in seconds; None when it has no unit."""
    number, unit = quantity_parts(text)
    return None if unit is None else float(number) * DURATION_SCALE[unit]


def duration_text(seconds: float, written: str | None = None) -> str:
    """A duration as the formatter writes it: as the author wrote it while that still reads as
    ``seconds``, else in seconds (``90 s``, ``0.5 s``)."""
    if written is not None and read_duration(written) == seconds:
        return quantity_text(written)
    return f"{int(seconds) if float(seconds).is_integer() else seconds!r} s"


def as_written(
    values: Sequence[float], written: Sequence[str], read: Callable[[str], float]
) -> list[str] | None:
    """The texts the author wrote for ``values`` (from the model), when they still read as
    those values; None when the model was made otherwise, or changed since it was read."""
    if len(written) != len(values) or not written:
        return None
    if any(read(text) != value for value, text in zip(values, written, strict=True)):
        return None
    return [quantity_text(text) for text in written]
