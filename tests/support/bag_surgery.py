"""Bags the executor wrote, with what real recordings lose: cut short, a topic silent for a while,
a topic thinned, ``/clock`` reset backwards.

Each function reads a bag through rosbags' own reader and deserialisation, edits the messages as
(log time in ns, message object) per topic, and writes a new bag with rosbags' writers
(:func:`tests.support.bag_factory.write_bag`), so nothing of exsce's reading is used to make it.  Times
are given in seconds from the bag's first message (:func:`bag_span` says where it starts and
ends), so a test computes its expected values from the parameters it passed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader

from tests.support.bag_factory import FORMATS, Topic, typestore_for, write_bag
from tests.support.clock_bags import CLOCK, CLOCK_TYPE, _time

Messages = list[tuple[int, Any]]
Edit = Callable[[str, Messages, int, int], Messages]
"""(topic, its messages, the bag's first and last log time in ns) → the messages to keep."""


@dataclass(frozen=True)
class Span:
    """A bag's first and last log time (ns since the epoch)."""

    start: int
    end: int

    @property
    def seconds(self) -> float:
        return (self.end - self.start) * 1e-9

    def at(self, seconds: float) -> int:
        """The log time ``seconds`` after the first message (ns)."""
        return self.start + round(seconds * 1e9)


def bag_span(bag: Path) -> Span:
    """From the first to the last message of ``bag``, as rosbags reads it."""
    with AnyReader([bag]) as reader:
        times = [t for _, t, _ in reader.messages()]
    return Span(min(times), max(times))


def rewrite(source: Path, target: Path, fmt: str, edit: Edit, extra: list[Topic] | None = None) -> Path:
    """``source`` written to ``target`` (format ``fmt`` of :data:`FORMATS`) with each topic's
    messages as ``edit`` leaves them, and ``extra`` topics added."""
    with AnyReader([source]) as reader:
        store = typestore_for(fmt)
        store.register({k: v for k, v in reader.typestore.fielddefs.items() if k not in store.fielddefs})
        found: dict[tuple[str, str], Messages] = {}
        for connection, time_ns, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            found.setdefault((connection.topic, connection.msgtype), []).append((time_ns, message))
    first = min(t for messages in found.values() for t, _ in messages)
    last = max(t for messages in found.values() for t, _ in messages)
    topics = [
        Topic(topic, msgtype, edit(topic, messages, first, last))
        for (topic, msgtype), messages in found.items()
    ]
    write_bag(target, FORMATS[fmt], [t for t in topics if t.messages] + (extra or []), store)
    return target


def cut(source: Path, target: Path, fmt: str, fraction: float) -> Path:
    """The recording stopped at ``fraction`` of its duration: messages logged after it are gone."""

    def edit(topic: str, messages: Messages, first: int, last: int) -> Messages:
        end = first + round((last - first) * fraction)
        return [(t, m) for t, m in messages if t <= end]

    return rewrite(source, target, fmt, edit)


def drop(source: Path, target: Path, fmt: str, topic: str, start: float, end: float) -> Path:
    """``topic`` silent from ``start`` to ``end`` seconds after the bag's first message (its
    messages logged strictly inside are gone)."""

    def edit(name: str, messages: Messages, first: int, last: int) -> Messages:
        if name != topic:
            return messages
        a, b = first + round(start * 1e9), first + round(end * 1e9)
        return [(t, m) for t, m in messages if not a < t < b]

    return rewrite(source, target, fmt, edit)


def thin(source: Path, target: Path, fmt: str, topic: str, every: int) -> Path:
    """Only every ``every``-th message of ``topic`` kept (the first, then each ``every``-th)."""

    def edit(name: str, messages: Messages, first: int, last: int) -> Messages:
        return messages[::every] if name == topic else messages

    return rewrite(source, target, fmt, edit)


def reset_clock(source: Path, target: Path, fmt: str, at: float, back: float, hz: float = 50.0) -> Path:
    """The bag with ``/clock`` (``hz`` ticks a second, simulated time = log time) going back by
    ``back`` seconds at ``at`` seconds after its first message, as a simulation reset makes it;
    every other message as it was."""
    span = bag_span(source)
    store = typestore_for(fmt)
    clock_type = store.types[CLOCK_TYPE]
    period = round(1e9 / hz)
    ticks = []
    for time_ns in range(span.start, span.end + period, period):
        seconds = time_ns * 1e-9 - (back if time_ns >= span.at(at) else 0.0)
        ticks.append((time_ns, clock_type(clock=_time(store, seconds))))
    return rewrite(
        source, target, fmt, lambda name, messages, first, last: messages, [Topic(CLOCK, CLOCK_TYPE, ticks)]
    )
