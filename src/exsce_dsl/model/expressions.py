"""Metric expressions: a small language over message fields, as a checked tree.

The builder (``lang.builders.metrics``) type-checks every node; a tree here is
known to be well formed: fields exist in their message type, aggregates are
over numbers, a metric's value is one number per window.  (A field of a type
exsce does not know is checked later, against the bag's definition, by
``messages.field_check``.)
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.messages import FieldPath


class Kind(enum.Enum):
    """What an expression is, per window of a run."""

    CONSTANT = "a constant"
    NUMBERS = "a number per message"
    ARRAYS = "an array of numbers per message"
    CONDITIONS = "a condition per message"
    ARRAY_CONDITIONS = "a condition per array element"
    VALUE = "one number per window"


@dataclass(frozen=True)
class Number:
    value: float
    """In SI units."""
    written: str | None = field(default=None, compare=False)
    """As written, unit included (``0.8 m/s``), for the formatter."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Field:
    """A message field of a topic: ``vel.linear.x``, ``tf.transforms[0].transform.translation.x``,
    ``len(diag.status)``; ``robot`` is the pair binder (``a``) if any."""

    read: str
    path: FieldPath
    robot: str | None = None
    arrays: bool = False
    """An array per message: an array field, or a field of every element of an array of messages
    (``tf.transforms.transform.translation.x``).  False for a type unknown when checked."""
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    @property
    def clock(self) -> str:
        """The topic whose receive times the values follow."""
        return f"{self.robot}.{self.read}" if self.robot else self.read


@dataclass(frozen=True)
class Unary:
    op: str  # "-" | "not"
    operand: Expression
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Binary:
    """Arithmetic, comparison or logic.  Operands on different topics are time-aligned: the
    right one is interpolated at the left one's times, where both have data."""

    op: str  # + - * / < <= > >= == != and or
    left: Expression
    right: Expression
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Call:
    """A function per message: element-wise ``norm``, ``abs``, ``sqrt``, or over the series of
    one topic, ``speed`` (of positions) and ``derivative`` (of a number), per second."""

    func: str
    args: tuple[Expression, ...]
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Aggregate:
    """Over time, within a window: ``min max mean sum first last integral change path_length``,
    ``duration`` and ``count`` (of a condition).  ``where`` keeps the elements it holds for."""

    func: str
    args: tuple[Expression, ...]
    where: Expression | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class WindowValue:
    """``elapsed`` (seconds the window lasts) or ``succeeded`` (waypoints the dispatcher reports
    SUCCEEDED)."""

    name: str
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


Expression = Number | Field | Unary | Binary | Call | Aggregate | WindowValue

AGGREGATES = ("min", "max", "mean", "sum", "first", "last", "integral", "change", "path_length")
CONDITION_AGGREGATES = ("duration", "count")
ELEMENTWISE = ("norm", "abs", "sqrt")
SERIES = ("speed", "derivative")
"""Functions of a topic's values over time, one value per message (see ``monitor_core.speed``)."""
FUNCTIONS = (*AGGREGATES, *ELEMENTWISE, *SERIES)
"""Every function written ``name(...)`` (``duration`` and ``count`` are written ``... where``)."""
WINDOW_VALUES = ("elapsed", "succeeded")


def is_constant(expr: Expression) -> bool:
    """Whether ``expr`` is the same number in every window (``-1``, ``(0 - 100) * 2``): it reads
    no field, aggregates nothing and names no window value."""
    return not any(isinstance(n, (Field, Aggregate, WindowValue)) for n in walk(expr))


def walk(expr: Expression) -> list[Expression]:
    """Every node of ``expr``, parents before children."""
    found: list[Expression] = [expr]
    if isinstance(expr, Unary):
        found += walk(expr.operand)
    elif isinstance(expr, Binary):
        found += walk(expr.left) + walk(expr.right)
    elif isinstance(expr, (Call, Aggregate)):
        for arg in expr.args:
            found += walk(arg)
        if isinstance(expr, Aggregate) and expr.where is not None:
            found += walk(expr.where)
    return found


MAX_DEPTH = 100
"""The deepest expression a metric may hold, in operations within operations (a sum of n terms
is n - 1 deep): every later stage (the generated monitors, Python's parser, which allows 200
nested parentheses, pickling) walks an expression by recursion (issue 46: a sum of 500 terms
passed ``check`` and broke ``generate``)."""


def expression_depth(expr: Expression) -> int:
    """How many operations deep ``expr`` is (a leaf: 0), counted without recursion."""
    deepest = 0
    pending: list[tuple[Expression, int]] = [(expr, 0)]
    while pending:
        node, depth = pending.pop()
        deepest = max(deepest, depth)
        children: list[Expression] = []
        if isinstance(node, Unary):
            children = [node.operand]
        elif isinstance(node, Binary):
            children = [node.left, node.right]
        elif isinstance(node, (Call, Aggregate)):
            children = list(node.args)
            if isinstance(node, Aggregate) and node.where is not None:
                children.append(node.where)
        pending.extend((child, depth + 1) for child in children)
    return deepest
