"""Decode fixed-layout ROS messages as numpy arrays over their raw bytes.

Messages on one topic almost always have the same layout (same frame id,
same number of laser beams), so the raw messages of a connection are joined
into one buffer and read as one structured array: no Python object per
message.  The offsets follow the ROS 1 serialization and CDR (ROS 2, little
endian) rules; a connection whose messages differ in length is decoded with
rosbags instead (slow, but right).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from exsce_dsl.errors import ExsceError

POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
TWIST = "geometry_msgs/msg/Twist"
FLOAT64 = "std_msgs/msg/Float64"
SCAN = "sensor_msgs/msg/LaserScan"
FIXED_TYPES = (POSE, TWIST, FLOAT64, SCAN)


class DecodeError(ExsceError):
    """Raw bytes that are not the message type they claim to be."""


@dataclass(frozen=True)
class Layout:
    """Where the fields we need are, in bytes from the start of a raw message."""

    size: int
    fields: dict[str, tuple[int, str]]  # name -> (offset, numpy scalar type)
    arrays: dict[str, tuple[int, int, str]] = field(default_factory=dict)
    """name -> (offset, element count, numpy element type): LaserScan ranges, a pose's covariance."""


def _align(offset: int, n: int) -> int:
    return (offset + n - 1) // n * n


def _header(raw: bytes, cdr: bool) -> tuple[int, dict[str, tuple[int, str]]]:
    """The end of a std_msgs/Header and the stamp fields; ``cdr`` offsets include the 4-byte prefix."""
    # ROS 1: seq, sec, nsec, frame_id; CDR: prefix, sec, nanosec, frame_id (with its NUL)
    length = int.from_bytes(raw[12:16], "little")
    return 16 + length, {"header.stamp.sec": (4, "<i4" if cdr else "<u4"), "header.stamp.nanosec": (8, "<u4")}


def layout(msgtype: str, raw: bytes, cdr: bool) -> Layout:
    """The layout of ``msgtype`` as shown by one raw message of the connection."""
    base = 4 if cdr else 0  # CDR: a 4-byte encapsulation header; alignment counts after it
    if cdr and raw[:2] != b"\x00\x01":
        raise DecodeError("only little-endian CDR is supported")
    if msgtype == TWIST:
        names: tuple[str, ...] = ("linear.x", "linear.y", "linear.z", "angular.x", "angular.y", "angular.z")
        return Layout(base + 48, {n: (base + 8 * i, "<f8") for i, n in enumerate(names)})
    if msgtype == FLOAT64:
        return Layout(base + 8, {"data": (base, "<f8")})
    end, fields = _header(raw, cdr)
    if msgtype == POSE:
        start = base + _align(end - base, 8) if cdr else end
        position = tuple(f"pose.pose.position.{c}" for c in "xyz")
        names = position + tuple(f"pose.pose.orientation.{c}" for c in "xyzw")
        fields.update({n: (start + 8 * i, "<f8") for i, n in enumerate(names)})
        covariance = {"pose.covariance": (start + 8 * 7, 36, "<f8")}
        return Layout(start + 8 * 7 + 8 * 36, fields, covariance)
    if msgtype == SCAN:
        start = base + _align(end - base, 4) if cdr else end
        names = (
            "angle_min",
            "angle_max",
            "angle_increment",
            "time_increment",
            "scan_time",
            "range_min",
            "range_max",
        )
        fields.update({n: (start + 4 * i, "<f4") for i, n in enumerate(names)})
        count_at = start + 28
        beams = int.from_bytes(raw[count_at : count_at + 4], "little")
        ranges_at = count_at + 4
        after = ranges_at + 4 * beams
        intensities = int.from_bytes(raw[after : after + 4], "little")
        arrays = {"ranges": (ranges_at, beams, "<f4"), "intensities": (after + 4, intensities, "<f4")}
        return Layout(after + 4 + 4 * intensities, fields, arrays)
    raise DecodeError(f"no fixed layout for {msgtype}")


def decode(
    msgtype: str,
    raws: Sequence[bytes | memoryview],
    cdr: bool,
    fallback: Callable[[bytes | memoryview], Any] | None = None,
) -> dict[str, np.ndarray]:
    """Fields of every message as arrays (``ranges`` is messages × beams for LaserScan)."""
    if not raws:
        return {}
    first = bytes(raws[0])
    shape = layout(msgtype, first, cdr)
    lengths = np.fromiter((len(r) for r in raws), dtype=np.int64, count=len(raws))
    if np.all(lengths == shape.size):
        buffer = np.frombuffer(b"".join(raws), dtype=np.uint8).reshape(len(raws), shape.size)
        return decode_rows(shape, buffer)
    if fallback is None:
        raise DecodeError(f"{msgtype} messages of different sizes ({lengths.min()}–{lengths.max()} bytes)")
    return _decode_slowly(msgtype, raws, fallback)


def decode_rows(shape: Layout, rows: np.ndarray) -> dict[str, np.ndarray]:
    """Fields of messages given as the rows of a uint8 array (one message per row)."""
    out = {name: _column(rows, offset, kind) for name, (offset, kind) in shape.fields.items()}
    for name, (at, count, kind) in shape.arrays.items():
        # a view on the raw rows, not a copy: laser ranges are most of a bag's bytes
        width = np.dtype(kind).itemsize
        out[name] = rows[:, at : at + width * count].view(kind)
    return out


def _column(buffer: np.ndarray, offset: int, kind: str) -> np.ndarray:
    width = np.dtype(kind).itemsize
    if offset + width > buffer.shape[1]:
        raise DecodeError("message shorter than its type")
    return buffer[:, offset : offset + width].copy().view(kind).reshape(-1).astype(np.float64)


def _decode_slowly(
    msgtype: str, raws: Sequence[bytes | memoryview], deserialize: Callable[[Any], Any]
) -> dict[str, np.ndarray]:
    msgs = [deserialize(r) for r in raws]
    if msgtype == TWIST:
        return {
            f"{part}.{c}": np.array([getattr(getattr(m, part), c) for m in msgs], dtype=np.float64)
            for part in ("linear", "angular")
            for c in "xyz"
        }
    if msgtype == FLOAT64:
        return {"data": np.array([m.data for m in msgs], dtype=np.float64)}
    stamps = {
        "header.stamp.sec": np.array([m.header.stamp.sec for m in msgs], dtype=np.float64),
        "header.stamp.nanosec": np.array([m.header.stamp.nanosec for m in msgs], dtype=np.float64),
    }
    if msgtype == POSE:
        p = [m.pose.pose for m in msgs]
        return stamps | {
            f"pose.pose.{part}.{c}": np.array([getattr(getattr(q, part), c) for q in p], dtype=np.float64)
            for part, coordinates in (("position", "xyz"), ("orientation", "xyzw"))
            for c in coordinates
        } | {"pose.covariance": np.array([m.pose.covariance for m in msgs], dtype=np.float64).reshape(-1, 36)}
    out: dict[str, np.ndarray] = stamps | {
        name: np.array([getattr(m, name) for m in msgs], dtype=np.float64)
        for name in ("angle_min", "angle_max", "angle_increment", "time_increment", "scan_time", "range_min",
                     "range_max")
    }
    for name in ("ranges", "intensities"):  # scans of different sizes: padded with NaN (never a valid range)
        width = max((len(getattr(m, name)) for m in msgs), default=0)
        values = np.full((len(msgs), width), np.nan, dtype=np.float32)
        for i, m in enumerate(msgs):
            values[i, : len(getattr(m, name))] = getattr(m, name)
        out[name] = values
    return out
