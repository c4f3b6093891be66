"""One form for each value a store answers with, whatever the store wrote.

The same query asked of Oxigraph and of Virtuoso gives the same values in other lexical forms
and sometimes other types: Oxigraph writes the double 7 as ``7`` and Virtuoso as ``7.0``;
Virtuoso keeps the milliseconds of ``00:00:31.66Z`` as ``00:00:31.660Z``, keeps an
``xsd:integer`` as an ``xsd:int``, answers an ``AVG`` as an ``xsd:decimal`` and, in the Turtle
result sets exsce reads (:mod:`exsce_dsl.store.virtuoso`), writes a whole decimal as an integer
and a boolean as ``1``.  Every answer is put in one form here before anyone reads or prints it:

* integers (``xsd:int``, ``xsd:long``... ) are ``xsd:integer``, written as Python writes an int;
* decimals, doubles and floats are ``xsd:double`` (exsce writes every number as an integer or a
  double; :mod:`exsce_dsl.store.virtuoso` says why a decimal is read as one), written as the
  shortest text that reads back as the same double;
* booleans are ``true`` or ``false``;
* date-times with a time zone are in UTC, written with ``Z``; seconds have three decimals, or six
  when the microseconds are not whole milliseconds (date-times without a zone keep none).

A query whose column must be a double whatever the store computes says so itself
(``xsd:double(AVG(?value))``).  For people and files (``exscec query``, ``exscec runs``,
``exscec sparql``, the MCP tools), :func:`literal_text` prints a double with 15 significant
digits, the precision a double holds in decimal: two stores that add the same numbers in
another order differ in the 16th or 17th digit, never in what is printed.  The Python values
(:func:`literal_value`) are exact.
"""

from __future__ import annotations

import datetime
import math
import re
from decimal import Decimal, InvalidOperation

from pyoxigraph import Literal, NamedNode

from exsce_dsl.prov.identifiers import XSD_NAMESPACE
from exsce_dsl.store.base import Rows, Term

INTEGER_TYPES = frozenset(
    XSD_NAMESPACE + local
    for local in (
        "integer",
        "int",
        "long",
        "short",
        "byte",
        "nonNegativeInteger",
        "positiveInteger",
        "nonPositiveInteger",
        "negativeInteger",
        "unsignedLong",
        "unsignedInt",
        "unsignedShort",
        "unsignedByte",
    )
)
"""The datatypes of whole numbers, all read as ``xsd:integer``."""
NUMBER_TYPES = frozenset(XSD_NAMESPACE + local for local in ("double", "float", "decimal"))
"""The datatypes of other numbers, all read as ``xsd:double``."""

XSD_INTEGER = NamedNode(XSD_NAMESPACE + "integer")
XSD_DOUBLE = NamedNode(XSD_NAMESPACE + "double")
XSD_BOOLEAN = XSD_NAMESPACE + "boolean"
XSD_DATE_TIME = XSD_NAMESPACE + "dateTime"

SIGNIFICANT_DIGITS = 15
"""Digits a printed double keeps: every double of 15 significant decimal digits or fewer prints
as written, and sums in another order print alike."""

_FRACTION = re.compile(r"(\.\d{6})\d+")  # Python reads microseconds at most


def canonical_rows(rows: Rows) -> Rows:
    """``rows`` with every literal in its one form (see the module's text)."""
    return Rows(rows.variables, tuple(tuple(canonical_term(t) for t in row) for row in rows.rows))


def canonical_term(term: Term | None) -> Term | None:
    return canonical_literal(term) if isinstance(term, Literal) else term


def canonical_literal(literal: Literal) -> Literal:
    """The literal in its one form; a literal whose text is not of its datatype is left as it is."""
    if literal.language:
        return literal
    datatype, text = literal.datatype.value, literal.value.strip()
    try:
        if datatype in INTEGER_TYPES or datatype in NUMBER_TYPES:
            return _number(text, whole=datatype in INTEGER_TYPES)
        if datatype == XSD_BOOLEAN and text in ("true", "false", "1", "0"):
            return Literal("true" if text in ("true", "1") else "false", datatype=literal.datatype)
        if datatype == XSD_DATE_TIME:
            return Literal(datetime_text(parse_datetime(text)), datatype=literal.datatype)
    except (ValueError, InvalidOperation):
        pass
    return literal


def _number(text: str, whole: bool) -> Literal:
    if whole:
        exact = Decimal(text)
        if exact == exact.to_integral_value():  # Virtuoso's 0.0 of an xsd:int
            return Literal(str(int(exact)), datatype=XSD_INTEGER)
    number = float(text)
    if math.isnan(number):
        return Literal("NaN", datatype=XSD_DOUBLE)
    if math.isinf(number):
        return Literal("INF" if number > 0 else "-INF", datatype=XSD_DOUBLE)
    return Literal(repr(number), datatype=XSD_DOUBLE)


def parse_datetime(text: str) -> datetime.datetime:
    """An ``xsd:dateTime``'s text as a datetime (aware when the text has a zone); ValueError if
    it is not one."""
    return datetime.datetime.fromisoformat(_FRACTION.sub(r"\1", text.strip()).replace("Z", "+00:00"))


def datetime_text(moment: datetime.datetime) -> str:
    """``moment`` in ISO 8601: in UTC with ``Z`` when it has a zone, seconds with three decimals
    (six when the microseconds are not whole milliseconds)."""
    zoned = moment.tzinfo is not None
    if zoned:
        moment = moment.astimezone(datetime.timezone.utc)
    spec = "milliseconds" if moment.microsecond % 1000 == 0 else "microseconds"
    return moment.replace(tzinfo=None).isoformat(timespec=spec) + ("Z" if zoned else "")


def number_text(number: float) -> str:
    """A double as printed: 15 significant digits, no trailing zeros (``7``, ``0.7``, ``1e-07``),
    ``NaN``, ``INF`` and ``-INF`` as XML Schema writes them."""
    if math.isnan(number):
        return "NaN"
    if math.isinf(number):
        return "INF" if number > 0 else "-INF"
    text = f"{number:.{SIGNIFICANT_DIGITS}g}"
    return "0" if text == "-0" else text


def literal_text(literal: Literal) -> str:
    """The text a literal is printed as: its one form, a double to 15 significant digits."""
    found = canonical_literal(literal)
    if found.datatype == XSD_DOUBLE and not found.language:
        try:
            return number_text(float(found.value))
        except ValueError:
            return found.value
    return found.value


LiteralValue = str | int | float | bool | datetime.datetime
"""What a literal holds, as Python has it."""


def literal_value(term: Term | None) -> LiteralValue | None:
    """A term as the Python value it holds: numbers, booleans, date-times (aware when the store
    kept a zone) and text; an IRI or blank node as its text."""
    if term is None:
        return None
    if not isinstance(term, Literal):
        return term.value
    found = canonical_literal(term)
    datatype = found.datatype.value
    try:
        if found.datatype == XSD_INTEGER:
            return int(found.value)
        if found.datatype == XSD_DOUBLE:
            return float(found.value)
        if datatype == XSD_BOOLEAN:
            return found.value == "true"
        if datatype == XSD_DATE_TIME:
            return parse_datetime(found.value)
    except ValueError:
        pass
    return found.value


__all__ = [
    "INTEGER_TYPES",
    "LiteralValue",
    "canonical_literal",
    "canonical_rows",
    "canonical_term",
    "datetime_text",
    "literal_text",
    "literal_value",
    "number_text",
    "parse_datetime",
]
