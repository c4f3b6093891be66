"""Bags on two clocks, as Gazebo and Isaac robots record them: log time from the wall clock, the
stamps inside messages (headers, TF transforms, goal stamps) in simulated time.

:func:`restamp` rewrites a bag the executor wrote (where stamps equal log times) with every stamp
moved onto a simulated clock, ``sim = SIM_START + (stamp - first log time) * rate``, log times
left as they were; with ``clock_hz`` it also records ``/clock`` (rosgraph_msgs/msg/Clock) as
Gazebo publishes it.  The robots drove the same paths, so every distance, speed limit and count
of the restamped bag equals the original's; durations scale by ``rate``.  Messages are rewritten
through rosbags' own deserialisation, so nothing of exsce's reading is used to make them; a
message whose only stamp is its leading header's (odometry, scans) has that stamp rewritten in
its bytes, where rosbags' serialisation puts it (a TFMessage's transforms too: test_clock_bags
holds both to rosbags' own round trip), and one with no stamp is copied as it is.
"""

from __future__ import annotations

import dataclasses
import math
import struct
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rosbags.highlevel import AnyReader
from rosbags.interfaces import Nodetype

from tests.support.bag_factory import FORMATS, Topic, typestore_for, write_bag

SIM_START = 931.25
"""Simulated seconds at the first message: a Gazebo world started a quarter of an hour ago."""
CLOCK = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"


def restamp(
    source: Path,
    target: Path,
    fmt: str,
    rate: float = 1.0,
    clock_hz: float | None = None,
    lag: dict[str, float] | None = None,
    shift_to_simulated: bool = True,
) -> Path:
    """Write ``source`` to ``target`` (format ``fmt`` of :data:`FORMATS`) with its stamps on a
    simulated clock (unless not ``shift_to_simulated``); ``lag``: topic → seconds its stamps are
    further behind (a late publisher)."""
    with AnyReader([source]) as reader:
        first = reader.start_time
        messages: dict[tuple[str, str], list[tuple[int, Any]]] = {}
        store = typestore_for(fmt)
        store.register({k: v for k, v in reader.typestore.fielddefs.items() if k not in store.fielddefs})
        same_encoding = reader.is2 == (FORMATS[fmt].ros == 2)
        for connection, time_ns, raw in reader.messages():
            behind = (lag or {}).get(connection.topic, 0.0)
            move: Callable[[float], float] | None
            if shift_to_simulated:
                move = lambda s, b=behind: SIM_START + (s - first * 1e-9) * rate - b  # noqa: E731
            else:
                move = (lambda s, b=behind: s - b) if behind else None  # noqa: E731
            stamps = _stamps(reader.typestore, connection.msgtype) if same_encoding else "other"
            if (move is None and same_encoding) or stamps == "none":
                moved: Any = raw  # no stamp to move: its bytes as they are
            elif move is not None and stamps == "header":
                moved = _header_moved(raw, reader.is2, move)
            elif move is not None and stamps == "tf":
                moved = _transforms_moved(raw, reader.is2, move)
            else:
                message = reader.deserialize(raw, connection.msgtype)
                moved = _moved(message, move, store) if move is not None else message
            messages.setdefault((connection.topic, connection.msgtype), []).append((time_ns, moved))
    topics = [Topic(topic, msgtype, found) for (topic, msgtype), found in messages.items()]
    if clock_hz is not None:
        topics.append(
            _clock(store, first, max(t for found in messages.values() for t, _ in found), rate, clock_hz)
        )
    write_bag(target, FORMATS[fmt], topics, store)
    return target


def sim_time(wall_ns: int, first_ns: int, rate: float = 1.0) -> float:
    """The simulated time :func:`restamp` gives a stamp of ``wall_ns``."""
    return SIM_START + (wall_ns - first_ns) * 1e-9 * rate


def _clock(store: Any, first: int, last: int, rate: float, hz: float) -> Topic:
    clock_type = store.types[CLOCK_TYPE]
    period = int(1e9 / hz)
    found = []
    for time_ns in range(first, last + period, period):
        found.append((time_ns, clock_type(clock=_time(store, sim_time(time_ns, first, rate)))))
    return Topic(CLOCK, CLOCK_TYPE, found)


def _time(store: Any, seconds: float) -> Any:
    sec, nanosec = _sec_nanosec(seconds)
    return store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)


def _sec_nanosec(seconds: float) -> tuple[int, int]:
    """``seconds`` as a Time's (sec, nanosec), rounded to the nanosecond (the fraction alone: a
    float of epoch seconds times 1e9 is too coarse for nanoseconds)."""
    sec = math.floor(seconds)
    nanosec = round((seconds - sec) * 1e9)
    return (sec + 1, 0) if nanosec == 10**9 else (sec, nanosec)


_HEADER_STAMP = struct.Struct("<iI")
"""A leading header's stamp (sec, nanosec), little-endian: 4 bytes into the message in both
encodings (ROS 1: after the header's ``seq``; CDR: after the encapsulation header)."""
_TIME = "builtin_interfaces/msg/Time"
_HEADER = "std_msgs/msg/Header"


def _header_moved(raw: bytes | memoryview, cdr: bool, move: Callable[[float], float]) -> bytes:
    """A serialised message whose one stamp leads it (its header's), with that stamp moved."""
    data = bytearray(raw)
    assert not cdr or data[1] == 1, "CDR not little-endian"
    sec, nanosec = _HEADER_STAMP.unpack_from(data, 4)
    stamp = sec + nanosec * 1e-9
    if stamp > 0:
        _HEADER_STAMP.pack_into(data, 4, *_sec_nanosec(move(stamp)))
    return bytes(data)


def _transforms_moved(raw: bytes | memoryview, cdr: bool, move: Callable[[float], float]) -> bytes:
    """A serialised ``tf2_msgs/msg/TFMessage`` with each transform's header stamp moved.  A
    transform is a header (ROS 1: seq, stamp, frame_id; CDR: stamp, frame_id), a child_frame_id
    and seven float64; in CDR each field is aligned to its size, counted after the 4-byte
    encapsulation header (ROS 1 packs them)."""
    data = bytearray(raw)
    assert not cdr or data[1] == 1, "CDR not little-endian"
    base = 4 if cdr else 0

    def aligned(at: int, size: int) -> int:
        return base + -(-(at - base) // size) * size if cdr else at

    at = aligned(base, 4)
    (count,) = _UINT32.unpack_from(data, at)
    at += 4
    for _ in range(count):
        at = aligned(at, 4) + (0 if cdr else 4)  # ROS 1: past the header's seq
        sec, nanosec = _HEADER_STAMP.unpack_from(data, at)
        stamp = sec + nanosec * 1e-9
        if stamp > 0:
            _HEADER_STAMP.pack_into(data, at, *_sec_nanosec(move(stamp)))
        at += 8
        for _ in ("frame_id", "child_frame_id"):
            at = aligned(at, 4)
            (length,) = _UINT32.unpack_from(data, at)
            at += 4 + length
        at = aligned(at, 8) + 7 * 8  # translation, rotation
    assert at == len(data) or (cdr and 0 < len(data) - at < 8), "a TFMessage of another layout"
    return bytes(data)


_UINT32 = struct.Struct("<I")
_TF = "tf2_msgs/msg/TFMessage"
_STAMPS: dict[tuple[int, str], str] = {}


def _stamps(store: Any, msgtype: str) -> str:
    """Where ``msgtype`` holds Times: ``none``, ``header`` (only its leading header's stamp),
    ``tf`` (a TFMessage: its transforms' header stamps) or ``other`` (anywhere else too: goal
    stamps)."""
    if msgtype == _TF:
        return "tf"
    key = (id(store), msgtype)
    if key not in _STAMPS:
        fields = store.fielddefs[msgtype][1]
        leading = bool(fields) and fields[0][1] == (Nodetype.NAME, _HEADER)
        later = any(_holds_time(store, spec) for _, spec in fields[1 if leading else 0 :])
        _STAMPS[key] = "other" if later else "header" if leading else "none"
    return _STAMPS[key]


def _holds_time(store: Any, spec: tuple[Any, Any]) -> bool:
    """Whether a field of type ``spec`` (rosbags' field definition) holds a Time."""
    kind, detail = spec
    if kind == Nodetype.NAME:  # a message
        return detail == _TIME or any(_holds_time(store, s) for _, s in store.fielddefs[detail][1])
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):  # (element spec, length)
        return _holds_time(store, detail[0])
    return False  # a base type


def _moved(value: Any, move: Any, store: Any) -> Any:
    """``value`` with every builtin_interfaces/msg/Time in it moved by ``move`` (seconds → seconds):
    a Time is replaced, what holds one is changed in place (a message just deserialised, owned
    here; rosbags' message classes are not frozen)."""
    if _is_time(value):
        stamp = value.sec + value.nanosec * 1e-9
        return _time(store, move(stamp)) if stamp > 0 else value
    if isinstance(value, list):
        if value and (dataclasses.is_dataclass(value[0]) or isinstance(value[0], list | tuple)):
            value[:] = [_moved(v, move, store) for v in value]  # a ROS array holds one type
        return value
    if isinstance(value, tuple):
        return tuple(_moved(v, move, store) for v in value)
    if not dataclasses.is_dataclass(value) or isinstance(value, type):
        return value
    for name in _fields_with_time(value):
        setattr(value, name, _moved(getattr(value, name), move, store))
    return value


_WITH_TIME: dict[type, tuple[str, ...]] = {}
"""Per message class, the fields that hold, or may hold, a Time (a list may, another time)."""


_IS_TIME: dict[type, bool] = {}


def _is_time(value: Any) -> bool:
    kind = type(value)
    if kind not in _IS_TIME:
        _IS_TIME[kind] = kind.__name__.endswith("builtin_interfaces__msg__Time")
    return _IS_TIME[kind]


def _fields_with_time(value: Any) -> tuple[str, ...]:
    kind = type(value)
    if kind not in _WITH_TIME:
        _WITH_TIME[kind] = tuple(
            f.name
            for f in dataclasses.fields(value)
            if isinstance(field := getattr(value, f.name), list | tuple)
            or (dataclasses.is_dataclass(field) and (_is_time(field) or _fields_with_time(field)))
        )
    return _WITH_TIME[kind]
