"""The canonical text of ``metric`` declarations and their expressions (the formatter's part).

Numbers print as written, units included (``0.8 m/s``; a safety limit too), and
parentheses only where precedence needs them, so parse → print → parse is stable.
A field prints as written: ``tf.transforms[child_frame_id == "base_link"].transform``,
``scan.ranges[-1]``, ``len(diag.status)``.
"""

from __future__ import annotations

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.expressions import read_quantity
from exsce_dsl.lang.lexical import as_written
from exsce_dsl.lang.lexical import number_text as _number
from exsce_dsl.lang.lexical import string_literal as _string
from exsce_dsl.model.expressions import Aggregate, Binary, Expression, Field, Number, Unary, WindowValue
from exsce_dsl.model.messages import Index
from exsce_dsl.model.metrics import ComputedFor, MetricDefinition

INDENT = "  "
Line = tuple[str, SourceLocation | None]

_PRECEDENCE = {"or": 1, "and": 2, "not": 3, "<": 4, "<=": 4, ">": 4, ">=": 4, "==": 4, "!=": 4}
_PRECEDENCE |= {"+": 5, "-": 5, "*": 6, "/": 6}
_NEGATION = 7
_ATOM = 8


def metric_lines(metric: MetricDefinition) -> list[Line]:
    if metric.subject is ComputedFor.PAIRS:
        assert metric.pair is not None
        subject = f"each pair of robots ({metric.pair[0]}, {metric.pair[1]})"
    else:
        subject = metric.subject.value
    segment = " per segment" if metric.per_segment else ""
    lines: list[Line] = [(f"metric {metric.name} for {subject}{segment} {{", metric.location)]
    if metric.meaning:
        lines.append((f"{INDENT}{_string(metric.meaning)}", None))
    if metric.unit:
        lines.append((f"{INDENT}unit {metric.unit}", None))
    if metric.safety is not None:
        written = as_written(
            [metric.safety.limit], [metric.safety.written] if metric.safety.written else [], _si
        )
        limit = written[0] if written else f"{_number(metric.safety.limit)} {metric.unit}".rstrip()
        lines.append((f"{INDENT}safe {metric.safety.bound} {limit}", None))
    for read in metric.reads:
        source = f"robot {read.signal}" if read.signal else f"{read.msgtype} on {_string(read.topic)}"
        lines.append((f"{INDENT}reads {read.name}: {source}", read.location))
    lines.append((f"{INDENT}value {expression_text(metric.value)}", None))
    if metric.fallback is not None:
        lines.append((f"{INDENT}otherwise {expression_text(metric.fallback)}", None))
    lines.append(("}", None))
    return lines


def _si(text: str) -> float:
    return read_quantity(text)[0]


def expression_text(expr: Expression) -> str:
    return _text(expr)[0]


def _text(expr: Expression) -> tuple[str, int]:
    """The text of ``expr`` and the precedence of its outermost operator."""
    if isinstance(expr, Number):
        return expr.written or _number(expr.value), _ATOM
    if isinstance(expr, Field):
        return field_text(expr), _ATOM
    if isinstance(expr, WindowValue):
        return expr.name, _ATOM
    if isinstance(expr, Unary):
        if expr.op == "not":
            return f"not {_operand(expr.operand, _PRECEDENCE['not'] + 1)}", _PRECEDENCE["not"]
        return f"-{_operand(expr.operand, _ATOM)}", _NEGATION
    if isinstance(expr, Binary):
        level = _PRECEDENCE[expr.op]
        # left-associative: the right operand needs parentheses at the same level
        left = _operand(expr.left, level)
        right = _operand(expr.right, level + 1)
        return f"{left} {expr.op} {right}", level
    if isinstance(expr, Aggregate) and expr.func in ("duration", "count"):
        assert expr.where is not None
        return f"{expr.func} where {expression_text(expr.where)}", 0
    args = ", ".join(expression_text(a) for a in expr.args)
    if isinstance(expr, Aggregate) and expr.where is not None:
        args += f" where {expression_text(expr.where)}"
    return f"{expr.func}({args})", _ATOM


def field_text(f: Field) -> str:
    """``a.odom.pose.pose.position.x``, ``len(diag.status)``: a field as the language writes it."""
    text = f"{f.robot}.{f.read}" if f.robot else f.read
    for step in f.path.steps:
        if isinstance(step, str):
            text += f".{step}"
        elif isinstance(step, Index):
            text += f"[{step.position}]"
        else:
            value = _string(step.value) if isinstance(step.value, str) else _select_number(step.value)
            text += f"[{'.'.join(step.field)} == {value}]"
    return f"len({text})" if f.path.length else text


def _select_number(value: float) -> str:
    """A whole number without its ``.0`` (``[status == 3]``), else the shortest text of it."""
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else _number(value)


def _operand(expr: Expression, needed: int) -> str:
    text, level = _text(expr)
    return text if level >= needed else f"({text})"
