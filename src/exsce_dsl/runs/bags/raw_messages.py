"""Messages of one type as raw bytes, back to back in one numpy buffer: what the decoder reads."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RawMessages:
    """Messages of one type, back to back in ``buffer``: message i is ``buffer[starts[i]:ends[i]]``.

    ``width`` is set when every message has that size and follows the previous
    one directly, so that fields at the same place in every message are read as
    a column of a 2-D view, without an index array.
    """

    buffer: np.ndarray  # uint8
    starts: np.ndarray  # int64
    ends: np.ndarray  # int64
    width: int | None = None

    def __len__(self) -> int:
        return len(self.starts)

    def raws(self) -> list[bytes]:
        """Each message's bytes."""
        spans = zip(self.starts.tolist(), self.ends.tolist(), strict=True)
        return [self.buffer[start:end].tobytes() for start, end in spans]

    @staticmethod
    def join(raws: Sequence[bytes | memoryview]) -> RawMessages:
        """Messages given one by one, joined into one buffer."""
        sizes = np.fromiter((len(r) for r in raws), dtype=np.int64, count=len(raws))
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64) if len(raws) else sizes
        buffer = np.frombuffer(b"".join(raws), dtype=np.uint8)
        width = int(sizes[0]) if len(raws) and np.all(sizes == sizes[0]) else None
        return RawMessages(buffer, starts, starts + sizes, width)

    @staticmethod
    def rows(rows: np.ndarray) -> RawMessages:
        """Equal-size messages given as the rows of a 2-D uint8 array."""
        n, size = rows.shape
        starts = np.arange(n, dtype=np.int64) * size
        return RawMessages(np.ascontiguousarray(rows).reshape(-1), starts, starts + size, size)
