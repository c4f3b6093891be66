"""ROS 1 bags (``.bag``, format 2.0): read straight from the bag's own index, with numpy.

rosbags hands out one Python tuple per message (about 100,000 messages/s
here).  A ROS 1 bag (format 2.0) indexes every message: after each chunk come
index-data records giving, per connection, each message's time and offset in
the chunk.  So for each chunk we read the index as arrays, find each message's
data with a vectorised gather, and hand a connection's messages of a batch of
chunks (:mod:`exsce_dsl.runs.bags.chunk_batches`) to a decoder as one buffer with
their offsets: Python work per batch, none per message.  A type's definition
comes from the connection (the bag's own), else from the user's files, else
from rosbags' ROS 1 typestore.

Uncompressed, bz2 and lz4 chunks are read; anything unexpected raises
:class:`~exsce_dsl.errors.UnsupportedBag` and :data:`ROS1` passes the
bag to the next reader (rosbags').
"""

from __future__ import annotations

import bz2
import functools
import mmap
import struct
from collections.abc import Container, Mapping
from pathlib import Path

import numpy as np

from exsce_dsl.errors import UnsupportedBag
from exsce_dsl.messages.catalogue import MessageCatalogue, Source, parse_definition, standard_ros1_catalogue
from exsce_dsl.model.messages import standard_type
from exsce_dsl.runs.bags.buffers import Buffer, mapped, release
from exsce_dsl.runs.bags.chunk_batches import ChunkBatch, Decoder, Gathered, Messages
from exsce_dsl.runs.bags.data import BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.formats import ROS1_BAG
from exsce_dsl.runs.bags.gather import gather_values
from exsce_dsl.runs.bags.names import BagTopics
from exsce_dsl.runs.bags.objects import deserialized, deserializer_for
from exsce_dsl.runs.bags.reader import BagReader
from exsce_dsl.runs.bags.reading_base import IndexReading

MAGIC = ROS1_BAG.magic
OP_MSG, OP_BAG, OP_INDEX, OP_CHUNK, OP_CHUNK_INFO, OP_CONN = 0x02, 0x03, 0x04, 0x05, 0x06, 0x07


def _header_at(data: Buffer, data_at: int) -> tuple[dict[str, bytes], int]:
    """The ``name=value`` fields of the header whose size is the u32 just before ``data_at``, and
    where the header ends."""
    (size,) = struct.unpack_from("<I", data, data_at - 4)
    fields: dict[str, bytes] = {}
    at, end = data_at, data_at + size
    while at < end:
        (flen,) = struct.unpack_from("<I", data, at)
        name, _, value = bytes(data[at + 4 : at + 4 + flen]).partition(b"=")
        fields[name.decode()] = value
        at += 4 + flen
    return fields, end


def _record(buf: Buffer, pos: int) -> tuple[dict[str, bytes], int, int]:
    """A record at ``pos``: its header fields, where its data starts, and where the next record starts."""
    fields, data_at = _header_at(buf, pos + 4)
    (size,) = struct.unpack_from("<I", buf, data_at)
    return fields, data_at + 4, data_at + 4 + size


def read_topics(path: Path, topics: Container[str], decoder: Decoder) -> dict[str, Messages]:
    """The messages of ``topics``, handed to ``decoder`` a batch of chunks at a time, so only what
    it keeps stays in memory, never the whole bag's chunks."""
    return read_connections(path, topics, decoder).by_topic()


def read_connections(path: Path, topics: Container[str], decoder: Decoder) -> Gathered:
    """:func:`read_topics`, the messages kept per connection (each with its own definition)."""
    with mapped(path) as data:
        return _read_topics(data, topics, decoder)


def connections(path: Path) -> dict[str, str]:
    """Topic → message type (``pkg/msg/Name``) of every connection of a ROS 1 bag, from its index."""
    with mapped(path) as data:
        found, _, _ = _connections(data, None)
        return {topic: _ros2_name(msgtype) for topic, msgtype, _, _ in found.values()}


def recorded_span(path: Path) -> tuple[int, int] | None:
    """The log times (ns) of the bag's first and last message, of every topic, from its chunk
    infos: the recording's span, whichever topics are read."""
    with mapped(path) as data:
        _, pos, chunk_count = _connections(data, ())
        times = []
        for _ in range(chunk_count):
            fields, _, pos = _record(data, pos)
            for name in ("start_time", "end_time"):
                sec, nsec = struct.unpack("<II", fields[name])
                times.append(sec * 10**9 + nsec)
        return (min(times), max(times)) if times else None


def _connections(
    data: mmap.mmap, topics: Container[str] | None
) -> tuple[dict[int, tuple[str, str, str, str]], int, int]:
    """Connection id → (topic, type, message definition, publisher) of ``topics`` (all if None);
    and where the chunk infos start, and how many there are.  The publisher is the connection's
    caller id (the node that published: rosbag records it), else its number."""
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
    found: dict[int, tuple[str, str, str, str]] = {}
    pos = index_pos
    for _ in range(conn_count):
        fields, data_at, pos = _record(data, pos)
        if fields.get("op") != bytes([OP_CONN]):
            raise UnsupportedBag("connection record expected")
        # ROS 1 records any bytes as a name: one that is not UTF-8 keeps its bytes written out
        topic = fields["topic"].decode(errors="backslashreplace")
        conn_fields, _ = _header_at(data, data_at)  # the data of a connection record is a header too
        if topics is None or topic in topics:
            conn = struct.unpack("<I", fields["conn"])[0]
            found[conn] = (
                topic,
                conn_fields.get("type", b"").decode(errors="backslashreplace"),
                conn_fields.get("message_definition", b"").decode(errors="backslashreplace"),
                conn_fields.get("callerid", b"").decode(errors="backslashreplace") or f"connection {conn}",
            )
    return found, pos, chunk_count


def _read_topics(data: mmap.mmap, topics: Container[str], decoder: Decoder) -> Gathered:
    wanted, pos, chunk_count = _connections(data, topics)
    chunks = []
    for _ in range(chunk_count):
        fields, data_at, pos = _record(data, pos)
        if fields.get("op") != bytes([OP_CHUNK_INFO]):
            raise UnsupportedBag("chunk info record expected")
        chunks.append(struct.unpack("<Q", fields["chunk_pos"])[0])
    names = {
        conn: (topic, _ros2_name(msgtype), definition, publisher)
        for conn, (topic, msgtype, definition, publisher) in wanted.items()
    }
    gathered = Gathered(names, decoder)
    view = np.frombuffer(data, dtype=np.uint8)
    batch, batch_from = ChunkBatch(), 0
    for chunk_pos in chunks:
        if not batch.chunks:
            batch_from = chunk_pos
        pos = _read_chunk(data, view, chunk_pos, wanted, batch)
        if batch.full:
            gathered.decode(batch)
            batch = ChunkBatch()
            release(data, batch_from, pos)
    gathered.decode(batch)
    del batch
    return gathered


def _read_chunk(
    data: mmap.mmap,
    view: np.ndarray,
    chunk_pos: int,
    wanted: dict[int, tuple[str, str, str, str]],
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
            header_len = _u32s(chunk, offsets)
            data_len = _u32s(chunk, offsets + 4 + header_len)
            starts = offsets + 8 + header_len
            if count and int((starts + data_len).max()) > len(chunk):
                raise UnsupportedBag("a message runs past the end of its chunk")
            batch.add(conn, times, starts, starts + data_len)
        pos = nxt
    batch.close_chunk(chunk)
    return pos


def _u32s(chunk: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """The u32 at each of ``offsets`` in ``chunk``, gathered at once."""
    if len(offsets) and int(offsets.max()) + 4 > len(chunk):
        raise UnsupportedBag("an index points outside its chunk")
    return gather_values(chunk, np.dtype("<u4"), offsets, None).astype(np.int64)


def _ros2_name(msgtype: str) -> str:
    """``geometry_msgs/Twist`` → ``geometry_msgs/msg/Twist`` (the names rosbags uses)."""
    package, _, name = msgtype.partition("/")
    return f"{package}/msg/{name}" if "/msg/" not in msgtype else msgtype


class _Ros1(IndexReading):
    """The fast path for ROS 1 bags: the bag's own index, numpy gathers, no per-message Python."""

    def read(self) -> BagData:
        found = list(read_connections(self.path, self.match, self.decoder).by_key())
        if not found:
            raise UnsupportedBag("none of the topics")  # rosbags then says whether the bag is empty
        start = min(int(m.times.min()) for _, m in found)
        end = max(int(m.times.max()) for _, m in found)
        span = recorded_span(self.path)  # the recording: its topics not read too
        if span is not None:
            start, end = min(start, span[0]), max(end, span[1])
        for topic, messages in found:  # each connection's by its own definition
            if not messages.raws:
                continue
            catalogue = self.catalogue(topic, messages.msgtype, messages.definition)
            store = deserializer_for(catalogue, messages.msgtype)
            order = np.argsort(messages.times, kind="stable")
            read = functools.partial(store.deserialize_ros1, typename=messages.msgtype)
            objects = deserialized(read, [messages.raws[i] for i in order.tolist()], topic)
            self.add_whole(topic, messages.times[order] / 1e9, objects)
        return self.data(start / 1e9, end / 1e9, tuple(sorted({topic for topic, _ in found})))

    def own_types(self, topic: str, msgtype: str, definition: str) -> MessageCatalogue:
        if not definition.strip():
            return MessageCatalogue()
        return parse_definition(definition, msgtype, "msg", Source(f"the bag {self.path.name}"))

    def standard_types(self) -> MessageCatalogue:
        return standard_ros1_catalogue()


def _read(
    path: Path, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce] | None, check: Check | None
) -> BagData:
    return _Ros1(path, wanted, reduce, check).read()


def _topics(path: Path) -> BagTopics:
    """The bag's own index: rosbags would read every chunk's index first."""
    return BagTopics({topic: standard_type(msgtype) for topic, msgtype in connections(path).items()})


ROS1 = BagReader(
    "ROS 1",
    claims=lambda path: path.is_file() and path.suffix == ROS1_BAG.suffix,
    read=_read,
    topics=_topics,
    formats=(ROS1_BAG,),
)
"""ROS 1 bags (a ``.bag`` file), from the bag's own index."""
