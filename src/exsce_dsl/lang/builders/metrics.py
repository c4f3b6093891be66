"""Build metric declarations (``metric NAME for ... { ... }``): what a metric is said of, the
topics it reads, its unit, safety limit and how its values combine; its expressions are
checked by :mod:`exsce_dsl.lang.builders.expressions`.

Every problem is reported at its ``file:line:col``: an unknown topic or field of
a message type (with a did-you-mean), an aggregate over something that is not a
number, per-message values mixed with one number per window, a value that cannot
be combined over segments.  A checked metric is safe to turn into code: its
name is a Python identifier and every other name in it was looked up.

Message types come from a catalogue (the user's definitions over rosbags'
standard packages, :func:`exsce_dsl.messages.user.configured_catalogue`).  A
type it lacks is a warning, not an error: the bag may define it, and its fields
are checked against the bag's definition when the bag is read
(:mod:`exsce_dsl.messages.field_check`).
"""

from __future__ import annotations

import dataclasses
import keyword
import re
from collections.abc import Mapping
from typing import Any, Protocol

from exsce_dsl.errors import MessageTypeError, Remedied, Severity, SourceLocation
from exsce_dsl.lang.builders.expressions import ExpressionBuilder, Scope, Typed, read_quantity
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.messages.catalogue import MessageCatalogue
from exsce_dsl.model.expressions import Aggregate, Expression, WindowValue
from exsce_dsl.model.messages import WINDOWS, Fields, canonical_type
from exsce_dsl.model.metrics import (
    SI_UNIT,
    SIGNAL_TYPES,
    UNITS,
    Combine,
    ComputedFor,
    Dimension,
    MetricDefinition,
    SafetyLimit,
    TopicRead,
    signal_pattern,
)
from exsce_dsl.model.names import ROS_TOPIC_RULE, TOPIC_RULE, is_ros_topic, is_topic_pattern
from exsce_dsl.remedies import DEFINE_THE_TYPE
from exsce_dsl.suggest import did_you_mean


class Report(Protocol):
    """Where problems go: an error (the metric is not built) or a warning."""

    def __call__(
        self,
        message: str,
        location: SourceLocation | None,
        severity: Severity = Severity.ERROR,
        remedied: Remedied | None = None,
        /,
    ) -> None: ...


_PYTHON_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
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


def build_metric(
    pf: ParsedFile,
    tree: Any,
    report: Report,
    reserved: Mapping[str, str] | None = None,
    standard: bool = False,
    name_location: SourceLocation | None = None,
    catalogue: MessageCatalogue | None = None,
) -> MetricDefinition | None:
    """The metric declared by ``tree``, or None if it has errors (all of them are reported).

    ``reserved``: names a metric may not take, with why (the standard library's metrics).
    Errors about the whole metric are reported at ``name_location`` (else at its start).
    ``catalogue``: the message types known (else the configured one: the user's and the
    standard types).
    """
    builder = _MetricBuilder(pf, report, standard, name_location, catalogue)
    return builder.build(tree, reserved or {})


class _MetricBuilder:
    def __init__(
        self,
        pf: ParsedFile,
        report: Report,
        standard: bool,
        name_location: SourceLocation | None,
        catalogue: MessageCatalogue | None,
    ) -> None:
        self.pf = pf
        self.name_location = name_location
        self.broken_reads: set[str] = set()
        self.report = report
        self.standard = standard
        self.failed = False
        self.reads: dict[str, TopicRead] = {}
        self.trees: dict[str, Fields] = {}
        """The fields of each read's type, if the catalogue knows it."""
        self.pair: tuple[str, str] | None = None
        self.subject = ComputedFor.ROBOT
        self._catalogue = catalogue

    def error(self, message: str, node: Any) -> None:
        self.failed = True
        where = self.pf.span(node)
        if node.__class__.__name__ == "Metric" and self.name_location is not None:
            where = self.name_location
        self.report(message, where)

    def warning(self, message: str, node: Any, remedied: Remedied | None = None) -> None:
        self.report(message, self.pf.span(node), Severity.WARNING, remedied)

    def catalogue(self) -> MessageCatalogue:
        if self._catalogue is None:
            from exsce_dsl.messages.catalogue import standard_catalogue
            from exsce_dsl.messages.user import configured_catalogue

            try:
                self._catalogue = configured_catalogue()
            except MessageTypeError as exc:  # a user's file: said once (no location), standard types used
                self.failed = True
                self.report(exc.message, None)
                self._catalogue = standard_catalogue()
        return self._catalogue

    def build(self, tree: Any, reserved: Mapping[str, str]) -> MetricDefinition | None:
        name = tree.name
        if not _PYTHON_NAME.fullmatch(name) or keyword.iskeyword(name):
            self.error(f"metric name '{name}' must be letters, digits and '_' (it names code and RDF)", tree)
        elif name in reserved:
            self.error(f"metric '{name}' {reserved[name]}; choose another name", tree)
        if tree.pairs is not None:
            self.subject = ComputedFor.PAIRS
            self.pair = (tree.pairs.first, tree.pairs.second)
            if self.pair[0] == self.pair[1]:
                self.error(f"the two robots of a pair need two names, not '{self.pair[0]}' twice", tree.pairs)
        elif tree.mission:
            self.subject = ComputedFor.MISSION
        for read in tree.reads:
            self._read(read)
        scope = Scope(self.subject, self.reads, self.trees, self.broken_reads, self.pair)
        expressions = ExpressionBuilder(self.pf, scope, self.error)
        value = expressions.checked_value(tree.value)
        fallback = expressions.checked_value(tree.fallback) if tree.fallback is not None else None
        dimension = self._dimension(tree, value)
        safety = self._safety(tree, value, dimension) if tree.safety is not None else None
        combine = self._combine(tree, value, fallback)
        if self.failed or value is None or dimension is None:
            return None
        reads = tuple(
            dataclasses.replace(r, fields=tuple(f for f in scope.fields if f.read == r.name))
            for r in self.reads.values()
        )
        return MetricDefinition(
            name,
            self.subject,
            bool(tree.per_segment),
            dimension,
            reads,
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
        if read.signal:
            self._signal_read(read)
            return
        msgtype = canonical_type(read.msgtype)
        self.broken_reads.add(read.name)  # until it is known to be good
        if read.name in self.reads:
            self.error(f"topic '{read.name}' is read twice in this metric", read)
            return
        if self.pair is not None and read.name in self.pair:
            self.error(f"'{read.name}' names a robot of the pair; give the topic another name", read)
            return
        tree = self._tree(read, msgtype)
        if not is_topic_pattern(read.topic):
            self.error(
                f"'{read.topic}' is not a ROS topic name ({TOPIC_RULE})",
                read,
            )
            return
        if not is_ros_topic(read.topic):  # the ROS monitor generators' own rule
            self.warning(
                f"'{read.topic}' is no topic a ROS node can subscribe to ({ROS_TOPIC_RULE}): "
                "bags may hold it, but ros1-monitor and ros2-monitor refuse it",
                read,
            )
        # a topic of each robot without '{ns}': only robots at the root may read it (checks.py)
        self.reads[read.name] = TopicRead(read.name, msgtype, read.topic, self.pf.span(read))
        if tree is not None:
            self.trees[read.name] = tree
        self.broken_reads.discard(read.name)

    def _signal_read(self, read: Any) -> None:
        self.broken_reads.add(read.name)
        if read.name in self.reads:
            self.error(f"topic '{read.name}' is read twice in this metric", read)
            return
        if self.pair is not None and read.name in self.pair:
            self.error(f"'{read.name}' names a robot of the pair; give the signal another name", read)
            return
        if self.subject is ComputedFor.MISSION and read.signal != "goals":  # a mission's: every robot's
            self.error(f"the robot's {read.signal} is read for each robot or each pair of robots", read)
            return
        msgtype = SIGNAL_TYPES[read.signal]
        topic = signal_pattern(read.signal)
        self.reads[read.name] = TopicRead(read.name, msgtype, topic, self.pf.span(read), signal=read.signal)
        if msgtype not in WINDOWS:
            self.trees[read.name] = self.catalogue().tree(msgtype)
        self.broken_reads.discard(read.name)

    def _tree(self, read: Any, msgtype: str) -> Fields | None:
        """The fields of ``msgtype``; None (and a warning) for a type the catalogue lacks."""
        if msgtype in WINDOWS:
            return None
        catalogue = self.catalogue()
        try:
            return catalogue.tree(msgtype)
        except MessageTypeError as exc:
            if msgtype in catalogue:  # known, but it needs a type that is not
                self.warning(f"{exc.message}: the fields of {read.name} are checked when a bag is read", read)
                return None
        remedied = Remedied(
            f"exsce does not know the message type {read.msgtype}"
            f"{did_you_mean(msgtype, catalogue.definitions)}: the fields of {read.name} are checked when "
            "a bag is read, against the bag's definition",
            DEFINE_THE_TYPE,
        )
        self.warning(remedied.said(), read, remedied)
        return None

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
        limit = read_quantity(tree.safety.limit)
        if value is None or dimension is None:
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
        return SafetyLimit(tree.safety.bound, number, tree.safety.limit)

    def _combine(self, tree: Any, value: Typed | None, fallback: Typed | None) -> Combine | None:
        if value is None or not (tree.per_segment or self.subject is ComputedFor.PAIRS):
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


def _top(expr: Expression) -> str | None:
    """The aggregate (or window value) a metric's value is, if it is one."""
    if isinstance(expr, Aggregate):
        return expr.func
    if isinstance(expr, WindowValue):
        return expr.name
    return None
