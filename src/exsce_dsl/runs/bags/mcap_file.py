"""What an MCAP file must hold before it is read: both magics, the ``ros2`` profile, a footer,
and a summary whose chunk indexes point at chunks exsce decompresses, whose channels are CDR and
whose schemas parse; said in a user's terms, with the advice to recover a truncated file."""

from __future__ import annotations

import mmap
import struct
from pathlib import Path

from exsce_dsl.errors import FileProblem
from exsce_dsl.runs.bags.buffers import u64
from exsce_dsl.runs.bags.file_problems import unparsed
from exsce_dsl.runs.bags.formats import MCAP_FILE
from exsce_dsl.runs.bags.mcap_index import (
    DECOMPRESSORS,
    MAGIC,
    OP_CHANNEL,
    OP_CHUNK,
    OP_CHUNK_INDEX,
    OP_FOOTER,
    OP_HEADER,
    OP_SCHEMA,
    OP_STATISTICS,
)

_FOOTER_SIZE = 1 + 8 + 20
_RECOVER = "recover what it holds with `mcap recover {file} -o {out}` (the mcap CLI)"


class _Cursor:
    """Reads MCAP's little-endian numbers and length-prefixed strings from one record."""

    def __init__(self, data: mmap.mmap, at: int, end: int) -> None:
        self.data, self.at, self.end = data, at, min(end, len(data))

    def take(self, size: int) -> bytes:
        if self.at + size > self.end:
            raise FileProblem("the MCAP file is damaged: a record is shorter than its fields")
        value = self.data[self.at : self.at + size]
        self.at += size
        return value

    def u16(self) -> int:
        value: int = struct.unpack("<H", self.take(2))[0]
        return value

    def u32(self) -> int:
        value: int = struct.unpack("<I", self.take(4))[0]
        return value

    def u64(self) -> int:
        value: int = struct.unpack("<Q", self.take(8))[0]
        return value

    def string(self) -> str:
        return self.take(self.u32()).decode("utf-8", "replace")


def check_mcap(data: mmap.mmap, path: Path) -> None:
    """Both magics, the header's profile, the footer, and the summary (schemas, channels, chunks)."""
    size = len(data)
    if size < 2 * len(MAGIC) + _FOOTER_SIZE or data[size - len(MAGIC) :] != MAGIC:
        raise FileProblem(
            "the MCAP file is truncated: it does not end with MCAP's closing magic bytes (a recording "
            "that was not closed, or an interrupted copy); copy it again, or "
            + _RECOVER.format(file=path, out=f"{path.stem}.recovered{MCAP_FILE.suffix}")
        )
    at = len(MAGIC)
    if data[at] != OP_HEADER:
        raise FileProblem("the MCAP file has no header record after its magic bytes: the file is damaged")
    profile = _Cursor(data, at + 9, at + 9 + u64(data, at + 1)).string()
    if profile != "ros2":
        raise FileProblem(
            f"an MCAP file of profile {profile!r}; exsce reads ROS 2 MCAP files (profile 'ros2') only"
        )
    footer = size - len(MAGIC) - _FOOTER_SIZE
    if data[footer] != OP_FOOTER or u64(data, footer + 1) != 20:
        raise FileProblem("the MCAP file's footer is damaged")
    summary = u64(data, footer + 9)
    if summary == 0:
        return  # no summary: the reader scans the whole file
    if not len(MAGIC) <= summary <= footer:
        raise FileProblem(f"the MCAP file's footer is damaged (its summary would start at byte {summary})")
    _check_mcap_summary(data, summary, footer)


def _check_mcap_summary(data: mmap.mmap, at: int, end: int) -> None:
    schemas: dict[int, tuple[str, str, str]] = {}  # id -> name, encoding, definition
    channels: dict[int, tuple[str, int, str]] = {}  # id -> topic, schema id, message encoding
    messages: int | None = None
    while at < end:
        op, length = data[at], u64(data, at + 1) if at + 9 <= end else end
        if at + 9 + length > end:
            raise FileProblem(f"the MCAP file's summary is damaged (the record at byte {at} runs past it)")
        record = _Cursor(data, at + 9, at + 9 + length)
        if op == OP_SCHEMA:
            schema = record.u16()
            schemas[schema] = (
                record.string(),
                record.string(),
                record.take(record.u32()).decode("utf-8", "replace"),
            )
        elif op == OP_CHANNEL:
            channel, schema = record.u16(), record.u16()
            channels[channel] = (record.string(), schema, record.string())
        elif op == OP_STATISTICS:
            messages = record.u64()
        elif op == OP_CHUNK_INDEX:
            _check_mcap_chunk(data, record, at)
        at += 9 + length
    foreign = sorted({(topic, encoding) for topic, _, encoding in channels.values() if encoding != "cdr"})
    if foreign:
        listed = ", ".join(f"{topic} ({encoding})" for topic, encoding in foreign)
        raise FileProblem(f"topics not serialized as CDR: {listed}; exsce reads ROS 2's CDR messages only")
    if messages == 0:
        raise FileProblem("the bag holds no messages (its recording stopped before any arrived?)")
    topics: dict[int, list[str]] = {}
    for topic, schema, _ in sorted(channels.values()):
        topics.setdefault(schema, []).append(topic)
    problems = []
    for schema, (name, encoding, definition) in sorted(schemas.items()):
        if not definition.strip():
            continue  # rosbag2 writes an empty "unknown" schema when it lacks the definition: ours then
        if encoding not in ("ros2msg", "ros2idl"):
            problems.append(f"the message definition of {name} is in {encoding!r}, not ros2msg or ros2idl")
            continue
        problem = unparsed(name, definition, topics.get(schema, []), encoding.removeprefix("ros2"))
        if problem is not None:
            problems.append(problem)
    if problems:
        raise FileProblem("; ".join(problems))


def _check_mcap_chunk(data: mmap.mmap, index: _Cursor, at: int) -> None:
    """The chunk a chunk index points to is where it says, of the size and compression it says."""
    index.take(16)  # message start and end times
    start, length = index.u64(), index.u64()
    index.take(index.u32())  # offsets of the message indexes
    index.take(8)  # their length
    compression = index.string()
    if compression not in DECOMPRESSORS:
        raise FileProblem(
            f"chunks compressed with {compression!r}, which exsce cannot read (zstd and lz4 it can)"
        )
    if (
        length < 9
        or start + length > len(data)
        or data[start] != OP_CHUNK
        or u64(data, start + 1) + 9 != length
    ):
        raise FileProblem(
            f"the MCAP file is damaged: its chunk index (byte {at}) points to no chunk at byte {start}"
        )
