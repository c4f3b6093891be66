"""Read messages of chosen connections straight from a ROS 1 bag's index, with numpy.

rosbags hands out one Python tuple per message (about 100,000 messages/s
here).  A ROS 1 bag (format 2.0) indexes every message: after each chunk come
index-data records giving, per connection, each message's time and offset in
the chunk.  So for each chunk we read the index as arrays, find each message's
data with a vectorised gather, and hand a connection's messages of a batch of
chunks (:mod:`exsce_dsl.runs.bags.chunk_batches`) to a decoder as one buffer with
their offsets: Python work per batch, none per message.

Uncompressed, bz2 and lz4 chunks are read; anything unexpected raises
:class:`UnsupportedBag` and the caller falls back to rosbags.
"""

from __future__ import annotations

import bz2
import gc
import mmap
import struct
import traceback
from collections.abc import Callable, Container, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from exsce_dsl.runs.bags.chunk_batches import ChunkBatch
from exsce_dsl.runs.bags.decode import RawMessages
from exsce_dsl.runs.bags.gather import gather_values

MAGIC = b"#ROSBAG V2.0\n"
OP_MSG, OP_BAG, OP_INDEX, OP_CHUNK, OP_CHUNK_INFO, OP_CONN = 0x02, 0x03, 0x04, 0x05, 0x06, 0x07


class UnsupportedBag(Exception):
    """This reader cannot read the bag; use rosbags."""


Buffer = bytes | memoryview | mmap.mmap

Decoder = Callable[[str, str, str, np.ndarray, RawMessages], bool]
"""(topic, message type, its definition, receive times in ns, its messages in a batch of chunks) → whether
it took them; False keeps their raw bytes (for messages deserialized whole)."""


@dataclass(frozen=True)
class Messages:
    """One topic's messages: receive times (ns, bag order), and the raw bytes of each message the
    decoder did not take."""

    msgtype: str
    definition: str  # the message definition the bag carries (ROS 1 concatenated form)
    times: np.ndarray
    raws: list[bytes]


def _header(buf: Buffer, pos: int) -> tuple[dict[str, bytes], int]:
    (length,) = struct.unpack_from("<I", buf, pos)
    fields: dict[str, bytes] = {}
    at, end = pos + 4, pos + 4 + length
    while at < end:
        (flen,) = struct.unpack_from("<I", buf, at)
        name, _, value = bytes(buf[at + 4 : at + 4 + flen]).partition(b"=")
        fields[name.decode()] = value
        at += 4 + flen
    return fields, end


def _record(buf: Buffer, pos: int) -> tuple[dict[str, bytes], int, int]:
    """A record at ``pos``: its header fields, where its data starts, and where the next record starts."""
    fields, data_at = _header(buf, pos)
    (size,) = struct.unpack_from("<I", buf, data_at)
    return fields, data_at + 4, data_at + 4 + size


@contextmanager
def mapped(path: Path) -> Iterator[mmap.mmap]:
    """The file mapped read-only (an empty file is :class:`UnsupportedBag`), closed however the
    reading ends."""
    with path.open("rb") as f:
        try:
            data = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
        except ValueError as exc:  # an empty file
            raise UnsupportedBag(str(exc)) from None
        try:
            yield data
        except BaseException as exc:
            # the frames the error went through still hold numpy views of the map (the whole file,
            # a chunk, an index): drop them, or close() fails with BufferError and hides the error
            traceback.clear_frames(exc.__traceback__)
            raise
        finally:
            _close(data)


def _close(data: mmap.mmap) -> None:
    """Unmap, once no numpy view of the map is left.  A view caught in a reference cycle lives
    until the collector runs, which a Dask worker runs rarely (it throttles collections): collect
    and try again; a view still alive then unmaps the file when it goes (the map is read-only, the
    file closed), rather than failing a bag whose reading succeeded."""
    try:
        data.close()
    except BufferError:
        gc.collect()
        try:
            data.close()
        except BufferError:
            pass


def read_topics(path: Path, topics: Container[str], decoder: Decoder) -> dict[str, Messages]:
    """The messages of ``topics``, handed to ``decoder`` a batch of chunks at a time, so only what
    it keeps stays in memory, never the whole bag's chunks."""
    with mapped(path) as data:
        return _read_topics(data, topics, decoder)


def connections(path: Path) -> dict[str, str]:
    """Topic → message type (``pkg/msg/Name``) of every connection of a ROS 1 bag, from its index."""
    with mapped(path) as data:
        found, _, _ = _connections(data, None)
        return {topic: _ros2_name(msgtype) for topic, msgtype, _ in found.values()}


def _connections(
    data: mmap.mmap, topics: Container[str] | None
) -> tuple[dict[int, tuple[str, str, str]], int, int]:
    """Connection id → (topic, type, message definition) of ``topics`` (all if None); and where
    the chunk infos start, and how many there are."""
    if data[: len(MAGIC)] != MAGIC:
        raise UnsupportedBag("not a ROS 1 bag 2.0")
    fields, _, _ = _record(data, len(MAGIC))
    if fields.get("op") != bytes([OP_BAG]):
        raise UnsupportedBag("no bag header")
    index_pos = struct.unpack("<Q", fields["index_pos"])[0]
    conn_count = struct.unpack("<I", fields["conn_count"])[0]
    chunk_count = struct.unpack("<I", fields["chunk_count"])[0]
    if index_pos == 0 or index_pos >= len(data):
        raise UnsupportedBag("the bag has no index (not closed properly)")
    found: dict[int, tuple[str, str, str]] = {}
    pos = index_pos
    for _ in range(conn_count):
        fields, data_at, pos = _record(data, pos)
        if fields.get("op") != bytes([OP_CONN]):
            raise UnsupportedBag("connection record expected")
        # ROS 1 records any bytes as a name: one that is not UTF-8 keeps its bytes written out
        topic = fields["topic"].decode(errors="backslashreplace")
        conn_fields, _ = _header_at(data, data_at)  # the data of a connection record is a header too
        if topics is None or topic in topics:
            found[struct.unpack("<I", fields["conn"])[0]] = (
                topic,
                conn_fields.get("type", b"").decode(errors="backslashreplace"),
                conn_fields.get("message_definition", b"").decode(errors="backslashreplace"),
            )
    return found, pos, chunk_count


def _read_topics(data: mmap.mmap, topics: Container[str], decoder: Decoder) -> dict[str, Messages]:
    wanted, pos, chunk_count = _connections(data, topics)
    chunks = []
    for _ in range(chunk_count):
        fields, data_at, pos = _record(data, pos)
        if fields.get("op") != bytes([OP_CHUNK_INFO]):
            raise UnsupportedBag("chunk info record expected")
        chunks.append(struct.unpack("<Q", fields["chunk_pos"])[0])
    times_of: dict[int, list[np.ndarray]] = {c: [] for c in wanted}
    raws_of: dict[int, list[bytes]] = {c: [] for c in wanted}

    def decode(batch: ChunkBatch) -> None:
        for conn, times, messages in batch.messages():
            topic, msgtype, definition = wanted[conn]
            if not decoder(topic, _ros2_name(msgtype), definition, times, messages):
                raws_of[conn].extend(messages.raws())
            times_of[conn].append(times)

    view = np.frombuffer(data, dtype=np.uint8)
    batch, batch_from = ChunkBatch(), 0
    for chunk_pos in chunks:
        if not batch.chunks:
            batch_from = chunk_pos
        pos = _read_chunk(data, view, chunk_pos, wanted, batch)
        if batch.full:
            decode(batch)
            batch = ChunkBatch()
            _release(data, batch_from, pos)
    decode(batch)
    del batch
    out: dict[str, Messages] = {}
    for conn, (topic, msgtype, definition) in wanted.items():
        if not times_of[conn]:
            continue
        times = np.concatenate(times_of[conn])
        if topic in out:  # several connections on one topic: one topic, its messages merged
            known = out[topic]
            times = np.concatenate([known.times, times])
            out[topic] = Messages(known.msgtype, known.definition, times, known.raws + raws_of[conn])
        else:
            out[topic] = Messages(_ros2_name(msgtype), definition, times, raws_of[conn])
    return out


def _read_chunk(
    data: mmap.mmap,
    view: np.ndarray,
    chunk_pos: int,
    wanted: dict[int, tuple[str, str, str]],
    batch: ChunkBatch,
) -> int:
    """Add the chunk at ``chunk_pos`` and its wanted messages to ``batch``; where the records after
    its index-data records start."""
    fields, data_at, after = _record(data, chunk_pos)
    compression = fields.get("compression", b"none")
    if after > len(data):
        raise UnsupportedBag("a chunk runs past the end of the file (truncated?)")
    raw = data[data_at:after] if compression != b"none" else b""
    if compression == b"none":
        chunk = view[data_at:after]
    elif compression == b"bz2":
        chunk = np.frombuffer(bz2.decompress(raw), dtype=np.uint8)
    elif compression == b"lz4":
        try:
            import lz4.frame  # type: ignore[import-untyped]  # rosbags' own dependency
        except ImportError as exc:  # pragma: no cover
            raise UnsupportedBag("lz4 chunks need the lz4 package") from exc
        chunk = np.frombuffer(lz4.frame.decompress(raw), dtype=np.uint8)
    else:
        raise UnsupportedBag(f"chunk compression {compression!r}")
    pos = after
    while pos < len(data):  # the index-data records that follow the chunk
        fields, idx_at, nxt = _record(data, pos)
        if fields.get("op") != bytes([OP_INDEX]):
            break
        if fields.get("ver") != struct.pack("<I", 1):  # rosbag writes version 1: 12-byte entries
            raise UnsupportedBag(f"index-data records of version {fields.get('ver')!r}, not 1")
        conn = struct.unpack("<I", fields["conn"])[0]
        if conn in wanted:
            count = struct.unpack("<I", fields["count"])[0]
            if nxt - idx_at != 12 * count:
                raise UnsupportedBag("an index-data record whose size is not its count's")
            entries = view[idx_at : idx_at + 12 * count].view("<u4").reshape(count, 3)
            times = entries[:, 0].astype(np.int64) * 1_000_000_000 + entries[:, 1]
            offsets = entries[:, 2].astype(np.int64)
            header_len = _u32(chunk, offsets)
            data_len = _u32(chunk, offsets + 4 + header_len)
            starts = offsets + 8 + header_len
            if count and int((starts + data_len).max()) > len(chunk):
                raise UnsupportedBag("a message runs past the end of its chunk")
            batch.add(conn, times, starts, starts + data_len)
        pos = nxt
    batch.close_chunk(chunk)
    return pos


def _release(data: mmap.mmap, start: int, end: int) -> None:
    """Let the kernel drop the pages of a chunk already read (keeps resident memory low)."""
    page = mmap.PAGESIZE
    first = start // page * page
    try:
        data.madvise(mmap.MADV_DONTNEED, first, max(0, end - first) // page * page)
    except (AttributeError, OSError, ValueError):  # not on this platform: only memory is lost
        pass


def _header_at(data: Buffer, data_at: int) -> tuple[dict[str, bytes], int]:
    (size,) = struct.unpack_from("<I", data, data_at - 4)
    fields: dict[str, bytes] = {}
    at, end = data_at, data_at + size
    while at < end:
        (flen,) = struct.unpack_from("<I", data, at)
        name, _, value = bytes(data[at + 4 : at + 4 + flen]).partition(b"=")
        fields[name.decode()] = value
        at += 4 + flen
    return fields, end


def _u32(chunk: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    if len(offsets) and int(offsets.max()) + 4 > len(chunk):
        raise UnsupportedBag("an index points outside its chunk")
    return gather_values(chunk, np.dtype("<u4"), offsets, None).astype(np.int64)


def _ros2_name(msgtype: str) -> str:
    """``geometry_msgs/Twist`` → ``geometry_msgs/msg/Twist`` (the names rosbags uses)."""
    package, _, name = msgtype.partition("/")
    return f"{package}/msg/{name}" if "/msg/" not in msgtype else msgtype
