"""Say what is wrong with a bag before reading it: its format, emptiness, truncation, compression.

The readers (ours for ROS 1 bags, rosbags' for the rest) are fast on
well-formed bags and trust their structure: given a damaged or foreign file
they fail deep inside, in terms of offsets and records, or not at all (under
``python -O`` rosbags' asserts are gone, and a broken index can be read as
garbage).  :func:`check_bag_file` looks first, at what can be told cheaply
(magic bytes, headers, indexes, summaries and message definitions, never the
messages), and says in a user's terms what the file is, what is wrong with it
and what to do about it.  A bag that passes may still hold damaged chunks; its
reader reports those.
"""

from __future__ import annotations

import mmap
import struct
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path, PurePath
from typing import Any

from rosbags.typesys import TypesysError, get_types_from_idl, get_types_from_msg

from exsce_dsl.runs.bags.reading import BagError

ROS1_MAGIC = b"#ROSBAG V2.0\n"
MCAP_MAGIC = b"\x89MCAP0\r\n"
SQLITE_MAGIC = b"SQLite format 3\x00"


@dataclass(frozen=True)
class Compression:
    """A format that compresses a file as a whole: how to recognise it and how to undo it."""

    name: str
    magic: bytes
    suffixes: tuple[str, ...]
    command: str  # {file}: the compressed file, {out}: the bag it holds


WHOLE_FILE = (
    Compression("zstd", b"\x28\xb5\x2f\xfd", (".zst", ".zstd"), "zstd -d {file} -o {out}"),
    Compression("bzip2", b"BZh", (".bz2",), "bzip2 -dc {file} > {out}"),
    Compression("gzip", b"\x1f\x8b", (".gz",), "gzip -dc {file} > {out}"),
    Compression("lz4", b"\x04\x22\x4d\x18", (".lz4",), "lz4 -d {file} {out}"),
    Compression("xz", b"\xfd7zXZ\x00", (".xz",), "xz -dc {file} > {out}"),
)
"""Whole-file compressions a bag may come in (a bag's own chunks are compressed inside it)."""


class _Problem(Exception):
    """What is wrong with one file, in words; :func:`check_bag_file` says which bag it is."""


def check_bag_file(path: Path) -> None:
    """Raise :class:`BagError` if ``path`` is not a bag exsce can read, saying why and what to do.

    ``path`` is a ROS 1 bag (``.bag``), an MCAP file (``.mcap``), a ROS 2 sqlite3
    file (``.db3``) or a ROS 2 bag folder.  Only headers, indexes and message
    definitions are read, so the check costs little even for large bags.
    """
    if not path.exists():
        raise BagError(f"{path}: no such bag")
    if not path.is_file() and not path.is_dir():
        raise BagError(f"{path}: not a bag: neither a file nor a folder")
    if path.name == "metadata.yaml":
        raise BagError(f"{path}: the metadata of a ROS 2 bag, not the bag: give its folder, {path.parent}")
    try:
        if path.is_dir():
            _check_ros2_folder(path)
        else:
            _check_file(path)
    except _Problem as problem:
        raise BagError(f"{path}: {problem}") from None
    except OSError as exc:  # unreadable: permissions, a disk error
        raise BagError(f"{path}: cannot read the bag: {exc.strerror or exc}") from None


def _check_file(path: Path) -> None:
    size = path.stat().st_size
    if size == 0:
        raise _Problem("the file is empty (0 bytes): nothing was recorded into it")
    with path.open("rb") as stream:
        head = stream.read(64)
    for compression in WHOLE_FILE:
        if head.startswith(compression.magic):
            raise _Problem(_compressed(path, compression))
    if head.startswith(ROS1_MAGIC):
        _named(path, ".bag", "a ROS 1 bag")
        _check_mapped(path, _check_ros1)
    elif head.startswith((b"#ROSRECORD V", b"#ROSBAG V")):
        raise _Problem(_old_format(path, head))
    elif head.startswith(MCAP_MAGIC):
        _named(path, ".mcap", "an MCAP file")
        _check_mapped(path, _check_mcap)
    elif head.startswith(SQLITE_MAGIC):
        _named(path, ".db3", "a ROS 2 sqlite3 bag file")
    else:
        raise _Problem(
            "not a bag: a ROS 1 bag starts with '#ROSBAG V2.0', an MCAP file with MCAP's magic bytes, "
            "and a ROS 2 bag is a folder holding metadata.yaml"
        )


def _named(path: Path, suffix: str, what: str) -> None:
    if path.suffix != suffix:
        raise _Problem(
            f"{what}, but named '{path.name}': exsce tells a bag's format by its name; "
            f"rename it to end in {suffix}"
        )


def _compressed(path: Path, compression: Compression) -> str:
    if path.suffix in compression.suffixes:
        out = path.with_suffix("")
    else:
        out = path.with_name(f"{path.stem}.decompressed{path.suffix}")
    command = compression.command.format(file=path, out=out)
    return (
        f"the file is compressed as a whole ({compression.name}), so it is no bag exsce can read; "
        f"decompress it first (`{command}`) and ingest {out.name}"
    )


def _old_format(path: Path, head: bytes) -> str:
    version = head.split(b"\n", 1)[0].rsplit(b"V", 1)[-1].decode("ascii", "replace")
    if head.startswith(b"#ROSRECORD V"):
        return (
            f"a ROS bag of the old format {version} (ROS before 2010), which exsce does not read (only "
            f"format 2.0); migrate it with ROS 1's `rosbag fix {path} {path.with_suffix('.v2.bag')}`, "
            "which writes format 2.0, and ingest the result"
        )
    return f"a ROS bag of format {version}; exsce reads ROS 1 bags of format 2.0 only"


def _check_mapped(path: Path, check: Callable[[mmap.mmap, Path], None]) -> None:
    """``check`` the file mapped into memory (only the pages it reads are read)."""
    try:
        with path.open("rb") as stream, mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as data:
            check(data, path)
    except (struct.error, IndexError):  # a number or a record cut off by the end of the file
        raise _Problem("the file is damaged: a record runs past its end (truncated?)") from None


def _u32(data: bytes | mmap.mmap, at: int) -> int:
    value: int = struct.unpack_from("<I", data, at)[0]
    return value


def _u64(data: bytes | mmap.mmap, at: int) -> int:
    value: int = struct.unpack_from("<Q", data, at)[0]
    return value


# ------------------------------------------------------------------ ROS 1
OP_BAG, OP_INDEX, OP_CHUNK, OP_CHUNK_INFO, OP_CONN = 0x03, 0x04, 0x05, 0x06, 0x07
_OPS = {
    0x02: "message",
    OP_BAG: "bag header",
    OP_CHUNK: "chunk",
    OP_CHUNK_INFO: "chunk info",
    OP_CONN: "connection",
}
_CHUNK_COMPRESSIONS = (b"none", b"bz2", b"lz4")
_REINDEX = "rebuild its index with ROS 1's `rosbag reindex {file}` (which keeps the original as .orig.bag)"


class _Damaged(_Problem):
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
        length = _u32(data, start) if start + 4 <= end else end
        if start + 4 + length > end:
            raise _Damaged(f"the {what} at byte {at} has a damaged header")
        name, _, value = data[start + 4 : start + 4 + length].partition(b"=")
        fields[name.decode("ascii", "replace")] = value
        start += 4 + length
    return fields


def _record(data: mmap.mmap, at: int, what: str) -> _Record:
    """The record at byte ``at``, which should be a ``what`` (for messages)."""
    size = len(data)
    header_end = at + 4 + (_u32(data, at) if at + 4 <= size else size)
    data_end = header_end + 4 + (_u32(data, header_end) if header_end + 4 <= size else size)
    if data_end > size:
        raise _Damaged(
            f"the bag is truncated or damaged: its {what} at byte {at} runs past the end of the file "
            f"({size} bytes); copy it again, or {{reindex}}"
        )
    fields = _fields(data, at + 4, header_end, what, at)
    op = fields.get("op", b"")
    return _Record(op[0] if len(op) == 1 else -1, fields, at, header_end + 4, data_end)


def _check_ros1(data: mmap.mmap, path: Path) -> None:
    """The bag header, the index (connections, chunk infos) and the index records after each chunk;
    then the message definitions the bag carries."""
    reindex = _REINDEX.format(file=path)
    try:
        connections, messages = _ros1_index(data)
    except _Damaged as damage:
        text = str(damage)
        advice = text.replace("{reindex}", reindex) if "{reindex}" in text else f"{text}; {reindex}"
        raise _Problem(advice) from None
    except struct.error:  # a number cut off by the end of the file
        raise _Problem(f"the bag's index runs past the end of the file (truncated?); {reindex}") from None
    if not messages:
        raise _Problem("the bag holds no messages (its recording stopped before any arrived?)")
    problems = [
        problem
        for topic, msgtype, definition in connections.values()
        if (problem := _unparsed(msgtype, definition, [topic], "msg")) is not None
    ]
    if problems:
        raise _Problem("; ".join(problems))


def _ros1_index(data: mmap.mmap) -> tuple[dict[int, tuple[str, str, str]], int]:
    """Connection id → (topic, type, definition), and how many messages the chunks hold."""
    header = _record(data, len(ROS1_MAGIC), "bag header")
    if header.op != OP_BAG:
        raise _Damaged("no bag header after the '#ROSBAG V2.0' line: the file is damaged")
    if header.fields.get("encryptor"):
        encryptor = header.fields["encryptor"].decode("ascii", "replace")
        raise _Problem(f"an encrypted bag ({encryptor}); decrypt it first with ROS 1's `rosbag decrypt`")
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
        messages += sum(_u32(data, info.data_at + 8 * k + 4) for k in range(count))
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
        raise _Problem(
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


def _unparsed(msgtype: str, definition: str, topics: list[str], encoding: str) -> str | None:
    """Why the message definition (``msg`` or ``idl``) a bag carries for ``msgtype`` does not
    parse; None if it does (or if there is none: the reader then takes the type from a typestore)."""
    if not definition.strip():
        return None
    name = msgtype if "/msg/" in msgtype else msgtype.replace("/", "/msg/", 1)
    try:
        if encoding == "msg":
            get_types_from_msg(definition, name)
        elif definition.startswith(f"{_IDL_SEPARATOR}IDL: "):  # several IDL files, each under its name
            for part in definition.split(_IDL_SEPARATOR)[1:]:
                get_types_from_idl(part.split("\n", 1)[1])
        else:
            get_types_from_idl(definition)
    except (TypesysError, IndexError, ValueError) as exc:
        return (
            f"the message definition of {name} ({_topics(topics)}) that the bag carries does not parse"
            f"{_where(str(exc))}: the bag was written with a broken definition"
        )
    return None


def _topics(topics: list[str]) -> str:
    if not topics:
        return "no topic"
    return f"topic {topics[0]}" if len(topics) == 1 else f"topics {', '.join(topics)}"


def _where(error: str) -> str:
    """`` near '...'``: the text rosbags' parser stopped at (its error gives the offset, then the rest)."""
    lines = error.splitlines()
    for k, line in enumerate(lines[:-1]):
        rest = lines[k + 1].strip()
        if line.strip().isdigit() and rest:
            return f" near '{rest[:60]}'"
    return ""


# ------------------------------------------------------------------ MCAP
MCAP_HEADER, MCAP_FOOTER, MCAP_SCHEMA, MCAP_CHANNEL, MCAP_CHUNK = 0x01, 0x02, 0x03, 0x04, 0x06
MCAP_CHUNK_INDEX, MCAP_STATISTICS = 0x08, 0x0B
_FOOTER_SIZE = 1 + 8 + 20
_MCAP_COMPRESSIONS = ("", "zstd", "lz4")
_IDL_SEPARATOR = "=" * 80 + "\n"
_RECOVER = "recover what it holds with `mcap recover {file} -o {out}` (the mcap CLI)"


class _Cursor:
    """Reads MCAP's little-endian numbers and length-prefixed strings from one record."""

    def __init__(self, data: mmap.mmap, at: int, end: int) -> None:
        self.data, self.at, self.end = data, at, min(end, len(data))

    def take(self, size: int) -> bytes:
        if self.at + size > self.end:
            raise _Problem("the MCAP file is damaged: a record is shorter than its fields")
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


def _check_mcap(data: mmap.mmap, path: Path) -> None:
    """Both magics, the header's profile, the footer, and the summary (schemas, channels, chunks)."""
    size = len(data)
    if size < 2 * len(MCAP_MAGIC) + _FOOTER_SIZE or data[size - len(MCAP_MAGIC) :] != MCAP_MAGIC:
        raise _Problem(
            "the MCAP file is truncated: it does not end with MCAP's closing magic bytes (a recording "
            "that was not closed, or an interrupted copy); copy it again, or "
            + _RECOVER.format(file=path, out=f"{path.stem}.recovered.mcap")
        )
    at = len(MCAP_MAGIC)
    if data[at] != MCAP_HEADER:
        raise _Problem("the MCAP file has no header record after its magic bytes: the file is damaged")
    profile = _Cursor(data, at + 9, at + 9 + _u64(data, at + 1)).string()
    if profile != "ros2":
        raise _Problem(
            f"an MCAP file of profile {profile!r}; exsce reads ROS 2 MCAP files (profile 'ros2') only"
        )
    footer = size - len(MCAP_MAGIC) - _FOOTER_SIZE
    if data[footer] != MCAP_FOOTER or _u64(data, footer + 1) != 20:
        raise _Problem("the MCAP file's footer is damaged")
    summary = _u64(data, footer + 9)
    if summary == 0:
        return  # no summary: the reader scans the whole file
    if not len(MCAP_MAGIC) <= summary <= footer:
        raise _Problem(f"the MCAP file's footer is damaged (its summary would start at byte {summary})")
    _check_mcap_summary(data, summary, footer)


def _check_mcap_summary(data: mmap.mmap, at: int, end: int) -> None:
    schemas: dict[int, tuple[str, str, str]] = {}  # id -> name, encoding, definition
    channels: dict[int, tuple[str, int, str]] = {}  # id -> topic, schema id, message encoding
    messages: int | None = None
    while at < end:
        op, length = data[at], _u64(data, at + 1) if at + 9 <= end else end
        if at + 9 + length > end:
            raise _Problem(f"the MCAP file's summary is damaged (the record at byte {at} runs past it)")
        record = _Cursor(data, at + 9, at + 9 + length)
        if op == MCAP_SCHEMA:
            schema = record.u16()
            schemas[schema] = (
                record.string(),
                record.string(),
                record.take(record.u32()).decode("utf-8", "replace"),
            )
        elif op == MCAP_CHANNEL:
            channel, schema = record.u16(), record.u16()
            channels[channel] = (record.string(), schema, record.string())
        elif op == MCAP_STATISTICS:
            messages = record.u64()
        elif op == MCAP_CHUNK_INDEX:
            _check_mcap_chunk(data, record, at)
        at += 9 + length
    foreign = sorted({(topic, encoding) for topic, _, encoding in channels.values() if encoding != "cdr"})
    if foreign:
        listed = ", ".join(f"{topic} ({encoding})" for topic, encoding in foreign)
        raise _Problem(f"topics not serialized as CDR: {listed}; exsce reads ROS 2's CDR messages only")
    if messages == 0:
        raise _Problem("the bag holds no messages (its recording stopped before any arrived?)")
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
        problem = _unparsed(name, definition, topics.get(schema, []), encoding.removeprefix("ros2"))
        if problem is not None:
            problems.append(problem)
    if problems:
        raise _Problem("; ".join(problems))


def _check_mcap_chunk(data: mmap.mmap, index: _Cursor, at: int) -> None:
    """The chunk a chunk index points to is where it says, of the size and compression it says."""
    index.take(16)  # message start and end times
    start, length = index.u64(), index.u64()
    index.take(index.u32())  # offsets of the message indexes
    index.take(8)  # their length
    compression = index.string()
    if compression not in _MCAP_COMPRESSIONS:
        raise _Problem(
            f"chunks compressed with {compression!r}, which exsce cannot read (zstd and lz4 it can)"
        )
    if (
        length < 9
        or start + length > len(data)
        or data[start] != MCAP_CHUNK
        or _u64(data, start + 1) + 9 != length
    ):
        raise _Problem(
            f"the MCAP file is damaged: its chunk index (byte {at}) points to no chunk at byte {start}"
        )


# ------------------------------------------------------------------ ROS 2 folders
def _check_ros2_folder(folder: Path) -> None:
    meta = folder / "metadata.yaml"
    if not meta.is_file():
        inside = sorted(p.name for p in folder.iterdir())
        if not inside:
            raise BagError(
                f"{folder}: an empty folder, not a ROS 2 bag "
                "(which holds metadata.yaml and its .db3 or .mcap files)"
            )
        storage = [name for name in inside if name.endswith((".db3", ".mcap"))]
        if not storage:
            raise BagError(f"{folder}: not a bag: a folder without metadata.yaml, .db3 or .mcap files")
        raise BagError(
            f"{folder}: a ROS 2 bag folder without its metadata.yaml (was the recording killed?); rebuild "
            f"it with `ros2 bag reindex {folder}`"
            + (f", or ingest {folder / storage[0]} itself" if storage[0].endswith(".mcap") else "")
        )
    import yaml  # here: only a ROS 2 bag folder needs it

    try:
        info = _bag_information(yaml.safe_load(meta.read_text(encoding="utf-8")))
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise BagError(f"{folder}: its metadata.yaml does not parse: {reason}") from None
    except _Problem as problem:
        raise BagError(f"{folder}: its metadata.yaml {problem}") from None
    storage_id = str(info.get("storage_identifier", ""))
    if storage_id not in ("sqlite3", "mcap"):
        raise BagError(f"{folder}: a ROS 2 bag stored with {storage_id!r}; exsce reads sqlite3 and mcap bags")
    foreign = sorted(
        (str(t["topic_metadata"].get("name")), str(t["topic_metadata"].get("serialization_format")))
        for t in info["topics_with_message_count"]
        if t["topic_metadata"].get("serialization_format") != "cdr"
    )
    if foreign:
        listed = ", ".join(f"{topic} ({fmt})" for topic, fmt in foreign)
        raise BagError(
            f"{folder}: its metadata.yaml names topics not serialized as CDR: {listed}; "
            "exsce reads ROS 2's CDR messages only"
        )
    mode = str(info.get("compression_mode") or "").lower()
    compression = str(info.get("compression_format") or "")
    if mode not in ("", "none") and compression != "zstd":
        raise BagError(f"{folder}: a ROS 2 bag compressed with {compression!r}; exsce reads zstd only")
    for name in info["relative_file_paths"]:
        file = folder / PurePath(str(name)).name
        if not file.is_file():
            raise BagError(f"{folder}: its file {file.name}, named in metadata.yaml, is missing")
        if mode == "file":  # each file compressed whole, on purpose: the reader decompresses it
            if file.stat().st_size == 0:
                raise BagError(f"{folder}: {file.name}: the file is empty (0 bytes)")
            continue
        try:
            _check_file(file)
        except _Problem as problem:
            raise BagError(f"{folder}: {file.name}: {problem}") from None
    if info.get("message_count") == 0:
        raise BagError(f"{folder}: the bag holds no messages (its recording stopped before any arrived?)")


def _bag_information(meta: Any) -> dict[str, Any]:
    """The ``rosbag2_bagfile_information`` of a metadata.yaml, with the parts read here checked."""
    info = meta.get("rosbag2_bagfile_information") if isinstance(meta, dict) else None
    if not isinstance(info, dict):
        raise _Problem("is not a ROS 2 bag's: it has no rosbag2_bagfile_information")
    topics = info.get("topics_with_message_count") or []
    if not isinstance(topics, list) or not all(
        isinstance(t, dict) and isinstance(t.get("topic_metadata"), dict) for t in topics
    ):
        raise _Problem("is damaged: its topics_with_message_count is not a list of topics")
    files = info.get("relative_file_paths")
    if not isinstance(files, list) or not files:
        raise _Problem("names no storage file (relative_file_paths)")
    return {**info, "topics_with_message_count": topics}
