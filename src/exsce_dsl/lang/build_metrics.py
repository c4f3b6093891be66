"""Build metric declarations (``metric NAME for ... { ... }``) and type-check their expressions.

Every problem is reported at its ``file:line:col``: an unknown topic or field of
a message type (with a did-you-mean), an aggregate over something that is not a
number, per-message values mixed with one number per window, a value that cannot
be combined over segments.  A checked metric is safe to turn into code: its
name is a Python identifier and every other name in it was looked up.
"""

from __future__ import annotations

import keyword
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.lang.suggest import did_you_mean
from exsce_dsl.model.expressions import (
    AGGREGATES,
    Aggregate,
    Binary,
    Call,
    Expression,
    Field,
    Kind,
    Number,
    Unary,
    WindowValue,
)
from exsce_dsl.model.messages import DISPATCHER, FEEDBACK, MESSAGES, RESULT, Leaf, canonical_type, field_of
from exsce_dsl.model.metrics import (
    SI_UNIT,
    UNITS,
    Combine,
    Dimension,
    MetricDefinition,
    SafetyLimit,
    Subject,
    TopicRead,
)

Report = Callable[[str, SourceLocation | None], None]

_PYTHON_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_TOPIC = re.compile(r"/?(?:[A-Za-z0-9_]|\{ns\})+(?:/(?:[A-Za-z0-9_]|\{ns\})+)*")
_QUANTITY = re.compile(r"(\S+?)\s*([a-z/]+)?")
_NUMERIC = (Kind.CONSTANT, Kind.NUMBERS, Kind.ARRAYS, Kind.VALUE)
_PER_MESSAGE = (Kind.NUMBERS, Kind.ARRAYS, Kind.CONDITIONS, Kind.ARRAY_CONDITIONS)
_CONDITIONS = (Kind.CONDITIONS, Kind.ARRAY_CONDITIONS)
_COMBINE = {
    "sum": Combine.SUM,
    "integral": Combine.SUM,
    "change": Combine.SUM,
    "path_length": Combine.SUM,
    "duration": Combine.SUM,
    "count": Combine.SUM,
    "elapsed": Combine.SUM,
    "min": Combine.MIN,
    "max": Combine.MAX,
}
_COUNTS = ("count", "succeeded")


@dataclass(frozen=True)
class Typed:
    """An expression with its kind and, for per-message values, the topic whose times they follow."""

    expr: Expression
    kind: Kind
    clock: str | None = None


class _Failed(Exception):
    """An expression with an error (already reported): its parents are not checked further."""


def build_metric(
    pf: ParsedFile,
    tree: Any,
    report: Report,
    reserved: Mapping[str, str] | None = None,
    standard: bool = False,
    name_location: SourceLocation | None = None,
) -> MetricDefinition | None:
    """The metric declared by ``tree``, or None if it has errors (all of them are reported).

    ``reserved``: names a metric may not take, with why (the standard library's metrics).
    Errors about the whole metric are reported at ``name_location`` (else at its start).
    """
    return _MetricBuilder(pf, report, standard, name_location).build(tree, reserved or {})


class _MetricBuilder:
    def __init__(
        self, pf: ParsedFile, report: Report, standard: bool, name_location: SourceLocation | None
    ) -> None:
        self.pf = pf
        self.name_location = name_location
        self.broken_reads: set[str] = set()
        self.report = report
        self.standard = standard
        self.failed = False
        self.reads: dict[str, TopicRead] = {}
        self.pair: tuple[str, str] | None = None
        self.subject = Subject.ROBOT

    def error(self, message: str, node: Any) -> None:
        self.failed = True
        where = self.pf.span(node)
        if node.__class__.__name__ == "Metric" and self.name_location is not None:
            where = self.name_location
        self.report(message, where)

    def build(self, tree: Any, reserved: Mapping[str, str]) -> MetricDefinition | None:
        name = tree.name
        if not _PYTHON_NAME.fullmatch(name) or keyword.iskeyword(name):
            self.error(f"metric name '{name}' must be letters, digits and '_' (it names code and RDF)", tree)
        elif name in reserved:
            self.error(f"metric '{name}' {reserved[name]}; choose another name", tree)
        if tree.pairs is not None:
            self.subject = Subject.PAIRS
            self.pair = (tree.pairs.first, tree.pairs.second)
            if self.pair[0] == self.pair[1]:
                self.error(f"the two robots of a pair need two names, not '{self.pair[0]}' twice", tree.pairs)
        elif tree.mission:
            self.subject = Subject.MISSION
        for read in tree.reads:
            self._read(read)
        value = self._checked_value(tree.value)
        fallback = self._checked_value(tree.fallback) if tree.fallback is not None else None
        dimension = self._dimension(tree, value)
        safety = self._safety(tree, value, dimension) if tree.safety is not None else None
        combine = self._combine(tree, value, fallback)
        if self.failed or value is None or dimension is None:
            return None
        return MetricDefinition(
            name,
            self.subject,
            bool(tree.per_segment),
            dimension,
            tuple(self.reads.values()),
            value.expr,
            fallback.expr if fallback is not None else None,
            safety,
            tree.meaning or "",
            self.pair,
            combine,
            self.standard,
            self.pf.span(tree),
        )

    # ------------------------------------------------------------ declarations
    def _read(self, read: Any) -> None:
        msgtype = canonical_type(read.msgtype)
        self.broken_reads.add(read.name)  # until it is known to be good
        if read.name in self.reads:
            self.error(f"topic '{read.name}' is read twice in this metric", read)
            return
        if self.pair is not None and read.name in self.pair:
            self.error(f"'{read.name}' names a robot of the pair; give the topic another name", read)
            return
        if msgtype not in MESSAGES and msgtype not in DISPATCHER:
            known = sorted([*MESSAGES, *DISPATCHER])
            self.error(
                f"exsce does not decode {read.msgtype}{did_you_mean(msgtype, known)} "
                f"(it reads {', '.join(known)})",
                read,
            )
            return
        if not _TOPIC.fullmatch(read.topic) or "{" in read.topic.replace("{ns}", ""):
            self.error(
                f"'{read.topic}' is not a ROS topic name (letters, digits, '_' and '/'; "
                "'{ns}' for the robot's namespace)",
                read,
            )
            return
        if self.subject is not Subject.MISSION and "{ns}" not in read.topic:
            self.error(f"a topic of each robot needs '{{ns}}' in its name: '{read.topic}'", read)
            return
        self.reads[read.name] = TopicRead(read.name, msgtype, read.topic, self.pf.span(read))
        self.broken_reads.discard(read.name)

    def _dimension(self, tree: Any, value: Typed | None) -> Dimension | None:
        if tree.unit is None:
            counted = value is not None and _top(value.expr) in _COUNTS
            return Dimension.COUNT if counted else Dimension.NUMBER
        dimension, factor = UNITS[tree.unit]
        if factor != 1.0:
            self.error(
                f"a metric's values are in SI units, as ROS messages are: write "
                f"'{SI_UNIT[dimension]}', not '{tree.unit}'",
                tree,
            )
            return None
        return dimension

    def _safety(self, tree: Any, value: Typed | None, dimension: Dimension | None) -> SafetyLimit | None:
        limit = self._quantity(tree.safety.limit, tree.safety)
        if limit is None or value is None or dimension is None:
            return None
        number, unit_dimension = limit
        if unit_dimension is not None and unit_dimension is not dimension:
            self.error(
                f"the limit is a {unit_dimension.value}, but '{tree.name}' is a {dimension.value}",
                tree.safety,
            )
            return None
        wanted = "max" if tree.safety.bound == "below" else "min"
        if _top(value.expr) != wanted or not isinstance(value.expr, Aggregate):
            self.error(
                f"a metric that stays {tree.safety.bound} a limit is the {wanted}(...) of its values, "
                "so that every value over the limit counts as a violation",
                tree.safety,
            )
            return None
        return SafetyLimit(tree.safety.bound, number)

    def _combine(self, tree: Any, value: Typed | None, fallback: Typed | None) -> Combine | None:
        if value is None or not (tree.per_segment or self.subject is Subject.PAIRS):
            return None
        combines = {_COMBINE.get(_top(t.expr) or "") for t in (value, fallback) if t is not None}
        top = _top(value.expr)
        why = "its values over path segments" if tree.per_segment else "its values over the pairs of robots"
        if top == "succeeded":
            self.error("'succeeded' counts the waypoints of the whole run, not of a path segment", tree)
            return None
        if len(combines) != 1 or None in combines:
            self.error(
                f"'{tree.name}' must be one sum, integral, change, path_length, duration, count, "
                f"elapsed, min or max (possibly of an expression) so that {why} make one value",
                tree,
            )
            return None
        return combines.pop()

    def _quantity(self, text: str, node: Any) -> tuple[float, Dimension | None] | None:
        match = _QUANTITY.fullmatch(text.strip())
        assert match is not None  # the grammar's token
        number = float(match[1])
        if match[2] is None:
            return number, None
        dimension, factor = UNITS[match[2]]
        return number * factor, dimension

    # ------------------------------------------------------------- expressions
    def _checked_value(self, tree: Any) -> Typed | None:
        try:
            typed = self._expr(tree)
        except _Failed:
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
        for side in (left, right):
            if side.kind not in _NUMERIC:
                raise self._fail(f"'{op}' needs numbers, but one side is {side.kind.value}", node)
        where = self.pf.span(node)
        expr = Binary(op, left.expr, right.expr, where)
        kinds = {left.kind, right.kind}
        if kinds <= {Kind.CONSTANT}:
            return Typed(expr, Kind.CONSTANT)
        if Kind.VALUE in kinds:
            if kinds - {Kind.VALUE, Kind.CONSTANT}:
                raise self._fail(
                    "this mixes one number per window with values per message: aggregate the "
                    "per-message values first (e.g. max(...))",
                    node,
                )
            return Typed(expr, Kind.VALUE)
        return self._elementwise(expr, [left, right], node)

    def _elementwise(self, expr: Expression, operands: list[Typed], node: Any) -> Typed:
        """Per-message operands: arrays broadcast over numbers; other topics are aligned in time."""
        per_message = [o for o in operands if o.kind in _PER_MESSAGE]
        clock = per_message[0].clock
        arrays = any(o.kind is Kind.ARRAYS for o in per_message)
        for other in per_message[1:]:
            if other.clock == clock:
                continue
            if arrays:
                raise self._fail(
                    f"arrays cannot be aligned in time: {clock} and {other.clock} are different topics",
                    node,
                )
            clock = f"{clock}&{other.clock}"
        return Typed(expr, Kind.ARRAYS if arrays else Kind.NUMBERS, clock)

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
        quantity = self._quantity(node.quantity, node)
        assert quantity is not None
        written = " ".join(node.quantity.split())
        return Typed(Number(quantity[0], written, self.pf.span(node)), Kind.CONSTANT)

    def _windowvalue(self, node: Any) -> Typed:
        needed = FEEDBACK if node.name == "elapsed" else RESULT
        if not any(r.msgtype == needed for r in self.reads.values()):
            which = "feedback" if node.name == "elapsed" else "result"
            raise self._fail(
                f"'{node.name}' comes from the waypoint dispatcher: read its {which} topic "
                f'(reads {which}: {needed} on "/{{ns}}/waypoint_dispatcher/{which}")',
                node,
            )
        if node.name == "succeeded" and self.subject is not Subject.ROBOT:
            raise self._fail("'succeeded' counts the waypoints of one robot: use it 'for each robot'", node)
        return Typed(WindowValue(node.name, self.pf.span(node)), Kind.VALUE)

    def _fieldpath(self, node: Any) -> Typed:
        parts = list(node.parts)
        robot = None
        if self.subject is Subject.MISSION:
            raise self._fail(
                "a mission metric reads every robot's topics, so a field does not say whose: "
                "use 'for each pair of robots (a, b)' and a.<topic>..., or 'elapsed'",
                node,
            )
        if self.pair is not None:
            if parts[0] not in self.pair:
                raise self._fail(
                    f"say whose topic this is: {self.pair[0]}.{'.'.join(parts)} or "
                    f"{self.pair[1]}.{'.'.join(parts)}",
                    node,
                )
            robot = parts.pop(0)
            if not parts:
                raise self._fail(f"'{robot}' is a robot: name one of its topics", node)
        read = self.reads.get(parts[0])
        if read is None and parts[0] in self.broken_reads:
            raise _Failed()  # its declaration's error says enough
        if read is None:
            raise self._fail(f"unknown topic '{parts[0]}'{did_you_mean(parts[0], self.reads)}", node)
        if read.msgtype in DISPATCHER:
            raise self._fail(
                f"the dispatcher's {read.msgtype} is read as windows: use 'elapsed' or 'succeeded'", node
            )
        path = tuple(parts[1:])
        found = field_of(read.msgtype, path)
        if found is None:
            done: tuple[str, ...] = ()
            for part in path:
                here = field_of(read.msgtype, done)
                if not isinstance(here, dict) or part not in here:
                    options = list(here) if isinstance(here, dict) else []
                    owner = ".".join((read.name, *done))
                    raise self._fail(
                        f"{owner} ({read.msgtype}{'.' + '.'.join(done) if done else ''}) has no field "
                        f"'{part}'{did_you_mean(part, options)}",
                        node,
                    )
                done = (*done, part)
        text = ".".join((read.name, *path))
        if isinstance(found, dict):
            raise self._fail(
                f"{text} is a message ({', '.join(found)}), not a number: name one of its fields", node
            )
        if found is Leaf.TEXT:
            raise self._fail(f"{text} is text, not a number", node)
        expr = Field(read.name, path, robot, self.pf.span(node))
        return Typed(expr, Kind.ARRAYS if found is Leaf.ARRAY else Kind.NUMBERS, expr.clock)

    def _call(self, node: Any) -> Typed:
        func = node.func
        if func in AGGREGATES:
            return self._aggregate(node)
        args = [self._argument(a, allow_where=False) for a in node.args]
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


def _top(expr: Expression) -> str | None:
    """The aggregate (or window value) a metric's value is, if it is one."""
    if isinstance(expr, Aggregate):
        return expr.func
    if isinstance(expr, WindowValue):
        return expr.name
    return None
