"""Values gathered from a buffer of messages at many byte positions at once, with numpy.

A gather indexes a view of the buffer whose elements start at every byte (strides of one byte),
so that reading n values costs n indices, not one per byte; texts are gathered eight bytes a
word and told apart by a hash of their words.
"""

from __future__ import annotations

import numpy as np


def gather_values(buffer: np.ndarray, kind: np.dtype, pos: np.ndarray, count: int | None) -> np.ndarray:
    """The ``kind`` values at byte positions ``pos`` of ``buffer`` (``count`` consecutive ones
    each: a 2-D result): one index per value into a view of the buffer whose elements start at
    every byte, not one per byte (positions are checked against the messages' ends before)."""
    many = 1 if count is None else count
    starts = len(buffer) - kind.itemsize * many + 1
    if starts <= 0 or not buffer.flags.c_contiguous:
        values = buffer[pos[:, None] + np.arange(kind.itemsize * many, dtype=np.int64)].view(kind)
        return values[:, 0] if count is None else values
    shape, strides = ((starts,), (1,)) if count is None else ((starts, many), (1, kind.itemsize))
    view = np.ndarray(shape, dtype=kind, buffer=buffer, strides=strides)
    found: np.ndarray = view[pos]
    return found


_WORD_MASKS = np.array([(1 << (8 * k)) - 1 for k in range(8)] + [(1 << 64) - 1], dtype=np.uint64)


def text_words(buffer: np.ndarray, pos: np.ndarray, sizes: np.ndarray, words: int) -> np.ndarray:
    """The bytes of each string (at ``pos``, ``sizes`` long) as ``words`` little-endian 8-byte
    words a row, zero past its end: gathered a word at a time, not a byte at a time."""
    table = np.zeros((len(pos), words), dtype="<u8")
    for w in range(words):
        at = pos + 8 * w
        held = np.clip(sizes - 8 * w, 0, 8)
        near_end = at + 8 > len(buffer)  # a word would run past the buffer: read its bytes alone
        inside = ~near_end & (held > 0)
        found = gather_values(buffer, np.dtype("<u8"), at[inside], None)
        table[inside, w] = found & _WORD_MASKS[held[inside]]
        for row in np.flatnonzero(near_end & (held > 0)).tolist():
            tail = bytes(buffer[at[row] : at[row] + held[row]])
            table[row, w] = int.from_bytes(tail, "little")
    return table


def distinct_rows(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct rows of a uint8 table: the index of each one's first occurrence, and which of
    them every row is.  Rows are keyed by a 64-bit hash of their bytes, so numpy sorts integers, not
    byte strings; a collision (rows with one key that differ) falls back to sorting the bytes."""
    n, width = rows.shape
    words = np.zeros((n, -(-width // 8) * 8), dtype=np.uint8)
    words[:, :width] = rows
    keys = np.zeros(n, dtype=np.uint64)
    for column in words.view("<u8").T:  # FNV-style mixing, one 8-byte word at a time
        keys = (keys ^ column) * np.uint64(0x100000001B3)
        keys ^= keys >> np.uint64(29)
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    if not np.array_equal(rows[first][inverse], rows):
        _, first, inverse = np.unique(
            np.ascontiguousarray(rows).view(f"V{width}").ravel(), return_index=True, return_inverse=True
        )
        inverse = inverse.ravel()
    return first, inverse
