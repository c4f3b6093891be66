"""Decode the fields a metric reads from raw ROS messages, with numpy, for any message type.

The decoder is driven by the message definition (rosbags' field descriptions,
from the bag, a typestore or the user): it walks the fields in order over *all*
messages at once, keeping each message's read position in an int64 array
(:mod:`~exsce_dsl.runs.bags.decode_walk`).  Fixed-size fields move every
position by the same amount; a string or a sequence moves each by its own
length prefix, read for all messages with one gather.  So messages whose sizes
differ (a ``frame_id``, a ``child_frame_id``, a variable array) cost no Python
per message either.  ROS 1 serialization
packs fields; CDR (ROS 2) aligns each primitive to its size, counted from the
end of the 4-byte encapsulation header, and may be big-endian.

Only the fields of the wanted :class:`~exsce_dsl.model.messages.FieldPath`\\ s
are gathered.  An array of messages (``transforms`` of a TFMessage) is walked
one element index at a time, over every message that has that element: its
loop runs as many times as the longest array has elements, not once per
message.  What comes out, per path key:

- a number: one float64 per message;
- an array of numbers, or a field of every element of an array of messages:
  one row per message (float32 arrays stay float32), padded with NaN where
  messages hold fewer elements;
- a path that picks elements (``[0]``, ``[child_frame_id == "base_link"]``):
  as above, NaN where a message has no such element, and a boolean mask under
  ``KEY#present``;
- ``len(...)``: the number of elements, as float64;
- a text (asked for with ``texts``, e.g. the frame ids of a TFMessage): a float64
  code per message (or row of codes), NaN where absent, indexing the strings in
  ``out[TEXTS]`` (one table for every text path of the call).

Layouts that truly cannot be vectorised are decoded with rosbags, one message
object at a time, and read by attribute (:func:`decode_slowly`): ``wstring``
and ``float128`` fields, which no numpy type matches.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any

import numpy as np

from exsce_dsl.errors import DecodeError, FieldProblem
from exsce_dsl.messages.catalogue import ARRAY, BASE, SEQUENCE, MessageCatalogue
from exsce_dsl.messages.field_check import field_shape
from exsce_dsl.model.messages import FieldPath, Index, canonical_type
from exsce_dsl.monitor_kit.monitor_core import PRESENT
from exsce_dsl.runs.bags.decode_walk import LENGTHS, UNVECTORISED, Request, Walker
from exsce_dsl.runs.bags.raw_messages import RawMessages

TEXTS = "#texts"
"""Key of the strings that text paths' codes index."""


def vectorisable(catalogue: MessageCatalogue, msgtype: str) -> bool:
    """Whether ``msgtype`` can be decoded by :func:`decode` (no ``wstring`` or ``float128``)."""
    catalogue.fields_of(msgtype)  # an unknown type is an error, not "vectorisable"
    for _, fields in catalogue.needed(msgtype).values():
        for _, desc in fields:
            while int(desc[0]) in (ARRAY, SEQUENCE):
                desc = desc[1][0]
            if int(desc[0]) == BASE and desc[1][0] in UNVECTORISED:
                return False
    return True


def decode(
    catalogue: MessageCatalogue,
    msgtype: str,
    messages: RawMessages,
    paths: Iterable[FieldPath],
    cdr: bool,
    texts: Iterable[FieldPath] = (),
) -> dict[str, np.ndarray]:
    """The values of ``paths`` (numbers) and ``texts`` in every message (see the module's
    docstring for their shapes)."""
    numbers, strings = list(dict.fromkeys(paths)), list(dict.fromkeys(texts))
    if not len(messages) or not (numbers or strings):
        return {}
    tree = catalogue.tree(msgtype)
    requests = []
    for path, text in [(p, False) for p in numbers] + [(p, True) for p in strings]:
        try:
            row = field_shape(tree, path, "message", msgtype, text=text)
        except FieldProblem as problem:
            raise DecodeError(f"{msgtype}: {problem.message}") from None
        requests.append(Request(path.steps, path.key, path, row=row, text=text))
    walker = Walker(catalogue, messages, cdr)
    pos = messages.starts + (4 if cdr else 0)
    out: dict[str, np.ndarray] = {}
    walker.struct(canonical_type(msgtype), pos, pos.copy(), np.arange(len(messages)), requests, out)
    found = {key: values for key, values in out.items() if not key.endswith(LENGTHS)}
    if strings:
        found[TEXTS] = np.array(list(walker.texts), dtype=object)
    return found


def decode_slowly(
    deserialize: Callable[[bytes | memoryview], Any],
    raws: Sequence[bytes | memoryview],
    paths: Iterable[FieldPath],
    texts: Iterable[FieldPath] = (),
) -> dict[str, np.ndarray]:
    """The values of ``paths`` and ``texts`` from message objects (rosbags' ``deserialize``), one
    message at a time: the checked fallback for what :func:`decode` cannot vectorise."""
    messages = [deserialize(r) for r in raws]
    out: dict[str, np.ndarray] = {}
    strings = list(dict.fromkeys(texts))
    if strings:
        table: dict[str, int] = {}

        def code(value: Any) -> Any:
            if value is None:
                return None
            if isinstance(value, (list, tuple)):
                return [code(v) for v in value]
            return table.setdefault(str(value), len(table))

        for path in strings:
            _put_slowly(out, path, [code(_attribute_value(m, path)) for m in messages])
        out[TEXTS] = np.array(list(table), dtype=object)
    for path in dict.fromkeys(paths):
        _put_slowly(out, path, [_attribute_value(m, path) for m in messages])
    return out


def _put_slowly(out: dict[str, np.ndarray], path: FieldPath, values: list[Any]) -> None:
    """One path's values, a value (or list of them) or None per message, in :func:`decode`'s shapes."""
    if any(isinstance(v, (list, tuple, np.ndarray)) for v in values):
        width = max((len(np.atleast_1d(v)) for v in values if v is not None), default=0)
        table = np.full((len(values), width), np.nan)
        for i, v in enumerate(values):
            if v is not None:
                row = np.atleast_1d(np.asarray(v, dtype=np.float64))
                table[i, : len(row)] = row
        out[path.key] = table
    else:
        out[path.key] = np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    if path.picks:
        out[path.key + PRESENT] = np.array([v is not None for v in values], dtype=bool)


def _attribute_value(message: Any, path: FieldPath) -> Any:
    """The value of ``path`` in a message object (None if it picks an element that is not there)."""
    node: Any = message
    for step in path.steps:
        if isinstance(step, str):  # on a list of messages (rosbags' arrays of messages): every element
            node = [getattr(x, step) for x in node] if isinstance(node, list) else getattr(node, step)
        elif isinstance(step, Index):
            try:
                node = node[step.position]
            except IndexError:
                return None
        else:
            node = next((x for x in node if _select_value(x, step.field) == step.value), None)
            if node is None:
                return None
    if path.length:
        return len(node)
    return node


def _select_value(element: Any, field: tuple[str, ...]) -> Any:
    for name in field:
        element = getattr(element, name)
    return element
