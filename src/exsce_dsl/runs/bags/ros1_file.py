"""What a ROS 1 bag file (format 2.0) must hold before it is read: its bag header, its index
(connections, chunk infos), the index records after each chunk, and message definitions that
parse; said in a user's terms, with the advice to reindex a damaged bag."""

from __future__ import annotations

import mmap
import struct
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.errors import FileProblem
from exsce_dsl.runs.bags.buffers import u32
from exsce_dsl.runs.bags.file_problems import unparsed
from exsce_dsl.runs.bags.ros1 import MAGIC, OP_BAG, OP_CHUNK, OP_CHUNK_INFO, OP_CONN, OP_INDEX, OP_MSG

_OPS = {
    OP_MSG: "message",
    OP_BAG: "bag header",
    OP_CHUNK: "chunk",
    OP_CHUNK_INFO: "chunk info",
    OP_CONN: "connection",
}
_CHUNK_COMPRESSIONS = (b"none", b"bz2", b"lz4")
_REINDEX = "rebuild its index with ROS 1's `rosbag reindex {file}` (which keeps the original as .orig.bag)"


class _Damaged(FileProblem):
    """The structure of a ROS 1 bag is broken: the advice to reindex it goes where the message says
    ``{reindex}``, else at its end."""


@dataclass(frozen=True)
class _Record:
    """A ROS 1 record: its op code (-1 if it has none), header fields, and where its data lies."""

    op: int
    fields: dict[str, bytes]
    at: int
    data_at: int
    end: int

    def number(self, name: str, fmt: str, what: str) -> int:
        value = self.fields.get(name, b"")
        if len(value) != struct.calcsize(fmt):
            raise _Damaged(f"the {what} at byte {self.at} lacks its {name} field")
        number: int = struct.unpack(fmt, value)[0]
        return number


def _fields(data: mmap.mmap, start: int, end: int, what: str, at: int) -> dict[str, bytes]:
    """The ``name=value`` fields of a ROS 1 record header (or of a connection record's data)."""
    fields: dict[str, bytes] = {}
    while start < end:
        length = u32(data, start) if start + 4 <= end else end
        if start + 4 + length > end:
            raise _Damaged(f"the {what} at byte {at} has a damaged header")
        name, _, value = data[start + 4 : start + 4 + length].partition(b"=")
        fields[name.decode("ascii", "replace")] = value
        start += 4 + length
    return fields


def _record(data: mmap.mmap, at: int, what: str) -> _Record:
    """The record at byte ``at``, which should be a ``what`` (for messages)."""
    size = len(data)
    header_end = at + 4 + (u32(data, at) if at + 4 <= size else size)
    data_end = header_end + 4 + (u32(data, header_end) if header_end + 4 <= size else size)
    if data_end > size:
        raise _Damaged(
            f"the bag is truncated or damaged: its {what} at byte {at} runs past the end of the file "
            f"({size} bytes); copy it again, or {{reindex}}"
        )
    fields = _fields(data, at + 4, header_end, what, at)
    op = fields.get("op", b"")
    return _Record(op[0] if len(op) == 1 else -1, fields, at, header_end + 4, data_end)


def check_ros1(data: mmap.mmap, path: Path) -> None:
    """The bag header, the index (connections, chunk infos) and the index records after each chunk;
    then the message definitions the bag carries."""
    reindex = _REINDEX.format(file=path)
    try:
        connections, messages = _ros1_index(data)
    except _Damaged as damage:
        text = str(damage)
        advice = text.replace("{reindex}", reindex) if "{reindex}" in text else f"{text}; {reindex}"
        raise FileProblem(advice) from None
    except struct.error:  # a number cut off by the end of the file
        raise FileProblem(f"the bag's index runs past the end of the file (truncated?); {reindex}") from None
    if not messages:
        raise FileProblem("the bag holds no messages (its recording stopped before any arrived?)")
    problems = [
        problem
        for topic, msgtype, definition in connections.values()
        if (problem := unparsed(msgtype, definition, [topic], "msg")) is not None
    ]
    if problems:
        raise FileProblem("; ".join(problems))


def _ros1_index(data: mmap.mmap) -> tuple[dict[int, tuple[str, str, str]], int]:
    """Connection id → (topic, type, definition), and how many messages the chunks hold."""
    header = _record(data, len(MAGIC), "bag header")
    if header.op != OP_BAG:
        raise _Damaged("no bag header after the '#ROSBAG V2.0' line: the file is damaged")
    if header.fields.get("encryptor"):
        encryptor = header.fields["encryptor"].decode("ascii", "replace")
        raise FileProblem(f"an encrypted bag ({encryptor}); decrypt it first with ROS 1's `rosbag decrypt`")
    index_pos = header.number("index_pos", "<Q", "bag header")
    conn_count = header.number("conn_count", "<I", "bag header")
    chunk_count = header.number("chunk_count", "<I", "bag header")
    if index_pos == 0:
        raise _Damaged(
            "the bag is not indexed: its recording did not end properly (rosbag record killed, or the "
            "machine stopped); {reindex}, then ingest it again"
        )
    if index_pos > len(data):
        raise _Damaged(
            f"the bag is truncated: it ends at byte {len(data)}, but its index starts at byte {index_pos} "
            "(an interrupted copy or download?); copy it again, or {reindex}"
        )
    if index_pos < header.end:
        raise _Damaged(f"the bag header is damaged: its index would start at byte {index_pos}")
    connections: dict[int, tuple[str, str, str]] = {}
    pos = index_pos
    for _ in range(conn_count):
        record = _record(data, pos, "connection record")
        if record.op != OP_CONN:
            raise _Damaged(f"the bag's index is damaged: no connection record at byte {pos}")
        inner = _fields(data, record.data_at, record.end, "connection record", pos)
        connections[record.number("conn", "<I", "connection record")] = (
            record.fields.get("topic", b"").decode("utf-8", "replace"),
            inner.get("type", b"").decode("utf-8", "replace"),
            inner.get("message_definition", b"").decode("utf-8", "replace"),
        )
        pos = record.end
    messages = 0
    for _ in range(chunk_count):
        info = _record(data, pos, "chunk info record")
        if info.op != OP_CHUNK_INFO:
            raise _Damaged(f"the bag's index is damaged: no chunk info record at byte {pos}")
        version = info.number("ver", "<I", "chunk info record")
        if version != 1:
            raise _Damaged(
                f"not a standard ROS 1 bag: its chunk infos are of version {version} (rosbag writes 1)"
            )
        chunk_pos = info.number("chunk_pos", "<Q", "chunk info record")
        count = info.number("count", "<I", "chunk info record")
        if info.end - info.data_at != 8 * count or not header.end <= chunk_pos < index_pos:
            raise _Damaged(f"the bag's index is damaged: the chunk info at byte {pos} is wrong")
        messages += sum(u32(data, info.data_at + 8 * k + 4) for k in range(count))
        _check_ros1_chunk(data, chunk_pos, count, connections)
        pos = info.end
    return connections, messages


def _check_ros1_chunk(
    data: mmap.mmap, at: int, count: int, connections: dict[int, tuple[str, str, str]]
) -> None:
    """The chunk at ``at``, and the ``count`` index records that must follow it."""
    chunk = _record(data, at, "chunk")
    if chunk.op != OP_CHUNK:
        raise _Damaged(f"the bag's index is damaged: it points to byte {at}, where no chunk starts")
    compression = chunk.fields.get("compression", b"")
    if compression not in _CHUNK_COMPRESSIONS:
        raise FileProblem(
            f"the chunk at byte {at} is compressed with {compression.decode('ascii', 'replace')!r}, "
            "which rosbag does not write (none, bz2 or lz4)"
        )
    pos = chunk.end
    for _ in range(count):
        index = _record(data, pos, "index record")
        if index.op != OP_INDEX:
            found = _OPS.get(index.op) or (
                f"of unknown op 0x{index.op:02x}" if index.op >= 0 else "without op"
            )
            raise _Damaged(
                f"not a standard ROS 1 bag: after the chunk at byte {at} comes a record ({found}) at byte "
                f"{pos}, where the chunk's index records belong (written by a tool other than rosbag?)"
            )
        version = index.number("ver", "<I", "index record")
        if version != 1:
            raise _Damaged(
                f"not a standard ROS 1 bag: its index records are of version {version} (the first after the "
                f"chunk at byte {at}), but rosbag writes and reads version 1"
            )
        entries = index.number("count", "<I", "index record")
        if (
            index.end - index.data_at != 12 * entries
            or index.number("conn", "<I", "index record") not in connections
        ):
            raise _Damaged(f"the bag's index is damaged: the index record at byte {pos} is wrong")
        pos = index.end
