"""Read the topics a run's metrics need from a bag (ROS 1, ROS 2 sqlite3, MCAP).

Only the needed connections are read.  Fixed-layout messages (poses, scans,
twists, floats) become numpy arrays over their raw bytes
(:mod:`exsce_dsl.runs.decode`); the dispatcher's few feedback and result
messages are deserialized by rosbags, with their types taken from the bag.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.errors import ExsceError
from exsce_dsl.runs.decode import FIXED_TYPES, DecodeError, Layout, decode, decode_rows, layout
from exsce_dsl.runs.ros1_index import UnsupportedBag, read_topics

_PROGRESS = {0: 0, 1: 1}  # PENDING, ACTIVE; every other status is final


class BagError(ExsceError):
    """A bag that cannot be used: unreadable, truncated, empty, of an unexpected type."""


@dataclass(frozen=True)
class Series:
    """One topic: receive times (seconds since the epoch, sorted) and decoded fields."""

    topic: str
    msgtype: str
    t: np.ndarray
    fields: Mapping[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True)
class StatusUpdate:
    """A dispatcher feedback or result: the status of each waypoint of one goal."""

    t: float
    goal: str  # the actionlib goal id (may be empty)
    waypoints: tuple[str, ...]
    statuses: tuple[int, ...]


@dataclass
class BagData:
    path: Path
    start: float
    end: float
    topics: tuple[str, ...]
    series: dict[str, Series] = field(default_factory=dict)
    feedback: dict[str, list[StatusUpdate]] = field(default_factory=dict)  # topic -> updates
    results: dict[str, list[StatusUpdate]] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)


def typestore_for(path: Path):  # type: ignore[no-untyped-def]
    ros2 = path.is_dir() or path.suffix in (".db3", ".mcap")
    return get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)


Reduce = Callable[[dict[str, np.ndarray]], dict[str, np.ndarray]]
"""Turns a block of decoded messages into the fields kept of them (arrays reduced per message)."""


def read_bag(path: Path, wanted: Mapping[str, str], reduce: Mapping[str, Reduce] | None = None) -> BagData:
    """Read the ``wanted`` topics (topic → expected message type; ``*`` for the dispatcher's).

    ``reduce`` (topic → function) is applied to each block of decoded messages as
    it is read, so that large arrays (laser ranges) are reduced per message and
    never all held at once; given a ``reduce``, array fields are not kept (what
    is needed of them is reduced).  Without it, every field is kept.
    """
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    if _is_ros1(path):
        try:
            return _read_ros1_index(path, wanted, reduce)
        except UnsupportedBag:
            pass  # rosbags reads what our index reader does not (and reports what is broken)
        except DecodeError as exc:
            raise BagError(f"{path}: {exc.message}") from None
    try:
        with AnyReader([path], default_typestore=typestore_for(path)) as reader:
            return _read(reader, path, wanted, reduce)
    except BagError:
        raise
    except DecodeError as exc:
        raise BagError(f"{path}: {exc.message}") from None
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt and truncated files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None


def _kept(
    fields: dict[str, np.ndarray], topic: str, reduce: Mapping[str, Reduce] | None
) -> dict[str, np.ndarray]:
    if reduce is None:
        return fields
    if topic in reduce:
        fields = reduce[topic](fields)
    return {k: v for k, v in fields.items() if v.ndim == 1}


def _read(
    reader: AnyReader, path: Path, wanted: Mapping[str, str], reduce: Mapping[str, Reduce] | None
) -> BagData:
    if reader.message_count == 0:
        raise BagError(f"{path}: the bag holds no messages")
    data = BagData(
        path,
        reader.start_time / 1e9,
        reader.end_time / 1e9,
        tuple(sorted({c.topic for c in reader.connections})),
    )
    by_topic: dict[str, list] = {}  # type: ignore[type-arg]
    for conn in reader.connections:
        if conn.topic in wanted:
            by_topic.setdefault(conn.topic, []).append(conn)
    for topic, conns in sorted(by_topic.items()):
        expected = wanted[topic]
        msgtype = conns[0].msgtype
        if expected != "*" and msgtype != expected:
            data.problems.append(f"topic {topic} carries {msgtype}, not {expected}: its metrics are missing")
            continue
        stamps: list[int] = []
        raws: list[bytes | memoryview] = []
        for _, timestamp, raw in reader.messages(connections=conns):
            stamps.append(timestamp)
            raws.append(raw)
        if not raws:
            continue
        times = np.asarray(stamps, dtype=np.int64)
        order = np.argsort(times, kind="stable")  # out-of-order recordings are put in time order
        if msgtype in FIXED_TYPES:
            in_order = raws if np.all(order[1:] > order[:-1]) else [raws[i] for i in order]
            fields = decode(
                msgtype,
                in_order,
                cdr=not _is_ros1(path),
                fallback=functools.partial(_deserialize, reader, msgtype),
            )
            data.series[topic] = Series(topic, msgtype, times[order] / 1e9, _kept(fields, topic, reduce))
            del raws, in_order  # the decoded buffer is all that is kept
        else:
            updates = [
                _status_update(reader.deserialize(raws[i], msgtype), times[i] / 1e9, topic) for i in order
            ]
            # statuses only move forward: updates recorded at the same instant go in that order
            updates.sort(key=lambda u: (u.t, sum(_PROGRESS.get(s, 2) for s in u.statuses)))
            target = data.results if topic.endswith("/result") else data.feedback
            target[topic] = updates
    return data


def _read_ros1_index(
    path: Path, wanted: Mapping[str, str], reduce: Mapping[str, Reduce] | None
) -> BagData:
    """The fast path for ROS 1 bags: the bag's own index, numpy gathers, no per-message Python."""
    layouts: dict[str, Layout] = {}

    def decoder(topic: str, msgtype: str, rows: np.ndarray) -> dict[str, np.ndarray] | None:
        if msgtype not in FIXED_TYPES or wanted.get(topic) not in (msgtype, "*"):
            return None
        shape = layouts.get(topic) or layouts.setdefault(topic, layout(msgtype, bytes(rows[0]), cdr=False))
        if shape.size != rows.shape[1]:
            raise DecodeError(f"{msgtype} messages on {topic} are not the size their type says")
        return _kept(decode_rows(shape, rows), topic, reduce)

    found = read_topics(path, set(wanted), decoder)
    if not found:
        raise UnsupportedBag("none of the topics")  # rosbags then says whether the bag is empty
    start = min(int(m.times.min()) for m in found.values())
    end = max(int(m.times.max()) for m in found.values())
    data = BagData(path, start / 1e9, end / 1e9, tuple(sorted(found)))
    store = get_typestore(Stores.ROS1_NOETIC)
    for topic, messages in sorted(found.items()):
        expected, msgtype = wanted[topic], messages.msgtype
        if expected != "*" and msgtype != expected:
            data.problems.append(f"topic {topic} carries {msgtype}, not {expected}: its metrics are missing")
            continue
        order = np.argsort(messages.times, kind="stable")
        times = messages.times[order] / 1e9
        if messages.fields is not None:
            sorted_fields = {k: v[order] for k, v in messages.fields.items()}
            data.series[topic] = Series(topic, msgtype, times, sorted_fields)
            continue
        if msgtype not in store.types:
            store.register(get_types_from_msg(messages.definition, msgtype))
        raws = [messages.raws[i] for i in order]
        if msgtype in FIXED_TYPES:
            fields = decode(
                msgtype, raws, cdr=False, fallback=functools.partial(store.deserialize_ros1, typename=msgtype)
            )
            data.series[topic] = Series(topic, msgtype, times, _kept(fields, topic, reduce))
            continue
        updates = [
            _status_update(store.deserialize_ros1(r, msgtype), t, topic)
            for r, t in zip(raws, times, strict=True)
        ]
        updates.sort(key=lambda u: (u.t, sum(_PROGRESS.get(s, 2) for s in u.statuses)))
        (data.results if topic.endswith("/result") else data.feedback)[topic] = updates
    return data


def _deserialize(reader: AnyReader, msgtype: str, raw: bytes | memoryview) -> Any:
    return reader.deserialize(bytes(raw), msgtype)


def _is_ros1(path: Path) -> bool:
    return path.is_file() and path.suffix == ".bag"


def _status_update(msg: Any, t: float, topic: str) -> StatusUpdate:
    try:
        payload = getattr(msg, "feedback", None) or msg.result
        status_list = payload.goal_status.status_list
        goal = getattr(getattr(msg, "status", None), "goal_id", None)
    except AttributeError:
        raise BagError(f"topic {topic} does not carry the waypoint dispatcher's goal statuses") from None
    return StatusUpdate(
        t,
        getattr(goal, "id", "") or "",
        tuple(str(s.goal_id.id) for s in status_list),
        tuple(int(s.status) for s in status_list),
    )
