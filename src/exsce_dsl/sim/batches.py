"""Many messages of one topic that differ only in numbers, serialized at once from one template.

A robot's high-rate topics (TF, odometry, scans, velocity commands) are tens of thousands of
messages whose strings never change: only stamps, sequence numbers, coordinates and ranges do.
A :class:`Batch` builds one message with a sentinel in each such *slot*, serializes it with
rosbags, finds where each sentinel landed, and writes every message's numbers into copies of
those bytes with numpy: the bytes rosbags would have written for each message, without a Python
object per message.  The first, middle and last messages are serialized by rosbags too; where
they disagree with the copies, the batch is serialized one message at a time instead.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

_SENTINEL_BASE = {
    np.dtype("<f8"): 0x40F5_A5A5_0000_0000,
    np.dtype("<f4"): 0x47A5_0000,
    np.dtype("<u4"): 0x5AA5_0000,
}
"""Bit patterns the sentinels start from, one run of them per slot (finite floats, unlikely bytes)."""


@dataclass(frozen=True)
class Batch:
    """Messages of one topic and type; message ``i`` is ``build(**{slot: columns[slot][i]})``."""

    topic: str
    msgtype: str
    stamps: np.ndarray
    """Log time of each message (ns)."""
    build: Callable[..., Any]
    """Slot values (Python numbers, or numpy arrays for array slots) → the message value."""
    columns: dict[str, np.ndarray]
    """Each slot's values, one row per message, in the dtype the wire has: ``<f8`` (float64),
    ``<f4`` (a float32 array) or ``<u4`` (stamps' seconds and nanoseconds, sequence numbers)."""

    def __len__(self) -> int:
        return len(self.stamps)

    def values(self, i: int) -> dict[str, Any]:
        """Message ``i``'s slot values, as :attr:`build` takes them."""
        return {
            slot: column[i] if column.ndim > 1 else column[i].item() for slot, column in self.columns.items()
        }

    def serialized(self, serialize: Callable[[Any, str], Any]) -> list[bytes]:
        """Each message's bytes, as ``serialize`` (a typestore's ``serialize_ros1`` or
        ``serialize_cdr``) writes them."""
        if not len(self):
            return []
        rows = self._from_template(serialize)
        if rows is None:  # the template's copies are not what rosbags writes: one message at a time
            return [bytes(serialize(self.build(**self.values(i)), self.msgtype)) for i in range(len(self))]
        return [row.tobytes() for row in rows]

    def _from_template(self, serialize: Callable[[Any, str], Any]) -> np.ndarray | None:
        sentinels = {slot: _sentinel(column, k) for k, (slot, column) in enumerate(self.columns.items())}
        template = bytes(serialize(self.build(**sentinels), self.msgtype))
        rows = np.tile(np.frombuffer(template, dtype=np.uint8), (len(self), 1))
        for slot, column in self.columns.items():
            pattern = np.asarray(sentinels[slot], dtype=column.dtype).tobytes()
            width = len(pattern)
            values = np.ascontiguousarray(column).view(np.uint8).reshape(len(self), width)
            at = template.find(pattern)  # none: a slot the message has not (a ROS 2 header's seq)
            while at >= 0:  # each place it is in (one stamp in several headers)
                rows[:, at : at + width] = values
                at = template.find(pattern, at + width)
        for i in {0, len(self) // 2, len(self) - 1}:  # rosbags' own bytes for some of them
            if bytes(serialize(self.build(**self.values(i)), self.msgtype)) != rows[i].tobytes():
                return None
        return rows


def stamp_columns(stamps: np.ndarray) -> dict[str, np.ndarray]:
    """``sec`` and ``nanosec`` columns of stamps in ns (a ``builtin_interfaces/Time`` each)."""
    return {
        "sec": (stamps // 1_000_000_000).astype("<u4"),
        "nanosec": (stamps % 1_000_000_000).astype("<u4"),
    }


def _sentinel(column: np.ndarray, slot: int) -> Any:
    """A value of ``column``'s slot whose bytes appear nowhere else in the template."""
    base = _SENTINEL_BASE.get(column.dtype)
    if base is None:
        raise TypeError(f"a batch slot of dtype {column.dtype}")
    width = column.dtype.itemsize
    count = int(np.prod(column.shape[1:], dtype=np.int64))
    bits = base + (slot << 12) + np.arange(count, dtype=np.int64) * 3 + 1
    value = bits.astype(f"<u{width}").view(column.dtype).reshape(column.shape[1:])
    return value if column.ndim > 1 else value.item()
