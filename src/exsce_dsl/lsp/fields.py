"""Message fields in metric declarations, for completion and hover.

The topics a metric reads (``reads odom: nav_msgs/msg/Odometry on ...``) give
the types; the catalogue (the user's ``.msg`` files over the standard packages)
gives their fields, with their ROS types.  The path written before the point
(``odom.pose.pose.``, ``tf.transforms[0].``, ``tf.transforms[header.``) says
which level of a type to offer: a name steps into a field, ``[...]`` into an
element of an array.  This is lexical, so it works while the text does not parse.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import MessageTypeError
from exsce_dsl.lang import declaration_chunks
from exsce_dsl.messages.catalogue import ARRAY, BASE, NAME, SEQUENCE, MessageCatalogue
from exsce_dsl.messages.user import configured_catalogue
from exsce_dsl.model.messages import WINDOWS, canonical_type
from exsce_dsl.model.metrics import SIGNAL_TYPES

_WORD = r"[A-Za-z_][A-Za-z0-9_]*"
_PART = rf"{_WORD}(?:\s*\[[^\[\]\n]*\])*"
_PATH = rf"{_PART}(?:\s*\.\s*{_PART})*"
_AFTER_DOT = re.compile(rf"({_PATH})\s*\.\s*\Z")
_IN_SELECTION = re.compile(rf"({_PATH})\s*\[\s*((?:{_WORD}\s*\.\s*)*)\Z")
_STEPS = re.compile(rf"{_WORD}|\[[^\[\]\n]*\]")
_READ = re.compile(rf"\breads\s+({_WORD})\s*:\s*({_WORD}/(?:msg/)?{_WORD})(?:\s+on\s+(\"[^\"\n]*\"))?")
_SIGNAL_READ = re.compile(rf"\breads\s+({_WORD})\s*:\s*robot\s+({'|'.join(SIGNAL_TYPES)})\b")
_PAIR = re.compile(rf"\bpair\s+of\s+robots\s*\(\s*({_WORD})\s*,\s*({_WORD})\s*\)")
_TYPE_BEFORE = re.compile(r"[\w/]*\Z")
_BEFORE = 400
"""How far back a path is looked for."""

_PICK = "[]"
"""A step into an element of an array."""


@dataclass(frozen=True)
class FieldInfo:
    """A field of a message: its name, its ROS type (``float64``, ``geometry_msgs/msg/Pose``,
    ``float32[]``) and the message type it belongs to."""

    name: str
    type: str
    owner: str


@dataclass(frozen=True)
class Offer:
    """What completion may offer at a point: (label, kind, detail) items, to replace the text
    from ``start`` (an offset) to the point."""

    start: int
    items: list[tuple[str, str, str]]


@dataclass(frozen=True)
class MetricText:
    """What a metric's text says about names: its reads (name → type, topic; a signal's topic is
    ``robot velocity``...) and pair binders."""

    reads: dict[str, tuple[str, str]]
    pair: tuple[str, ...]

    def source(self, name: str) -> str:
        """Where a read is: ``geometry_msgs/msg/Twist on /{ns}/cmd_vel``, ``the robot's velocity
        (geometry_msgs/msg/Twist)``."""
        msgtype, topic = self.reads[name]
        if topic.startswith("robot "):
            return f"the robot's {topic.removeprefix('robot ')} ({msgtype})"
        return f"{msgtype} on {topic}"


def metric_text(text: str, offset: int) -> tuple[int, MetricText] | None:
    """The start of the metric declaration around ``offset`` and what it declares, if it is one."""
    chunk = next((c for c in declaration_chunks(text) if c.start <= offset <= c.end), None)
    if chunk is None or chunk.keyword != "metric":
        return None
    body = text[chunk.start : chunk.end]
    reads = {m[1]: (canonical_type(m[2]), (m[3] or '""')[1:-1]) for m in _READ.finditer(body)}
    reads |= {m[1]: (SIGNAL_TYPES[m[2]], f"robot {m[2]}") for m in _SIGNAL_READ.finditer(body)}
    pair = _PAIR.search(body)
    return chunk.start, MetricText(reads, (pair[1], pair[2]) if pair else ())


def offers(text: str, offset: int, word_start: int, message_type: bool) -> Offer | None:
    """The fields of the path before the point, the reads where a field starts, or message types
    (``message_type``: the grammar expects one)."""
    found = metric_text(text, word_start)
    if found is None:
        return None
    start, metric = found
    catalogue = configured_catalogue()
    if message_type:
        typed = _TYPE_BEFORE.search(text[max(start, offset - _BEFORE) : offset])
        begin = offset - len(typed.group()) if typed else offset
        return Offer(begin, [(name, "type", "message type") for name in sorted(catalogue.definitions)])
    before = text[max(start, word_start - _BEFORE) : word_start]
    path = _path_before(before)
    if path is None:
        items = [(name, "read", metric.source(name)) for name in metric.reads]
        items += [(name, "robot", "a robot of the pair") for name in metric.pair]
        return Offer(word_start, items) if _at_field_start(before) else None
    fields = _fields_at(catalogue, metric, path)
    if fields is None:
        return None
    return Offer(word_start, [(f.name, "field", f"{f.type} ({f.owner})") for f in fields])


def field_hover(text: str, start: int, end: int) -> str | None:
    """Markdown about the field (or read) written at ``text[start:end]`` of a metric, if it is one."""
    found = metric_text(text, start)
    if found is None:
        return None
    begin, metric = found
    before = text[max(begin, start - _BEFORE) : start]
    word = text[start:end]
    path = _path_before(before)
    if path is None:
        if word in metric.reads and not re.search(r"\breads\s*\Z", before):
            msgtype, topic = metric.reads[word]
            if topic.startswith("robot "):
                return f"**signal** `{word}`: the robot's {topic.removeprefix('robot ')} (`{msgtype}`)"
            return f"**topic** `{word}`: `{msgtype}` on `{topic}`"
        return None
    catalogue = configured_catalogue()
    fields = _fields_at(catalogue, metric, path)
    if fields is None:
        return None
    field = next((f for f in fields if f.name == word), None)
    if field is None:
        return None
    written = ".".join(s for s in path if s != _PICK)
    return f"**field** `{written}.{word}`: `{field.type}`, of `{field.owner}`"


def _at_field_start(before: str) -> bool:
    """Whether a field may start here: after ``value``, ``otherwise``, an operator or a ``(``."""
    last = re.search(r"(\bvalue|\botherwise|\bwhere|\band|\bor|\bnot|[-+*/<>=(,])\s*\Z", before)
    return last is not None


def _path_before(before: str) -> list[str] | None:
    """The steps written before the point (names, and ``[]`` for each pick), ending in a step
    into a message: ``odom.pose.`` → [odom, pose]; ``tf.transforms[child`` → [tf, transforms, []]."""
    selection = _IN_SELECTION.search(before)
    if selection is not None:
        inner = re.findall(_WORD, selection[2])
        return [*_steps(selection[1]), _PICK, *inner]
    dot = _AFTER_DOT.search(before)
    return _steps(dot[1]) if dot is not None else None


def _steps(written: str) -> list[str]:
    return [_PICK if s.startswith("[") else s for s in _STEPS.findall(written)]


def _fields_at(catalogue: MessageCatalogue, metric: MetricText, path: list[str]) -> list[FieldInfo] | None:
    """The fields of the message ``path`` leads to (of each element, for an array of messages)."""
    if path and path[0] in metric.pair:
        path = path[1:]
    if not path or path[0] not in metric.reads:
        return None
    msgtype = metric.reads[path[0]][0]
    if msgtype in WINDOWS:
        return None
    desc: Any = (NAME, msgtype)
    try:
        for step in path[1:]:
            if step == _PICK:
                if int(desc[0]) not in (ARRAY, SEQUENCE):
                    return None
                desc = desc[1][0]
                continue
            members = dict(_members(catalogue, desc))
            if step not in members:
                return None
            desc = members[step]
        owner = _message_of(desc)
        if owner is None:
            return None
        return [FieldInfo(name, type_text(d), owner) for name, d in catalogue.fields_of(owner)]
    except MessageTypeError:
        return None


def _message_of(desc: Any) -> str | None:
    """The message type whose fields come next: of a sub-message, or of an array's elements."""
    kind = int(desc[0])
    if kind == NAME:
        return canonical_type(desc[1])
    if kind in (ARRAY, SEQUENCE) and int(desc[1][0][0]) == NAME:
        return canonical_type(desc[1][0][1])
    return None


def _members(catalogue: MessageCatalogue, desc: Any) -> list[tuple[str, Any]]:
    owner = _message_of(desc)
    return catalogue.fields_of(owner) if owner is not None else []


def type_text(desc: Any) -> str:
    """A field description as ROS writes its type: ``float64``, ``string``,
    ``geometry_msgs/msg/Pose``, ``float64[36]``, ``geometry_msgs/msg/TransformStamped[]``."""
    kind, detail = int(desc[0]), desc[1]
    if kind == BASE:
        return str(detail[0])
    if kind == NAME:
        return canonical_type(detail)
    element, length = detail
    size = str(length) if kind == ARRAY else (f"<={length}" if length else "")
    return f"{type_text(element)}[{size}]"
