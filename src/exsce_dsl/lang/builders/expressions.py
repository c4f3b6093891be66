"""Type-check a metric's expressions (its ``value`` and ``otherwise``) into the semantic model.

Each node gets a :class:`~exsce_dsl.model.expressions.Kind` (a constant, a number
or an array per message, a condition, one number per window), and the topic whose
times its values follow.  A field is looked up in its topic's type
(:mod:`exsce_dsl.messages.field_check`); a field of a type exsce does not know is
taken as a number per message, to be checked against the bag's definition.
Every problem is reported at the node it concerns, and stops the checks of the
nodes above it.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from exsce_dsl.errors import FieldProblem, SourceLocation
from exsce_dsl.lang.lexical import quantity_text
from exsce_dsl.messages.field_check import field_shape
from exsce_dsl.model.expressions import (
    AGGREGATES,
    CONDITION_AGGREGATES,
    FUNCTIONS,
    MAX_DEPTH,
    SERIES,
    Aggregate,
    Binary,
    Call,
    Expression,
    Field,
    Kind,
    Number,
    Unary,
    WindowValue,
    expression_depth,
)
from exsce_dsl.model.messages import FEEDBACK, GOALS, RESULT, WINDOWS, FieldPath, Fields, Index, Select, Step
from exsce_dsl.model.metrics import UNITS, ComputedFor, Dimension, TopicRead
from exsce_dsl.suggest import did_you_mean

if TYPE_CHECKING:  # parse trees come in; the parser (and textX) is not needed to read them
    from exsce_dsl.lang.parser import ParsedFile

_QUANTITY = re.compile(r"(\S+?)\s*([a-z/]+)?")
_NUMERIC = (Kind.CONSTANT, Kind.NUMBERS, Kind.ARRAYS, Kind.VALUE)
_PER_MESSAGE = (Kind.NUMBERS, Kind.ARRAYS, Kind.CONDITIONS, Kind.ARRAY_CONDITIONS)
_CONDITIONS = (Kind.CONDITIONS, Kind.ARRAY_CONDITIONS)


@dataclass(frozen=True)
class Typed:
    """An expression with its kind and, for per-message values, the topic whose times they follow."""

    expr: Expression
    kind: Kind
    clock: str | None = None


@dataclass
class Scope:
    """What a metric's expressions may name: its reads (with their types' fields, when known)
    and, for pairs of robots, the pair's binders."""

    subject: ComputedFor
    reads: dict[str, TopicRead]
    trees: dict[str, Fields]
    broken_reads: set[str]
    """Reads whose declaration has an error (already reported)."""
    pair: tuple[str, str] | None = None
    fields: list[Field] = field(default_factory=list)
    """Every field the expressions read, as they are checked."""


class _Failed(Exception):
    """An expression with an error (already reported): its parents are not checked further."""


def read_quantity(text: str) -> tuple[float, Dimension | None]:
    """A quantity token (``0.8 m/s``) in SI, with its unit's dimension (None without a unit)."""
    match = _QUANTITY.fullmatch(text.strip())
    assert match is not None  # the grammar's token
    number = float(match[1])
    if match[2] is None:
        return number, None
    dimension, factor = UNITS[match[2]]
    return number * factor, dimension


class ExpressionBuilder:
    """Checks the expressions of one metric; ``error(message, node)`` reports a problem."""

    def __init__(self, pf: ParsedFile, scope: Scope, error: Callable[[str, Any], None]) -> None:
        self.pf = pf
        self.scope = scope
        self.error = error

    def checked_value(self, tree: Any) -> Typed | None:
        try:
            typed = self._expr(tree)
        except _Failed:
            return None
        depth = expression_depth(typed.expr)
        if depth > MAX_DEPTH:
            self.error(
                f"this expression nests {depth} operations deep (each + or * of a sum or product is one): "
                f"exsce reads at most {MAX_DEPTH}",
                tree,
            )
            return None
        if typed.kind is not Kind.VALUE:
            self.error(
                f"a metric's value is one number per window, but this is {typed.kind.value}: "
                "aggregate it over time, e.g. max(...), mean(...), duration where ...",
                tree,
            )
            return None
        return typed

    def _expr(self, node: Any) -> Typed:
        kind = node.__class__.__name__
        method = getattr(self, f"_{kind.lower()}")
        result: Typed = method(node)
        return result

    def _fail(self, message: str, node: Any) -> _Failed:
        self.error(message, node)
        return _Failed()

    def _disjunction(self, node: Any) -> Typed:
        return self._logic(node, "or")

    def _conjunction(self, node: Any) -> Typed:
        return self._logic(node, "and")

    def _logic(self, node: Any, op: str) -> Typed:
        typed = [self._expr(o) for o in node.operands]
        result = typed[0]
        for operand, right in zip(node.operands[1:], typed[1:], strict=True):
            for side in (result, right):
                if side.kind not in _CONDITIONS:
                    raise self._fail(f"'{op}' joins conditions, but this is {side.kind.value}", operand)
            if result.clock != right.clock:
                raise self._fail(
                    f"'{op}' joins conditions on different topics ({result.clock}, {right.clock}): "
                    "compare values instead, which are aligned in time",
                    operand,
                )
            arrays = Kind.ARRAY_CONDITIONS in (result.kind, right.kind)
            result = Typed(
                Binary(op, result.expr, right.expr, self.pf.span(node)),
                Kind.ARRAY_CONDITIONS if arrays else Kind.CONDITIONS,
                result.clock,
            )
        return result

    def _negation(self, node: Any) -> Typed:
        inner = self._expr(node.operand)
        if not node.negated:
            return inner
        if inner.kind not in _CONDITIONS:
            raise self._fail(f"'not' negates a condition, but this is {inner.kind.value}", node)
        return Typed(Unary("not", inner.expr, self.pf.span(node)), inner.kind, inner.clock)

    def _comparison(self, node: Any) -> Typed:
        left = self._expr(node.left)
        if node.op is None or node.op == "":
            return left
        right = self._expr(node.right)
        combined = self._arithmetic(node.op, left, right, node)
        if combined.kind in (Kind.VALUE, Kind.CONSTANT):
            raise self._fail(
                "a metric is a number: comparisons of whole-window values belong in acceptance criteria",
                node,
            )
        kind = Kind.ARRAY_CONDITIONS if combined.kind is Kind.ARRAYS else Kind.CONDITIONS
        return Typed(combined.expr, kind, combined.clock)

    def _sum(self, node: Any) -> Typed:
        return self._chain(node)

    def _product(self, node: Any) -> Typed:
        return self._chain(node)

    def _chain(self, node: Any) -> Typed:
        result = self._expr(node.first)
        for tail in node.rest:
            result = self._arithmetic(tail.op, result, self._expr(tail.operand), tail.operand)
        return result

    def _arithmetic(self, op: str, left: Typed, right: Typed, node: Any) -> Typed:
        """``left op right`` for numbers (``op`` may be a comparison: same rules for the operands)."""
        typed = binary_type(op, left, right, self.pf.span(node))
        if isinstance(typed, str):
            raise self._fail(typed, node)
        return typed

    def _elementwise(self, expr: Expression, operands: list[Typed], node: Any) -> Typed:
        typed = elementwise_type(expr, operands)
        if isinstance(typed, str):
            raise self._fail(typed, node)
        return typed

    def _signed(self, node: Any) -> Typed:
        inner = self._expr(node.operand)
        if not node.minus:
            return inner
        if inner.kind not in _NUMERIC:
            raise self._fail(f"'-' needs a number, but this is {inner.kind.value}", node)
        return Typed(Unary("-", inner.expr, self.pf.span(node)), inner.kind, inner.clock)

    def _parenthesized(self, node: Any) -> Typed:
        return self._expr(node.inner)

    def _literal(self, node: Any) -> Typed:
        quantity = read_quantity(node.quantity)
        written = quantity_text(node.quantity)
        return Typed(Number(quantity[0], written, self.pf.span(node)), Kind.CONSTANT)

    def _windowvalue(self, node: Any) -> Typed:
        needed = FEEDBACK if node.name == "elapsed" else RESULT  # or the dispatcher's topic itself
        if not any(r.msgtype in (needed, GOALS) for r in self.scope.reads.values()):
            what = (
                "measures the robot's goals"
                if node.name == "elapsed"
                else "counts the robot's goals that succeeded"
            )
            raise self._fail(f"'{node.name}' {what}: read them (reads goals: robot goals)", node)
        if node.name == "succeeded" and self.scope.subject is not ComputedFor.ROBOT:
            raise self._fail("'succeeded' counts the waypoints of one robot: use it 'for each robot'", node)
        return Typed(WindowValue(node.name, self.pf.span(node)), Kind.VALUE)

    def _fieldlength(self, node: Any) -> Typed:
        return self._fieldpath(node.path, length=True, at=node)

    def _fieldpath(self, node: Any, length: bool = False, at: Any = None) -> Typed:
        at = at or node
        parts = list(node.parts)
        robot = None
        if self.scope.subject is ComputedFor.MISSION:
            raise self._fail(
                "a mission metric reads every robot's topics, so a field does not say whose: "
                "use 'for each pair of robots (a, b)' and a.<topic>..., or 'elapsed'",
                at,
            )
        if self.scope.pair is not None:
            if parts[0].name not in self.scope.pair:
                written = self.pf.text[node._tx_position : node._tx_position_end]
                a, b = self.scope.pair
                raise self._fail(f"say whose topic this is: {a}.{written} or {b}.{written}", at)
            robot = parts[0].name
            self._not_an_array(parts.pop(0), f"'{robot}' is a robot")
            if not parts:
                raise self._fail(f"'{robot}' is a robot: name one of its topics", at)
        first = parts[0]
        read = self.scope.reads.get(first.name)
        if read is None and first.name in self.scope.broken_reads:
            raise _Failed()  # its declaration's error says enough
        if read is None:
            raise self._fail(f"unknown topic '{first.name}'{did_you_mean(first.name, self.scope.reads)}", at)
        self._not_an_array(first, f"'{read.name}' is a topic")
        if read.msgtype in WINDOWS:
            whose = "robot's goals are" if read.signal else f"dispatcher's {read.msgtype} is"
            raise self._fail(f"the {whose} read as windows: use 'elapsed' or 'succeeded'", at)
        path = FieldPath(tuple(step for part in parts[1:] for step in _steps(part)), length)
        arrays = False
        tree = self.scope.trees.get(read.name)
        if tree is not None:
            try:
                arrays = field_shape(tree, path, read.name, read.msgtype)
            except FieldProblem as problem:
                raise self._fail(problem.message, at) from None
        expr = Field(read.name, path, robot, arrays, self.pf.span(at))
        self.scope.fields.append(expr)
        return Typed(expr, Kind.ARRAYS if arrays else Kind.NUMBERS, expr.clock)

    def _not_an_array(self, part: Any, what: str) -> None:
        if part.picks:
            raise self._fail(f"{what}, not an array: [...] picks an element of an array field", part.picks[0])

    def _call(self, node: Any) -> Typed:
        func = node.func
        if func not in FUNCTIONS:
            raise self._fail(_unknown_function(func), node)
        if func in AGGREGATES:
            return self._aggregate(node)
        args = [self._argument(a, allow_where=False) for a in node.args]
        if func in SERIES:
            return self._series(node, args)
        if func in ("abs", "sqrt") and len(args) != 1:
            raise self._fail(f"{func}(...) takes one value, not {len(args)}", node)
        for arg in args:
            if arg.kind not in _NUMERIC:
                raise self._fail(f"{func}(...) needs numbers, but this is {arg.kind.value}", node)
        expr = Call(func, tuple(a.expr for a in args), self.pf.span(node))
        kinds = {a.kind for a in args}
        if kinds <= {Kind.CONSTANT}:
            return Typed(expr, Kind.CONSTANT)
        if Kind.VALUE in kinds:
            if kinds - {Kind.VALUE, Kind.CONSTANT}:
                raise self._fail(f"{func}(...) mixes one number per window with values per message", node)
            return Typed(expr, Kind.VALUE)
        return self._elementwise(expr, args, node)

    def _series(self, node: Any, args: list[Typed]) -> Typed:
        """``speed(x, y[, z])``, ``derivative(v)``: a number per message of one topic, over time."""
        func = node.func
        speed = func == "speed"
        if len(args) not in ((2, 3) if speed else (1,)):
            wanted = "two or three coordinates (x, y[, z])" if speed else "one value"
            raise self._fail(f"{func}(...) takes {wanted}, not {len(args)}", node)
        for arg in args:
            if arg.kind is not Kind.NUMBERS:
                raise self._fail(
                    f"{func}(...) is over a number per message, in time, but this is {arg.kind.value}", node
                )
        if len({a.clock for a in args}) > 1:
            raise self._fail(f"{func}(...) needs its values on one topic", node)
        expr = Call(func, tuple(a.expr for a in args), self.pf.span(node))
        return Typed(expr, Kind.NUMBERS, args[0].clock)

    def _argument(self, arg: Any, allow_where: bool) -> Typed:
        if arg.condition is not None and not allow_where:
            raise self._fail(
                "'where' filters the values of an aggregate over time, e.g. min(x where ...)", arg
            )
        return self._expr(arg.value)

    def _aggregate(self, node: Any) -> Typed:
        func = node.func
        args = [self._expr(a.value) for a in node.args]
        wheres = [a for a in node.args if a.condition is not None]
        arity = (2, 3) if func == "path_length" else (1,)
        if len(args) not in arity:
            wanted = "two or three values (x, y[, z])" if func == "path_length" else "one value"
            raise self._fail(f"{func}(...) takes {wanted}, not {len(args)}", node)
        for arg in args:
            if arg.kind in _CONDITIONS:
                raise self._fail(
                    f"{func}(...) is over numbers, but this is {arg.kind.value}: "
                    "use 'count where ...' or 'duration where ...'",
                    node,
                )
            if arg.kind not in _PER_MESSAGE:
                raise self._fail(
                    f"{func}(...) aggregates values per message over time, but this is {arg.kind.value}",
                    node,
                )
            if arg.kind is Kind.ARRAYS and func not in ("min", "max", "mean", "sum"):
                raise self._fail(
                    f"{func}(...) of an array has no single time course: take min, max, mean or sum", node
                )
        if len({a.clock for a in args}) > 1:
            raise self._fail(f"{func}(...) needs its values on one topic", node)
        where: Expression | None = None
        if wheres:
            if len(wheres) > 1 or func in ("integral", "change", "path_length"):
                raise self._fail(f"{func}(...) takes no 'where'", wheres[0])
            condition = self._expr(wheres[0].condition)
            if condition.kind not in _CONDITIONS:
                raise self._fail(f"'where' needs a condition, but this is {condition.kind.value}", wheres[0])
            if condition.clock != args[0].clock:
                raise self._fail(
                    f"the condition is on {condition.clock}, the values on {args[0].clock}: "
                    "filter a topic by its own fields",
                    wheres[0],
                )
            if condition.kind is Kind.ARRAY_CONDITIONS and args[0].kind is not Kind.ARRAYS:
                raise self._fail("a condition per array element filters an array, not a number", wheres[0])
            where = condition.expr
        return Typed(Aggregate(func, tuple(a.expr for a in args), where, self.pf.span(node)), Kind.VALUE)

    def _whereaggregate(self, node: Any) -> Typed:
        condition = self._expr(node.condition)
        if condition.kind is not Kind.CONDITIONS:
            raise self._fail(
                f"'{node.func} where' needs a condition per message, but this is {condition.kind.value}",
                node,
            )
        return Typed(Aggregate(node.func, (), condition.expr, self.pf.span(node)), Kind.VALUE)


def _unknown_function(name: str) -> str:
    if name in CONDITION_AGGREGATES:
        return f"'{name}' is written without parentheses: {name} where <condition>"
    return f"unknown function '{name}'{did_you_mean(name, FUNCTIONS)} (the functions: {', '.join(FUNCTIONS)})"


def _steps(part: Any) -> list[Step]:
    """A written part of a path (``transforms[0]``): its name, then its picks."""
    steps: list[Step] = [part.name]
    for pick in part.picks:
        if pick.select is None:
            steps.append(Index(int(pick.index)))
            continue
        number = pick.select.number
        value = float(number) if number is not None else str(pick.select.text)
        steps.append(Select(tuple(pick.select.field), value))
    return steps


def binary_type(op: str, left: Typed, right: Typed, where: SourceLocation) -> Typed | str:
    """``left op right`` for numbers (``op`` may be a comparison: same rules for the operands),
    or why the operands do not go together."""
    for side in (left, right):
        if side.kind not in _NUMERIC:
            return f"'{op}' needs numbers, but one side is {side.kind.value}"
    expr = Binary(op, left.expr, right.expr, where)
    kinds = {left.kind, right.kind}
    if kinds <= {Kind.CONSTANT}:
        return Typed(expr, Kind.CONSTANT)
    if Kind.VALUE in kinds:
        if kinds - {Kind.VALUE, Kind.CONSTANT}:
            return (
                "this mixes one number per window with values per message: aggregate the "
                "per-message values first (e.g. max(...))"
            )
        return Typed(expr, Kind.VALUE)
    return elementwise_type(expr, [left, right])


def elementwise_type(expr: Expression, operands: list[Typed]) -> Typed | str:
    """Per-message operands: arrays broadcast over numbers; other topics are aligned in time
    (or why they cannot be)."""
    per_message = [o for o in operands if o.kind in _PER_MESSAGE]
    clock = per_message[0].clock
    arrays = any(o.kind is Kind.ARRAYS for o in per_message)
    for other in per_message[1:]:
        if other.clock == clock:
            continue
        if arrays:
            return f"arrays cannot be aligned in time: {clock} and {other.clock} are different topics"
        clock = f"{clock}&{other.clock}"
    return Typed(expr, Kind.ARRAYS if arrays else Kind.NUMBERS, clock)
