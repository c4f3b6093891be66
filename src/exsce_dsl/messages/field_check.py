"""Check what a metric reads of a message against the type's field tree.

The metric builder checks each field against the catalogue's definition of its
topic's type (rosbags' standard packages and the user's files).  A type the
catalogue does not know is only a warning then, and its fields are checked when
a bag is read, against the bag's own definition: :func:`check_fields` gives the
same messages at the same places as the builder would have.

A path walks the tree: a name steps into a sub-message, or into every element
of an array of messages (one array per message: ``tf.transforms.transform.
translation.x``); ``[i]`` and ``[field == value]`` pick one element instead;
``len(...)`` counts an array's elements.  An array met while walking every
element of another would be an array of arrays, which no metric reads.
"""

from __future__ import annotations

from collections.abc import Callable

from exsce_dsl.errors import BagError, ExsceError, FieldProblem, Remedied
from exsce_dsl.messages.catalogue import Source
from exsce_dsl.model.messages import (
    FieldPath,
    Fields,
    Index,
    Leaf,
    MessageArray,
    Node,
    Select,
    Step,
    canonical_type,
)
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.robots import Robot
from exsce_dsl.remedies import DEFINE_THE_BAGS_TYPE
from exsce_dsl.suggest import did_you_mean


def field_shape(tree: Fields, path: FieldPath, read: str, msgtype: str, text: bool = False) -> bool:
    """Whether ``path`` of topic ``read`` (of type ``msgtype``, whose fields are ``tree``) is an
    array per message (else a number per message); a :class:`FieldProblem` says what is wrong.
    ``text``: the path is to end at a text (a frame id, read by ingestion itself), not a number."""
    return _Walk(tree, path, read, msgtype, text).shape()


def check_fields(
    metric: MetricDefinition, msgtype: str, tree: Fields, source: str | None = None
) -> list[ExsceError]:
    """The problems of the fields ``metric`` reads of its topics of type ``msgtype``, whose fields
    are ``tree`` (the bag's definition), each at the place the field is written.  ``source``
    (``the bag x.bag``) is said in the messages, if given."""
    wanted = canonical_type(msgtype)
    found: list[ExsceError] = []
    for read in metric.reads:
        if canonical_type(read.msgtype) != wanted:
            continue
        for f in read.fields:
            try:
                arrays = field_shape(tree, f.path, read.name, read.msgtype)
            except FieldProblem as problem:
                found.append(ExsceError(_from(problem.message, source), f.location))
                continue
            if arrays != f.arrays:
                shape = "an array" if arrays else "a number"
                wrong = (
                    f"{_text(read.name, f.path)} is {shape} per message by the definition of "
                    f"{msgtype}, not what metric '{metric.name}' was checked with"
                )
                said = Remedied(wrong, DEFINE_THE_BAGS_TYPE).said()  # ingest prints it in a BagError's text
                found.append(ExsceError(_from(said, source), f.location))
    return found


def field_checker(
    metrics: tuple[MetricDefinition, ...], robots: list[Robot]
) -> Callable[[str, str, Fields, Source | None], None]:
    """Checks what ``metrics`` read of a topic against the definition of the type the bag has for
    it, before anything is computed: a type unknown when the specification was checked is checked
    here, with the same messages at the same places (``file:line:col``)."""

    def check(topic: str, msgtype: str, tree: Fields, source: Source | None) -> None:
        problems: list[ExsceError] = []
        for metric in metrics:
            if any(read.topic_of(r.namespace) == topic for read in metric.reads for r in robots):
                problems += check_fields(metric, msgtype, tree, source.text if source else None)
        if problems:
            where = "\n".join(f"  {p}" for p in dict.fromkeys(str(p) for p in problems))
            raise BagError(f"topic {topic} ({msgtype}) lacks what the metrics read of it:\n{where}")

    return check


def describe(node: Node) -> str:
    """``a number``, ``a message (x, y, z)``, ``an array of messages (...)``..."""
    if isinstance(node, Leaf):
        return node.value
    if isinstance(node, MessageArray):
        return f"an array of messages ({', '.join(node.element)})"
    return f"a message ({', '.join(node)})"


def _from(message: str, source: str | None) -> str:
    return f"{message} (in {source})" if source else message


def _text(read: str, path: FieldPath) -> str:
    """How the metric writes the path: ``tf.transforms[0].header``, ``len(tf.transforms)``."""
    inner = f"{read}.{FieldPath(path.steps).key}" if path.steps else read
    return f"len({inner})" if path.length else inner


def _is_array(node: Node) -> bool:
    return isinstance(node, MessageArray) or node in (Leaf.ARRAY, Leaf.TEXTS)


class _Walk:
    def __init__(self, tree: Fields, path: FieldPath, read: str, msgtype: str, text: bool = False) -> None:
        self.path = path
        self.read = read
        self.msgtype = msgtype
        self.node: Node = tree
        self.done: list[Step] = []
        self.spread: int | None = None
        """Where the path went into every element of an array of messages (a step number)."""
        self.text = text

    def here(self) -> str:
        return _text(self.read, FieldPath(tuple(self.done)))

    def shape(self) -> bool:
        for step in self.path.steps:
            if isinstance(step, str):
                self._name(step)
            elif isinstance(step, Index):
                self._index(step)
            else:
                self._select(step)
            self.done.append(step)
            if self.spread is not None and _is_array(self.node):
                self._array_of_arrays()
        return self._end()

    def _name(self, name: str) -> None:
        node = self.node
        if isinstance(node, MessageArray):
            self.spread = len(self.done)
            node = node.element
        if not isinstance(node, dict):
            raise FieldProblem(f"{self.here()} is {describe(node)}: it has no field '{name}'")
        if name not in node:
            where = f"{self.msgtype}.{FieldPath(tuple(self.done)).key}" if self.done else self.msgtype
            raise FieldProblem(f"{self.here()} ({where}) has no field '{name}'{did_you_mean(name, node)}")
        self.node = node[name]

    def _index(self, index: Index) -> None:
        node = self.node
        if node is Leaf.ARRAY:
            self.node = Leaf.NUMBER
        elif node is Leaf.TEXTS:
            if self.text:
                raise FieldProblem(f"{self.here()} is {describe(node)}: its elements are not read")
            self.node = Leaf.TEXT
        elif isinstance(node, MessageArray):
            if node.length is not None and not -node.length <= index.position < node.length:
                raise FieldProblem(
                    f"{self.here()} has {node.length} elements: [{index.position}] is not one of them"
                )
            self.node = node.element
        else:
            raise FieldProblem(
                f"{self.here()} is {describe(node)}, not an array: [{index.position}] picks an element "
                "of an array"
            )

    def _select(self, select: Select) -> None:
        node = self.node
        if node in (Leaf.ARRAY, Leaf.TEXTS):
            raise FieldProblem(
                f"{self.here()} is {describe(node)}: [{'.'.join(select.field)} == ...] picks an element "
                f"of an array of messages by one of its fields; pick a position instead: {self.here()}[0]"
            )
        if not isinstance(node, MessageArray):
            raise FieldProblem(
                f"{self.here()} is {describe(node)}, not an array of messages: "
                f"[{'.'.join(select.field)} == ...] picks an element of one by one of its fields"
            )
        value: Node = node.element
        for i, name in enumerate(select.field):
            owner = f"{'.'.join(select.field[:i])} in an element" if i else "an element"
            if not isinstance(value, dict):
                raise FieldProblem(f"{owner} of {self.here()} is {describe(value)}: it has no field '{name}'")
            if name not in value:
                raise FieldProblem(
                    f"{owner} of {self.here()} has no field '{name}'{did_you_mean(name, value)}"
                )
            value = value[name]
        field = ".".join(select.field)
        if value is Leaf.TEXT and not isinstance(select.value, str):
            raise FieldProblem(f'{field} is text: compare it to a quoted string ({field} == "...")')
        if value is Leaf.NUMBER and isinstance(select.value, str):
            raise FieldProblem(f"{field} is a number: compare it to a number, not to text")
        if value not in (Leaf.TEXT, Leaf.NUMBER):
            raise FieldProblem(
                f"{field} in an element of {self.here()} is {describe(value)}: a selection compares "
                "a number or a text of each element"
            )
        self.node = node.element

    def _array_of_arrays(self) -> None:
        assert self.spread is not None
        outer = _text(self.read, FieldPath(tuple(self.done[: self.spread])))
        steps = self.path.steps
        picked = FieldPath((*steps[: self.spread], Index(0), *steps[self.spread :]), self.path.length)
        raise FieldProblem(
            f"{self.here()} is {describe(self.node)} in each element of {outer}, an array of arrays: "
            f"pick one element of {outer}, e.g. {_text(self.read, picked)}"
        )

    def _end(self) -> bool:
        node, text = self.node, self.here()
        if self.text:
            if node is not Leaf.TEXT or self.path.length:
                raise FieldProblem(f"{text} is {describe(node)}, not a text")
            return self.spread is not None
        if self.path.length:
            if not _is_array(node):
                raise FieldProblem(
                    f"len(...) counts the elements of an array, but {text} is {describe(node)}"
                )
            return False
        if node is Leaf.NUMBER:
            return self.spread is not None
        if node is Leaf.ARRAY:
            return True
        if isinstance(node, MessageArray):
            first = next(iter(node.element), "field")
            raise FieldProblem(
                f"{text} is {describe(node)}, not a number: name a field of its elements "
                f"({text}.{first}) or pick one ({text}[0])"
            )
        if isinstance(node, dict):
            raise FieldProblem(f"{text} is {describe(node)}, not a number: name one of its fields")
        if node is Leaf.TEXT:
            raise FieldProblem(
                f"{text} is text, not a number: text only picks an element of an array of messages, "
                'as in transforms[child_frame_id == "base_link"]'
            )
        raise FieldProblem(f"{text} is {describe(node)}, not numbers")
