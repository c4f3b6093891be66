"""Generate the monitor module of a set of metrics, and load it to compute a run's metrics.

The code comes from ``templates/monitors/monitors.py.j2``: a ``RobotMetrics``
and a ``MissionMetrics`` class whose ``get_<metric>(start, end)`` methods call
:mod:`exsce_dsl.monitor_kit.monitor_core`.  Ingestion renders it for the standard
library's metrics and the specification's own and executes that text (kept in
the user's cache folder like ``__pycache__``, never loaded by a name from a
data file); ``exscec generate monitors`` writes the same text to a file.
Metric names are checked Python identifiers, topic names and strings go
through the template's quoting filters, operators and function names are
checked against the language's (:func:`check_written_code`), the expression's
text reaches only a one-line comment, and local variable names are exsce's
own, so nothing from a user's file becomes code unchecked.
"""

from __future__ import annotations

import functools
import hashlib
import types
from collections.abc import Sequence
from dataclasses import dataclass

from exsce_dsl.errors import GenerationError
from exsce_dsl.lang import expression_text
from exsce_dsl.model.expressions import (
    AGGREGATES,
    CONDITION_AGGREGATES,
    ELEMENTWISE,
    MAX_DEPTH,
    SERIES,
    WINDOW_VALUES,
    Aggregate,
    Binary,
    Call,
    Expression,
    Field,
    Unary,
    WindowValue,
    expression_depth,
    is_constant,
    walk,
)
from exsce_dsl.model.messages import FEEDBACK, GOALS, RESULT
from exsce_dsl.model.metrics import GOALS_READ_AS, Combine, ComputedFor, MetricDefinition
from exsce_dsl.user_cache import cache_folder, read_cached, write_cached

GENERATOR = "exscec generate monitors"
TEMPLATE = "monitors/monitors.py.j2"

_UFUNCS = {
    "+": "np.add",
    "-": "np.subtract",
    "*": "np.multiply",
    "/": "np.divide",
    "<": "np.less",
    "<=": "np.less_equal",
    ">": "np.greater",
    ">=": "np.greater_equal",
    "==": "np.equal",
    "!=": "np.not_equal",
    "and": "np.logical_and",
    "or": "np.logical_or",
    "abs": "np.abs",
    "sqrt": "np.sqrt",
}
_PAIR_COMBINE = {Combine.MIN: "min", Combine.MAX: "max", Combine.SUM: "sum"}
_WRITTEN: list[tuple[type, str, frozenset[str]]] = [
    (Binary, "op", frozenset(("+", "-", "*", "/", "<", "<=", ">", ">=", "==", "!=", "and", "or"))),
    (Unary, "op", frozenset(("-", "not"))),
    (Call, "func", frozenset((*ELEMENTWISE, *SERIES))),
    (Aggregate, "func", frozenset((*AGGREGATES, *CONDITION_AGGREGATES))),
    (WindowValue, "name", frozenset(WINDOW_VALUES)),
]
"""The attributes of expression nodes the template writes as code, and the words they may be."""


def check_written_code(metric: MetricDefinition, expr: Expression) -> None:
    """Raise a :class:`GenerationError` unless every operator and function name of ``expr``
    (which the template writes as code, not as a literal) is one of the language's, and it nests
    at most :data:`MAX_DEPTH` deep."""
    depth = expression_depth(expr)
    if depth > MAX_DEPTH:  # the builder refuses these; a model made in Python may not have been built
        raise GenerationError(
            f"metric '{metric.name}': its expression nests {depth} operations deep, more than the "
            f"{MAX_DEPTH} that code is generated for; split it into metrics of their own",
            metric.location,
        )
    for node in walk(expr):
        for kind, attribute, allowed in _WRITTEN:
            word = getattr(node, attribute, None) if isinstance(node, kind) else None
            if word is not None and word not in allowed:
                raise GenerationError(
                    f"metric '{metric.name}': {word!r} is no {attribute} of the language",
                    getattr(node, "location", None),
                )


@dataclass(frozen=True)
class Alternative:
    """One way to compute a metric (its value, or what ``otherwise`` gives), as the template needs it."""

    text: str
    value: Expression
    aggregates: list[Aggregate]
    reads: list[tuple[str, str, str]]
    """(local variable, whose topic: ``first``/``second`` of a pair or "", topic pattern)."""
    vars: dict[tuple[str | None, str], str]
    uses_succeeded: bool
    blocks: list[str | None]
    """Per aggregate: the variable of the topic whose arrays it reduces (prepared in blocks), or None."""
    reducers: list[tuple[str, str] | None]
    """Per aggregate over arrays: (function, key) that reduce its arrays per message as a bag is read."""


@dataclass(frozen=True)
class MetricCode:
    name: str
    meaning: str
    alternatives: list[Alternative]
    pairs: str | None
    """For a metric over pairs of robots: how the pairs' values combine (min, max or sum)."""


def alternatives(metric: MetricDefinition) -> list[Alternative]:
    found = []
    for number, expr in enumerate((metric.value, metric.fallback)):
        if expr is None:
            continue
        check_written_code(metric, expr)
        nodes = walk(expr)
        aggregates: list[Aggregate] = []
        for node in nodes:
            if isinstance(node, Aggregate) and node not in aggregates:
                aggregates.append(node)
        fields = [n for n in nodes if isinstance(n, Field)]
        variables: dict[tuple[str | None, str], str] = {}
        reads: list[tuple[str, str, str]] = []
        patterns = {r.name: r.topic for r in metric.reads}
        for f in fields:
            key = (f.robot, f.read)
            if key in variables:
                continue
            variables[key] = f"topic_{len(variables)}"
            first = metric.pair is not None and f.robot == metric.pair[0]
            whose = "" if f.robot is None else ("first" if first else "second")
            reads.append((variables[key], whose, patterns[f.read]))
        succeeded = any(isinstance(n, WindowValue) and n.name == "succeeded" for n in nodes)
        blocks = [_array_topic(a, variables) for a in aggregates]
        reducers = [
            None if var is None else (f"_reduce_{metric.name}_{number}_{k}", f"{metric.name}/{number}/{k}")
            for k, var in enumerate(blocks)
        ]
        text = expression_text(expr)
        found.append(Alternative(text, expr, aggregates, reads, variables, succeeded, blocks, reducers))
    return found


def _array_topic(aggregate: Aggregate, variables: dict[tuple[str | None, str], str]) -> str | None:
    """The variable of the topic an aggregate reads arrays of (one topic: arrays are never aligned)."""
    for node in [n for arg in aggregate.args for n in walk(arg)]:
        if isinstance(node, Field) and node.arrays:
            return variables[(node.robot, node.read)]
    return None


def _code(metric: MetricDefinition) -> MetricCode:
    pairs = _PAIR_COMBINE[metric.combine] if metric.subject is ComputedFor.PAIRS and metric.combine else None
    return MetricCode(metric.name, metric.meaning, alternatives(metric), pairs)


def monitor_source(metrics: Sequence[MetricDefinition], source: str, core_import: str | None = None) -> str:
    """The Python text of the monitor module for ``metrics``; ``source`` names the spec in its header.

    ``core_import``: how the module imports the core (ingestion's default: from exsce).
    """
    robot = [_code(m) for m in metrics if m.subject is ComputedFor.ROBOT]
    mission = [_code(m) for m in metrics if m.subject is not ComputedFor.ROBOT]
    reducers = []
    for code in robot + mission:
        for alt in code.alternatives:
            patterns = {var: pattern for var, _, pattern in alt.reads}
            for agg, var, names in zip(alt.aggregates, alt.blocks, alt.reducers, strict=True):
                if var is not None and names is not None:
                    reducers.append(
                        {
                            "name": names[0],
                            "key": names[1],
                            "var": var,
                            "pattern": patterns[var],
                            "aggregate": agg,
                            "vars": alt.vars,
                        }
                    )
    # Jinja2 is imported only when there is something to render
    from exsce_dsl.templating import render_with_tests

    return render_with_tests(
        TEMPLATE,
        {"constant": is_constant},  # an expression with one number for every window
        generator=GENERATOR,
        source=source,
        core_import=core_import or "from exsce_dsl.monitor_kit import monitor_core as core",
        robot_metrics=robot,
        mission_metrics=mission,
        reducers=reducers,
        ufuncs=_UFUNCS,
    )


@functools.lru_cache(maxsize=32)
def _load(source_text: str) -> types.ModuleType:
    digest = hashlib.sha256(source_text.encode()).hexdigest()[:16]
    module = types.ModuleType(f"exsce_monitors_{digest}")
    module.__dict__["__file__"] = f"<exsce monitors {digest}>"
    exec(compile(source_text, module.__dict__["__file__"], "exec"), module.__dict__)  # noqa: S102
    return module


def load_monitors(metrics: Sequence[MetricDefinition], source: str = "the specification") -> types.ModuleType:
    """The generated monitor module of ``metrics``, executed in memory (cached by text).

    The rendered text is kept in the user's cache folder under a digest of what
    it was rendered from (exsce's version, the template, the metrics), the way
    Python keeps ``__pycache__``: rendering needs Jinja2, whose import and
    template compilation cost more than the metrics of a short bag.
    """
    digest = _inputs_digest(metrics, source)
    folder = cache_folder()
    cached = folder / f"monitors-{digest}.py" if folder is not None else None
    found = read_cached(cached) if cached is not None else None
    try:
        text = found.decode("utf-8") if found is not None else None
    except UnicodeDecodeError:
        text = None
    if text is None:
        text = monitor_source(metrics, source)
        if cached is not None:
            write_cached(cached, text.encode("utf-8"))
    return _load(text)


def _inputs_digest(metrics: Sequence[MetricDefinition], source: str) -> str:
    from exsce_dsl import __version__
    from exsce_dsl.resources import resource_dir

    template = (resource_dir("templates") / TEMPLATE).read_bytes()
    digest = hashlib.sha256()
    for part in (__version__.encode(), template, repr(tuple(metrics)).encode(), source.encode()):
        digest.update(len(part).to_bytes(8, "little") + part)
    return digest.hexdigest()


def topics_used(metric: MetricDefinition, alternative: int) -> list[tuple[str | None, str]]:
    """The (pair robot or None, topic pattern) an alternative reads: its fields' topics, and what
    ``elapsed`` and ``succeeded`` read (of a robot's goals signal: :data:`GOALS_READ_AS`)."""
    expr = metric.value if alternative == 0 else metric.fallback
    assert expr is not None
    reads = {r.name: r for r in metric.reads}
    used: list[tuple[str | None, str]] = []
    for node in walk(expr):
        if isinstance(node, Field) and (node.robot, reads[node.read].topic) not in used:
            used.append((node.robot, reads[node.read].topic))
        elif isinstance(node, WindowValue):
            wanted = RESULT if node.name == "succeeded" else FEEDBACK
            for read in metric.reads:
                topic = GOALS_READ_AS[node.name] if read.msgtype == GOALS else read.topic
                if read.msgtype in (wanted, GOALS) and (None, topic) not in used:
                    used.append((None, topic))
    return used
