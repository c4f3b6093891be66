"""Read messages of chosen channels straight from an MCAP file's index, with numpy.

The MCAP counterpart of :mod:`exsce_dsl.runs.bags.ros1`'s index reader, with the same
:data:`~exsce_dsl.runs.bags.chunk_batches.Decoder` and
:class:`~exsce_dsl.runs.bags.chunk_batches.Messages`.  An indexed MCAP file (what
rosbag2 and rosbags write) ends with a summary section: its schemas and
channels, and a chunk index per chunk that gives, per channel, where the
chunk's message index record for that channel is.  A message index lists the
(log time, offset) of each of the channel's messages in the decompressed chunk.
So for each chunk holding a wanted channel we decompress the chunk once, read
each wanted channel's message index as an array, and find every message's data
with vectorised gathers over the message records' headers: per chunk Python
work, no per-message Python work.  The receive time of a message is its log
time; its type is the schema's name (``nav_msgs/msg/Odometry``) and its
definition the schema's text, whose encoding (``ros2msg`` or ``ros2idl``)
:func:`schemas` gives.

The file is mapped, but nothing is ever viewed in place: what is read of it
(a record's content, a compressed chunk) is copied out as ``bytes`` first, so
no numpy array or memoryview of the map can outlive reading, whatever a decoder
keeps or raises, and the map always closes.

Every message record is checked against its index entry (opcode, channel, log
time) and its chunk, with the same gathers; a chunk's CRC-32, where the writer
computed one, is checked against its decompressed records (zlib: 0.4 ms per MiB,
about as long again as decompressing it) and a mismatch is :class:`CorruptBag`.

Chunks stored uncompressed, with ``zstd`` or with ``lz4`` are read.  A file
without a summary, a chunk index or message indexes (written so, or not closed:
a truncated file has lost its summary), another compression, or a record that
does not fit where it is said to be raises :class:`UnsupportedBag`, and
:data:`~exsce_dsl.runs.bags.mcap.MCAP` passes the bag to rosbags, which reads
what it can and reports the rest.
"""

from __future__ import annotations

import importlib
import mmap
import struct
import zlib
from collections.abc import Callable, Container
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from exsce_dsl.errors import CorruptBag, UnsupportedBag
from exsce_dsl.runs.bags.buffers import mapped, release
from exsce_dsl.runs.bags.chunk_batches import ChunkBatch, Decoder, Gathered, Messages
from exsce_dsl.runs.bags.formats import MCAP_FILE
from exsce_dsl.wording import counted

MAGIC = MCAP_FILE.magic
OP_HEADER = 0x01
OP_FOOTER = 0x02
OP_SCHEMA = 0x03
OP_CHANNEL = 0x04
OP_MESSAGE = 0x05
OP_CHUNK = 0x06
OP_MESSAGE_INDEX = 0x07
OP_CHUNK_INDEX = 0x08
OP_STATISTICS = 0x0B
RECORD_PREFIX = 9  # opcode u8, content length u64
FOOTER_CONTENT = 20  # summary start u64, summary offset start u64, summary crc u32
MESSAGE_HEADER = np.dtype(
    [
        ("opcode", "u1"),
        ("length", "<u8"),
        ("channel", "<u2"),
        ("sequence", "<u4"),
        ("log_time", "<u8"),
        ("publish_time", "<u8"),
    ]
)
"""A message record up to its data (31 bytes, packed)."""
_HEADER_BYTES = np.arange(MESSAGE_HEADER.itemsize, dtype=np.int64)

IDL_SEPARATOR = "=" * 80 + "\n"
"""Between the ``.idl`` files of a ``ros2idl`` schema, each then headed ``IDL: pkg/msg/Name``."""

MESSAGE_ENCODINGS = ("cdr",)
"""The message encodings the decoders read (ROS 2's)."""
SCHEMA_ENCODINGS = ("ros2msg", "ros2idl")
"""The schema encodings whose text the caller parses (``.msg`` and ``.idl`` forms, as rosbag2 writes).
An empty schema, which rosbag2 writes when it has no definition, may say any encoding: the caller
then finds the definition elsewhere."""


@dataclass(frozen=True)
class Schema:
    """The message type a channel carries, as the file defines it."""

    name: str  # nav_msgs/msg/Odometry
    encoding: str  # ros2msg or ros2idl
    text: str  # the definition: what the decoder is handed as ``definition``


@dataclass(frozen=True)
class _Channel:
    id: int
    topic: str
    message_encoding: str
    schema: Schema | None  # None: a channel without schema (schema id 0)


@dataclass(frozen=True)
class _ChunkIndex:
    start: int  # of the chunk record, in the file
    length: int  # of the chunk record, prefix included
    message_indexes: dict[int, int]  # channel id → where its message index record is, in the file
    message_index_length: int  # of the message index records that follow the chunk
    message_start_time: int
    message_end_time: int


@dataclass(frozen=True)
class _Summary:
    channels: dict[int, _Channel]
    chunks: list[_ChunkIndex]
    message_counts: dict[int, int] | None  # per channel id, from the statistics record if there is one


def _zstd(raw: bytes) -> bytes:
    for name in ("compression.zstd", "backports.zstd", "zstandard"):  # what rosbags itself imports
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        out: bytes = module.decompress(raw)
        return out
    raise UnsupportedBag("zstd chunks need compression.zstd, backports.zstd or zstandard")


def _lz4(raw: bytes) -> bytes:
    try:
        module = importlib.import_module("lz4.frame")  # rosbags' own dependency
    except ImportError:
        raise UnsupportedBag("lz4 chunks need the lz4 package") from None
    out: bytes = module.decompress(raw)
    return out


def _stored(raw: bytes) -> bytes:
    return raw


DECOMPRESSORS: dict[str, Callable[[bytes], bytes]] = {"": _stored, "zstd": _zstd, "lz4": _lz4}
"""Chunk compression (as the chunk names it) → how its records are decompressed."""


def read_topics(path: Path, topics: Container[str], decoder: Decoder) -> dict[str, Messages]:
    """The messages of ``topics``, handed to ``decoder`` a batch of chunks and a channel at a time,
    so only what it keeps stays in memory, never the whole bag's chunks.

    ``definition`` is the schema's text; its encoding (``ros2msg`` or ``ros2idl``) is that of
    the schema :func:`definitions` gives for it.  The channels of a topic may carry different
    schemas of one type (two versions of it); of different types, they are an
    :class:`UnsupportedBag`."""
    return read_channels(path, topics, decoder).by_topic()


def read_channels(path: Path, topics: Container[str], decoder: Decoder) -> Gathered:
    """:func:`read_topics`, the messages kept per channel (each with its own schema)."""
    with mapped(path) as data:
        return _read_topics(data, topics, decoder)


def recorded_span(path: Path) -> tuple[int, int]:
    """The log times (ns) of the file's first and last message, of every channel, from its chunk
    indexes: the recording's span, whichever topics are read."""
    with mapped(path) as data:
        chunks = _summary(data).chunks
        return min(c.message_start_time for c in chunks), max(c.message_end_time for c in chunks)


def schemas(path: Path) -> dict[str, Schema]:
    """Topic → the schema of its channels (of its first channel if they differ), from the
    summary section."""
    with mapped(path) as data:
        summary = _summary(data)
    found: dict[str, Schema] = {}
    for _, channel in sorted(summary.channels.items()):
        if channel.schema is not None:
            found.setdefault(channel.topic, channel.schema)
    return found


def definitions(path: Path) -> dict[tuple[str, str], Schema]:
    """(type name, definition text) → the schema of the file that says it: what a channel's
    messages are decoded by (each channel its own, :func:`read_channels`)."""
    with mapped(path) as data:
        summary = _summary(data)
    found: dict[tuple[str, str], Schema] = {}
    for _, channel in sorted(summary.channels.items()):
        if channel.schema is not None:
            found.setdefault((channel.schema.name, channel.schema.text), channel.schema)
    return found


class _Fields:
    """The fields of one record's content, read in order; reading past its end is an
    :class:`UnsupportedBag`."""

    def __init__(self, content: bytes, what: str) -> None:
        self.content = content
        self.at = 0
        self.what = what

    def _unpack(self, fmt: struct.Struct) -> int:
        if self.at + fmt.size > len(self.content):
            raise UnsupportedBag(f"a {self.what} record is shorter than its fields")
        (value,) = fmt.unpack_from(self.content, self.at)
        self.at += fmt.size
        return int(value)

    def u16(self) -> int:
        return self._unpack(_U16)

    def u32(self) -> int:
        return self._unpack(_U32)

    def u64(self) -> int:
        return self._unpack(_U64)

    def raw(self, size: int) -> bytes:
        if self.at + size > len(self.content):
            raise UnsupportedBag(f"a {self.what} record is shorter than its fields")
        self.at += size
        return self.content[self.at - size : self.at]

    def string(self) -> str:
        try:
            return self.raw(self.u32()).decode()
        except UnicodeDecodeError:
            raise UnsupportedBag(f"a {self.what} record holds a string that is not UTF-8") from None

    def channel_map(self) -> dict[int, int]:
        """A map of channel id (u16) → u64 (an offset in a chunk index, a count in statistics)."""
        entries = self.raw(self.u32())
        if len(entries) % _U16_U64.size:
            raise UnsupportedBag(f"a {self.what} record holds a broken map")
        return {channel: offset for channel, offset in _U16_U64.iter_unpack(entries)}


_U16, _U32, _U64 = struct.Struct("<H"), struct.Struct("<I"), struct.Struct("<Q")
_U16_U64 = struct.Struct("<HQ")
_PREFIX = struct.Struct("<BQ")


def _record(data: mmap.mmap, pos: int, end: int, opcode: int | None = None) -> tuple[int, int, int]:
    """The record at ``pos``, which must end by ``end``: its opcode, where its content starts,
    and where it ends."""
    if pos < 0 or pos + RECORD_PREFIX > end:
        raise UnsupportedBag(f"a record at {pos} lies outside the file or its section (truncated?)")
    found, length = _PREFIX.unpack_from(data, pos)
    if opcode is not None and found != opcode:
        raise UnsupportedBag(f"record {opcode:#04x} expected at {pos}, found {found:#04x}")
    if length > end - pos - RECORD_PREFIX:
        raise UnsupportedBag(f"the record at {pos} runs past the end of the file or its section (truncated?)")
    return found, pos + RECORD_PREFIX, pos + RECORD_PREFIX + length


def _summary(data: mmap.mmap) -> _Summary:
    """The summary section, found through the footer."""
    size = len(data)
    footer = size - len(MAGIC) - RECORD_PREFIX - FOOTER_CONTENT
    if data[: len(MAGIC)] != MAGIC:
        raise UnsupportedBag("not an MCAP file")
    if footer < len(MAGIC):
        raise UnsupportedBag("too short for an MCAP file: truncated")
    if data[size - len(MAGIC) :] != MAGIC:
        raise UnsupportedBag("no closing magic: the file is truncated, or its recorder did not close it")
    _, at, end = _record(data, footer, size - len(MAGIC), OP_FOOTER)
    if end - at != FOOTER_CONTENT:
        raise UnsupportedBag("no footer where the file ends: the file is damaged")
    summary_start, _, crc = struct.unpack_from("<QQI", data, at)
    if summary_start == 0:
        raise UnsupportedBag("the file has no summary section (written without one)")
    if not len(MAGIC) <= summary_start <= footer:
        raise UnsupportedBag("the footer points outside the file")
    if crc and zlib.crc32(data[summary_start : at + 16]) != crc:
        raise UnsupportedBag("the summary section does not match its CRC (damaged)")
    schema_of: dict[int, Schema] = {}
    channels: list[tuple[int, int, str, str]] = []
    chunks: list[_ChunkIndex] = []
    counts: dict[int, int] | None = None
    chunk_count: int | None = None
    pos = summary_start
    while pos < footer:
        opcode, at, pos = _record(data, pos, footer)
        if opcode not in (OP_SCHEMA, OP_CHANNEL, OP_CHUNK_INDEX, OP_STATISTICS):
            continue
        fields = _Fields(data[at:pos], _RECORD_NAMES[opcode])
        if opcode == OP_SCHEMA:
            schema_id, name, encoding = fields.u16(), fields.string(), fields.string()
            text = fields.raw(fields.u32())
            try:
                schema_of[schema_id] = Schema(name, encoding, text.decode())
            except UnicodeDecodeError:
                raise UnsupportedBag(f"the schema of {name} is not UTF-8 text") from None
        elif opcode == OP_CHANNEL:
            channels.append((fields.u16(), fields.u16(), fields.string(), fields.string()))
        elif opcode == OP_CHUNK_INDEX:
            start_time, end_time, start, length = fields.u64(), fields.u64(), fields.u64(), fields.u64()
            offsets = fields.channel_map()
            chunks.append(_ChunkIndex(start, length, offsets, fields.u64(), start_time, end_time))
        else:
            fields.u64()  # message count
            fields.u16()  # schema count
            fields.raw(4 * 3)  # channel, attachment and metadata counts
            chunk_count = fields.u32()
            fields.raw(8 * 2)  # message start and end times
            counts = fields.channel_map() or None  # an empty map: the writer did not count per channel
    found: dict[int, _Channel] = {}
    for channel_id, schema_id, topic, encoding in channels:
        if schema_id and schema_id not in schema_of:
            raise UnsupportedBag(f"channel {topic} refers to schema {schema_id}, which the summary lacks")
        found[channel_id] = _Channel(channel_id, topic, encoding, schema_of.get(schema_id))
    if not chunks:
        raise UnsupportedBag("the summary indexes no chunk (messages written unchunked, or no messages)")
    unknown = {cid for chunk in chunks for cid in chunk.message_indexes} - found.keys()
    if unknown:
        raise UnsupportedBag(f"chunks hold messages of channels {sorted(unknown)}, which the summary lacks")
    if chunk_count is not None and chunk_count != len(chunks):
        raise UnsupportedBag(f"the summary indexes {len(chunks)} of the {counted(chunk_count, 'chunk')}")
    return _Summary(found, sorted(chunks, key=lambda c: c.start), counts)


_RECORD_NAMES = {
    OP_SCHEMA: "schema",
    OP_CHANNEL: "channel",
    OP_CHUNK_INDEX: "chunk index",
    OP_STATISTICS: "statistics",
}


def _wanted(summary: _Summary, topics: Container[str]) -> dict[int, _Channel]:
    wanted = {cid: c for cid, c in sorted(summary.channels.items()) if c.topic in topics}
    first: dict[str, str] = {}
    for channel in wanted.values():
        if channel.schema is None:
            raise UnsupportedBag(f"topic {channel.topic} has a channel without schema")
        if channel.message_encoding not in MESSAGE_ENCODINGS:
            raise UnsupportedBag(f"topic {channel.topic} is encoded as {channel.message_encoding!r}, not CDR")
        if channel.schema.encoding not in SCHEMA_ENCODINGS and channel.schema.text.strip():
            raise UnsupportedBag(f"the schema of topic {channel.topic} is {channel.schema.encoding!r}")
        if first.setdefault(channel.topic, channel.schema.name) != channel.schema.name:
            raise UnsupportedBag(f"topic {channel.topic} has channels of different types")
    return wanted


def _read_topics(data: mmap.mmap, topics: Container[str], decoder: Decoder) -> Gathered:
    summary = _summary(data)
    wanted = _wanted(summary, topics)
    names = {}
    for cid, channel in wanted.items():
        assert channel.schema is not None  # _wanted checked it
        names[cid] = (channel.topic, channel.schema.name, channel.schema.text, f"channel {cid}")
    gathered = Gathered(names, decoder)
    batch, batch_from, batch_to = ChunkBatch(), 0, 0
    for index in summary.chunks:
        if not index.message_indexes:
            if index.message_start_time <= index.message_end_time:
                raise UnsupportedBag("a chunk has no message indexes (written without them)")
            continue  # a chunk of no messages (schemas and channels only)
        here = sorted(wanted.keys() & index.message_indexes.keys())
        if not here:
            continue
        if not batch.chunks:
            batch_from = index.start
        chunk = np.frombuffer(_chunk_records(data, index), dtype=np.uint8)
        for cid in here:
            times, offsets = _message_index(data, index.message_indexes[cid], cid)
            if len(times):
                batch.add(cid, times, *_message_data(chunk, offsets, times, cid))
        batch.close_chunk(chunk)
        batch_to = index.start + index.length + index.message_index_length
        if batch.full:
            gathered.decode(batch)
            batch = ChunkBatch()
            release(data, batch_from, batch_to)
    gathered.decode(batch)
    del batch
    if summary.message_counts is not None:
        for cid, channel in wanted.items():
            found = gathered.count(cid)
            expected = summary.message_counts.get(cid, 0)
            if found != expected:
                raise UnsupportedBag(
                    f"the message indexes of topic {channel.topic} list {counted(found, 'message')}, "
                    f"its statistics {expected}"
                )
    return gathered


def _chunk_records(data: mmap.mmap, index: _ChunkIndex) -> bytes:
    """The decompressed records of the chunk that ``index`` points to."""
    end = index.start + index.length
    if end > len(data) - len(MAGIC):
        raise UnsupportedBag("a chunk index points outside the file")
    _, at, record_end = _record(data, index.start, end, OP_CHUNK)
    fields = _Fields(data[at : min(record_end, at + 1024)], "chunk")  # the fields before the records
    fields.raw(8 * 2)  # message start and end times
    uncompressed_size = fields.u64()
    crc = fields.u32()  # of the decompressed records; 0: the writer did not compute it
    compression = fields.string()
    records_size = fields.u64()
    records_at = at + fields.at
    if records_size > record_end - records_at:
        raise UnsupportedBag("a chunk's records run past the end of the chunk")
    if compression not in DECOMPRESSORS:
        raise UnsupportedBag(f"chunk compression {compression!r}")
    try:
        records = DECOMPRESSORS[compression](data[records_at : records_at + records_size])
    except UnsupportedBag:
        raise
    except Exception as exc:  # each library raises its own errors for damaged data
        raise UnsupportedBag(f"a {compression} chunk does not decompress: {exc}") from None
    if len(records) != uncompressed_size:
        raise UnsupportedBag("a chunk decompresses to another size than it says")
    if crc and zlib.crc32(records) != crc:
        raise CorruptBag(f"checksum mismatch: the chunk at byte {index.start} is not what was recorded")
    return records


def _message_index(data: mmap.mmap, pos: int, cid: int) -> tuple[np.ndarray, np.ndarray]:
    """The log times (int64 ns) and offsets in the chunk (uint64) of channel ``cid``'s messages,
    from its message index record at ``pos``."""
    _, at, end = _record(data, pos, len(data) - len(MAGIC), OP_MESSAGE_INDEX)
    fields = _Fields(data[at : min(end, at + 6)], "message index")
    if fields.u16() != cid:
        raise UnsupportedBag(f"a chunk index points at another channel's message index, not {cid}'s")
    size = fields.u32()
    if size > end - at - 6 or size % 16:
        raise UnsupportedBag("a message index runs past its record")
    entries = np.frombuffer(data[at + 6 : at + 6 + size], dtype="<u8").reshape(-1, 2)
    return entries[:, 0].astype(np.int64), entries[:, 1]


def _message_data(
    chunk: np.ndarray, offsets: np.ndarray, times: np.ndarray, cid: int
) -> tuple[np.ndarray, np.ndarray]:
    """Where the data of each message record at ``offsets`` starts and ends, with every
    record checked against its index entry (opcode, channel, log time) and its chunk."""
    if int(offsets.max()) > len(chunk) - MESSAGE_HEADER.itemsize:
        raise UnsupportedBag("a message index points outside its chunk")
    at = offsets.astype(np.int64)
    headers = chunk[at[:, None] + _HEADER_BYTES].view(MESSAGE_HEADER)[:, 0]
    lengths = headers["length"]
    if (
        np.any(headers["opcode"] != OP_MESSAGE)
        or np.any(headers["channel"] != cid)
        or np.any(headers["log_time"].astype(np.int64) != times)
    ):
        raise UnsupportedBag("a message index entry does not point at its message")
    content = MESSAGE_HEADER.itemsize - RECORD_PREFIX
    if int(lengths.min()) < content or int(lengths.max()) > len(chunk):
        raise UnsupportedBag("a message record has a length that does not fit its chunk")
    ends = at + RECORD_PREFIX + lengths.astype(np.int64)
    if int(ends.max()) > len(chunk):
        raise UnsupportedBag("a message runs past the end of its chunk")
    return at + MESSAGE_HEADER.itemsize, ends
