"""Bad bags for the tests, each made at test time from a small valid bag (no binary file is kept).

:func:`small_bags` thins a simulated run of scenario_c down to a tenth of its
messages (about 1 MB) and writes it as a ROS 1 bag, a ROS 2 sqlite3 folder and
an MCAP file; every other function here breaks a copy of one of them the way real
bags are broken (a recorder killed, a copy cut short, a file compressed as a
whole, headers of another tool) and returns the bad bag's path.
"""

from __future__ import annotations

import bz2
import gzip
import os
import shutil
import struct
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from backports import zstd
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer
from rosbags.rosbag2.enums import CompressionFormat, CompressionMode

from exsce_dsl.lang import load_spec
from exsce_dsl.sim.messages import typestore
from exsce_dsl.sim.run import simulate

from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
MCAP_MAGIC = b"\x89MCAP0\r\n"
ROS1_MAGIC = b"#ROSBAG V2.0\n"
OP_INDEX, OP_CHUNK, OP_CHUNK_INFO = 0x04, 0x05, 0x06
Message = tuple[str, str, int, object]  # topic, type, receive time (ns), deserialized message
KEEP_EVERY = {"scan": 40, "robot_pose": 10, "nav_vel": 10, "distance_travelled": 10}
"""Of these topics, one message in so many is kept (the dispatcher's are all kept)."""
CHUNK_SIZE = 1 << 16
"""Bytes of messages per chunk of the ROS 1 bags (rosbag's default is 768 KiB): several chunks."""


# ------------------------------------------------------------------ small valid bags
def _thinned_messages(folder: Path) -> list[Message]:
    scenario = load_spec(SPEC).scenario()
    [run] = simulate(scenario, folder / "full", runs=1, fmt="ros1", seed=3)
    kept: list[Message] = []
    seen: dict[str, int] = {}
    with AnyReader([run.bag], default_typestore=typestore("ros1")) as reader:
        for conn, timestamp, raw in reader.messages():
            every = KEEP_EVERY.get(conn.topic.rsplit("/", 1)[-1], 1)
            n = seen[conn.topic] = seen.get(conn.topic, -1) + 1
            if n % every == 0:
                kept.append((conn.topic, conn.msgtype, timestamp, reader.deserialize(raw, conn.msgtype)))
    shutil.rmtree(folder / "full")
    return kept


def write_ros1(path: Path, messages: list[Message], msgdefs: dict[str, str] | None = None) -> Path:
    """A ROS 1 bag of ``messages``; ``msgdefs`` (topic → text) replaces the definitions the bag carries."""
    store = typestore("ros1")
    writer = Ros1Writer(path)
    writer.chunk_threshold = CHUNK_SIZE
    with writer:
        conns = {}
        for topic, msgtype, timestamp, msg in messages:
            if topic not in conns:
                msgdef = (msgdefs or {}).get(topic)
                extra = {"msgdef": msgdef, "md5sum": "0" * 32} if msgdef is not None else {}
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store, **extra)
            writer.write(conns[topic], timestamp, store.serialize_ros1(msg, msgtype))
    return path


def write_ros2(
    path: Path,
    messages: list[Message],
    storage: StoragePlugin = StoragePlugin.SQLITE3,
    compressed_chunks: bool = False,
    msgdefs: dict[str, str] | None = None,
) -> Path:
    """A ROS 2 bag folder of ``messages`` (sqlite3 or MCAP; zstd-compressed MCAP chunks if asked)."""
    store = typestore("ros2")
    writer = Ros2Writer(path, version=8, storage_plugin=storage)
    if compressed_chunks:
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer:
        conns = {}
        for topic, msgtype, timestamp, msg in messages:
            if topic not in conns:
                msgdef = (msgdefs or {}).get(topic)
                extra = {"msgdef": msgdef, "rihs01": "RIHS01_" + "0" * 64} if msgdef is not None else {}
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store, **extra)
            writer.write(conns[topic], timestamp, store.serialize_cdr(msg, msgtype))
    return path


def small_bags(folder: Path) -> dict[str, Path]:
    """A short run of scenario_c as ``ros1`` (a .bag), ``ros2`` (a sqlite3 folder) and ``mcap`` (a .mcap
    file), all three with the same messages."""
    folder.mkdir(parents=True, exist_ok=True)
    messages = _thinned_messages(folder)
    mcap_folder = write_ros2(folder / "mcap", messages, StoragePlugin.MCAP)
    return {
        "ros1": write_ros1(folder / "run.bag", messages),
        "ros2": write_ros2(folder / "ros2", messages),
        "mcap": next(mcap_folder.glob("*.mcap")),
    }


# ------------------------------------------------------------------ ROS 1 records
@dataclass
class Record:
    """One record of a ROS 1 bag (format 2.0): its header fields, in order, and its data."""

    fields: dict[str, bytes]
    data: bytes
    at: int  # where it was in the bag read

    @property
    def op(self) -> int:
        return self.fields["op"][0]

    def to_bytes(self) -> bytes:
        header = b"".join(
            struct.pack("<I", len(name) + 1 + len(value)) + name.encode() + b"=" + value
            for name, value in self.fields.items()
        )
        return struct.pack("<I", len(header)) + header + struct.pack("<I", len(self.data)) + self.data


def read_records(path: Path) -> list[Record]:
    """Every top-level record of a ROS 1 bag, in file order."""
    raw = path.read_bytes()
    assert raw.startswith(ROS1_MAGIC)
    records, pos = [], len(ROS1_MAGIC)
    while pos < len(raw):
        (size,) = struct.unpack_from("<I", raw, pos)
        fields, at = {}, pos + 4
        while at < pos + 4 + size:
            (flen,) = struct.unpack_from("<I", raw, at)
            name, _, value = raw[at + 4 : at + 4 + flen].partition(b"=")
            fields[name.decode()] = value
            at += 4 + flen
        (dlen,) = struct.unpack_from("<I", raw, at)
        records.append(Record(fields, raw[at + 4 : at + 4 + dlen], pos))
        pos = at + 4 + dlen
    return records


def write_records(path: Path, records: list[Record]) -> Path:
    """A ROS 1 bag of ``records``, with the bag header's index position and the chunk infos' chunk
    positions moved to where their records now are."""
    moved: dict[int, int] = {}
    pos = len(ROS1_MAGIC)
    for record in records:
        moved[record.at] = pos
        pos += len(record.to_bytes())
    header = records[0]
    index_pos = struct.unpack("<Q", header.fields["index_pos"])[0]
    if index_pos:
        header.fields["index_pos"] = struct.pack("<Q", moved[index_pos])
    for record in records:
        if record.op == OP_CHUNK_INFO:
            chunk_pos = struct.unpack("<Q", record.fields["chunk_pos"])[0]
            record.fields["chunk_pos"] = struct.pack("<Q", moved[chunk_pos])
    path.write_bytes(ROS1_MAGIC + b"".join(r.to_bytes() for r in records))
    return path


# ------------------------------------------------------------------ MCAP records
MCAP_CHUNK, MCAP_FOOTER = 0x06, 0x02


def mcap_records(raw: bytes) -> list[tuple[int, int, int]]:
    """(opcode, where the record starts, where its content starts) of each top-level MCAP record."""
    found, pos = [], len(MCAP_MAGIC)
    while pos < len(raw) - len(MCAP_MAGIC):
        op = raw[pos]
        (length,) = struct.unpack_from("<Q", raw, pos + 1)
        found.append((op, pos, pos + 9))
        pos += 9 + length
    return found


def _chunk_records_at(raw: bytes, content: int) -> int:
    """Where the records of the chunk whose content starts at ``content`` begin."""
    (compression_len,) = struct.unpack_from("<I", raw, content + 28)
    return content + 32 + compression_len + 8


# ------------------------------------------------------------------ the bad bags
Maker = Callable[[dict[str, Path], Path], Path]
"""(the small valid bags, a folder of its own) → a bad bag."""


def empty_bag(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "empty.bag").write_bytes(b"")
    return folder / "empty.bag"


def empty_mcap(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "empty.mcap").write_bytes(b"")
    return folder / "empty.mcap"


def empty_folder(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "empty_ros2").mkdir()
    return folder / "empty_ros2"


def ros1_without_messages(bags: dict[str, Path], folder: Path) -> Path:
    with Ros1Writer(folder / "nothing.bag"):
        pass
    return folder / "nothing.bag"


def ros1_connections_without_messages(bags: dict[str, Path], folder: Path) -> Path:
    with Ros1Writer(folder / "silent.bag") as writer:
        for topic in ("/tiago1/robot_pose", "/tiago1/nav_vel"):
            msgtype = (
                "geometry_msgs/msg/PoseWithCovarianceStamped"
                if "pose" in topic
                else "geometry_msgs/msg/Twist"
            )
            writer.add_connection(topic, msgtype, typestore=typestore("ros1"))
    return folder / "silent.bag"


def mcap_without_messages(bags: dict[str, Path], folder: Path) -> Path:
    with Ros2Writer(folder / "nothing", version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        writer.add_connection("/tiago1/nav_vel", "geometry_msgs/msg/Twist", typestore=typestore("ros2"))
    return folder / "nothing" / "nothing.mcap"


def ros2_without_messages(bags: dict[str, Path], folder: Path) -> Path:
    with Ros2Writer(folder / "nothing", version=8) as writer:
        writer.add_connection("/tiago1/nav_vel", "geometry_msgs/msg/Twist", typestore=typestore("ros2"))
    return folder / "nothing"


def ros1_index_version_2(bags: dict[str, Path], folder: Path) -> Path:
    """Index-data records of a version 2 that has 16-byte entries (rosbag writes and reads version 1,
    of 12-byte entries: time and offset)."""
    records = read_records(bags["ros1"])
    for record in records:
        if record.op == OP_INDEX:
            record.fields["ver"] = struct.pack("<I", 2)
            entries = [record.data[k : k + 12] for k in range(0, len(record.data), 12)]
            record.data = b"".join(entry + b"\0\0\0\0" for entry in entries)
    return write_records(folder / "index_v2.bag", records)


def _with_record_after(bags: dict[str, Path], target: Path, after_index: bool) -> Path:
    """An unknown record (op 0x42) after the second chunk: before its index records, or after them."""
    records = read_records(bags["ros1"])
    chunks = [i for i, r in enumerate(records) if r.op == OP_CHUNK]
    at = chunks[1] + 1
    if after_index:
        while records[at].op == OP_INDEX:
            at += 1
    stranger = Record({"op": bytes([0x42]), "tool": b"someone else's"}, b"\x00" * 16, -1)
    return write_records(target, [*records[:at], stranger, *records[at:]])


def ros1_record_before_index(bags: dict[str, Path], folder: Path) -> Path:
    return _with_record_after(bags, folder / "stranger_in_index.bag", after_index=False)


def ros1_record_between_chunks(bags: dict[str, Path], folder: Path) -> Path:
    return _with_record_after(bags, folder / "stranger_between_chunks.bag", after_index=True)


def ros1_version_1_2(bags: dict[str, Path], folder: Path) -> Path:
    """The magic line of the format of ROS before 2010, and bytes that follow it."""
    (folder / "old.bag").write_bytes(b"#ROSRECORD V1.2\n" + bags["ros1"].read_bytes()[13:4000])
    return folder / "old.bag"


def ros1_unindexed(bags: dict[str, Path], folder: Path) -> Path:
    """What a killed ``rosbag record`` leaves: chunks, no index, a header whose index position is 0."""
    records = read_records(bags["ros1"])
    header = records[0]
    index_pos = struct.unpack("<Q", header.fields["index_pos"])[0]
    header.fields.update(
        index_pos=struct.pack("<Q", 0), conn_count=struct.pack("<I", 0), chunk_count=struct.pack("<I", 0)
    )
    return write_records(folder / "killed.bag", [r for r in records if r.at < index_pos])


def ros1_truncated_mid_chunk(bags: dict[str, Path], folder: Path) -> Path:
    raw = bags["ros1"].read_bytes()
    chunks = [r for r in read_records(bags["ros1"]) if r.op == OP_CHUNK]
    middle = chunks[len(chunks) // 2]
    (folder / "cut.bag").write_bytes(raw[: middle.at + len(middle.data) // 2])
    return folder / "cut.bag"


def ros1_truncated_in_header(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "stub.bag").write_bytes(bags["ros1"].read_bytes()[:100])
    return folder / "stub.bag"


def ros1_named_mcap(bags: dict[str, Path], folder: Path) -> Path:
    shutil.copy(bags["ros1"], folder / "run.mcap")
    return folder / "run.mcap"


def ros2_without_metadata(bags: dict[str, Path], folder: Path) -> Path:
    """A ROS 2 bag folder whose recorder was killed before it wrote metadata.yaml."""
    shutil.copytree(bags["mcap"].parent, folder / "killed")
    (folder / "killed" / "metadata.yaml").unlink()
    return folder / "killed"


def ros2_metadata_nested_deep(bags: dict[str, Path], folder: Path) -> Path:
    """A ROS 2 bag folder whose metadata.yaml nests 50,000 lists deep (issue 46: Python's YAML
    loader recursed until it failed, an internal error)."""
    shutil.copytree(bags["mcap"].parent, folder / "deep")
    (folder / "deep" / "metadata.yaml").write_text("[" * 50_000 + "]" * 50_000)
    return folder / "deep"


def ros2_metadata_fifo(bags: dict[str, Path], folder: Path) -> Path:
    """A ROS 2 bag folder whose metadata.yaml is a FIFO that nobody writes (issue 46: reading it
    waited forever)."""
    shutil.copytree(bags["mcap"].parent, folder / "fifo")
    (folder / "fifo" / "metadata.yaml").unlink()
    os.mkfifo(folder / "fifo" / "metadata.yaml")
    return folder / "fifo"


def garbage_named_bag(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "noise.bag").write_bytes(bytes(range(256)) * 64)
    return folder / "noise.bag"


def mcap_truncated_middle(bags: dict[str, Path], folder: Path) -> Path:
    raw = bags["mcap"].read_bytes()
    (folder / "cut.mcap").write_bytes(raw[: len(raw) // 2])
    return folder / "cut.mcap"


def mcap_truncated_before_footer(bags: dict[str, Path], folder: Path) -> Path:
    raw = bags["mcap"].read_bytes()
    footer = next(at for op, at, _ in mcap_records(raw) if op == MCAP_FOOTER)
    (folder / "no_footer.mcap").write_bytes(raw[:footer])
    return folder / "no_footer.mcap"


def _messages(bags: dict[str, Path]) -> list[Message]:
    with AnyReader([bags["ros1"]], default_typestore=typestore("ros1")) as reader:
        return [
            (c.topic, c.msgtype, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()
        ]


def mcap_corrupt_compressed_chunk(bags: dict[str, Path], folder: Path) -> Path:
    """zstd-compressed chunks, one of them with a page of zeros in the middle (a disk or file
    system losing a block)."""
    written = write_ros2(folder / "zchunks", _messages(bags), StoragePlugin.MCAP, compressed_chunks=True)
    path = next(written.glob("*.mcap"))
    raw = bytearray(path.read_bytes())
    chunks = [(at, content) for op, at, content in mcap_records(bytes(raw)) if op == MCAP_CHUNK]
    at, content = chunks[len(chunks) // 2]
    start, end = _chunk_records_at(bytes(raw), content), at + 9 + struct.unpack_from("<Q", raw, at + 1)[0]
    middle = (start + end) // 2
    raw[middle : middle + 4096] = bytes(4096)
    path.write_bytes(bytes(raw))
    return path


def mcap_chunk_checksum_mismatch(bags: dict[str, Path], folder: Path) -> Path:
    """Chunks with their CRC-32 (as the mcap recorder writes them), one byte of one chunk changed."""
    raw = bytearray(bags["mcap"].read_bytes())
    chunks = [(at, content) for op, at, content in mcap_records(bytes(raw)) if op == MCAP_CHUNK]
    for at, content in chunks:
        (length,) = struct.unpack_from("<Q", raw, at + 1)
        start = _chunk_records_at(bytes(raw), content)
        struct.pack_into("<I", raw, content + 24, zlib.crc32(raw[start : at + 9 + length]))
    start = _chunk_records_at(bytes(raw), chunks[len(chunks) // 2][1])
    raw[start + 500] ^= 0x55
    (folder / "crc.mcap").write_bytes(bytes(raw))
    return folder / "crc.mcap"


def mcap_zstd_whole(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "run.mcap.zstd").write_bytes(zstd.compress(bags["mcap"].read_bytes()))
    return folder / "run.mcap.zstd"


def mcap_zstd_named_mcap(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "run.mcap").write_bytes(zstd.compress(bags["mcap"].read_bytes()))
    return folder / "run.mcap"


def ros1_bz2_whole(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "run.bag.bz2").write_bytes(bz2.compress(bags["ros1"].read_bytes()))
    return folder / "run.bag.bz2"


def ros1_zst_whole(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "run.bag.zst").write_bytes(zstd.compress(bags["ros1"].read_bytes()))
    return folder / "run.bag.zst"


def ros1_gzip_whole(bags: dict[str, Path], folder: Path) -> Path:
    (folder / "run.bag.gz").write_bytes(gzip.compress(bags["ros1"].read_bytes()))
    return folder / "run.bag.gz"


def ros2_protobuf(bags: dict[str, Path], folder: Path) -> Path:
    """A ROS 2 bag whose metadata says one topic is serialized with protobuf, not CDR."""
    target = folder / "protobuf"
    shutil.copytree(bags["ros2"], target)
    for db in target.glob("*.db3"):
        db.rename(target / f"protobuf{db.suffix}")
    meta = target / "metadata.yaml"
    text = meta.read_text().replace(bags["ros2"].name + ".db3", "protobuf.db3")
    topic = "name: /tiago1/robot_pose"
    at = text.index(topic)
    end = text.index("serialization_format: cdr", at)
    meta.write_text(
        text[:end] + "serialization_format: protobuf" + text[end + len("serialization_format: cdr") :]
    )
    return target


GARBAGE_DEFINITION = "float64 x\n%%% not a message definition ]]\n"


def ros1_garbage_definition(bags: dict[str, Path], folder: Path) -> Path:
    return write_ros1(folder / "garbage_def.bag", _messages(bags), {"/tiago1/nav_vel": GARBAGE_DEFINITION})


def mcap_garbage_schema(bags: dict[str, Path], folder: Path) -> Path:
    written = write_ros2(
        folder / "garbage_schema",
        _messages(bags),
        StoragePlugin.MCAP,
        msgdefs={"/tiago1/nav_vel": GARBAGE_DEFINITION},
    )
    return next(written.glob("*.mcap"))


MAKERS: dict[str, Maker] = {
    "empty .bag": empty_bag,
    "empty .mcap": empty_mcap,
    "empty ROS 2 folder": empty_folder,
    "ROS 1 without messages": ros1_without_messages,
    "ROS 1 connections without messages": ros1_connections_without_messages,
    "MCAP without messages": mcap_without_messages,
    "ROS 2 without messages": ros2_without_messages,
    "ROS 1 index records of version 2": ros1_index_version_2,
    "ROS 1 unknown record before a chunk's index": ros1_record_before_index,
    "ROS 1 format 1.2": ros1_version_1_2,
    "ROS 1 unindexed": ros1_unindexed,
    "ROS 1 truncated mid-chunk": ros1_truncated_mid_chunk,
    "ROS 1 truncated in its header": ros1_truncated_in_header,
    "ROS 1 bag named .mcap": ros1_named_mcap,
    "ROS 2 folder without metadata.yaml": ros2_without_metadata,
    "ROS 2 metadata.yaml nested deep": ros2_metadata_nested_deep,
    "ROS 2 metadata.yaml a FIFO": ros2_metadata_fifo,
    "garbage named .bag": garbage_named_bag,
    "MCAP truncated in the middle": mcap_truncated_middle,
    "MCAP truncated before its footer": mcap_truncated_before_footer,
    "MCAP compressed chunk corrupted": mcap_corrupt_compressed_chunk,
    "MCAP chunk checksum mismatch": mcap_chunk_checksum_mismatch,
    "MCAP compressed whole (.mcap.zstd)": mcap_zstd_whole,
    "MCAP compressed whole, named .mcap": mcap_zstd_named_mcap,
    "ROS 1 compressed whole (.bag.bz2)": ros1_bz2_whole,
    "ROS 1 compressed whole (.bag.zst)": ros1_zst_whole,
    "ROS 1 compressed whole (.bag.gz)": ros1_gzip_whole,
    "ROS 2 protobuf serialization": ros2_protobuf,
    "ROS 1 garbage message definition": ros1_garbage_definition,
    "MCAP garbage schema": mcap_garbage_schema,
}
"""Each kind of bad bag, by a name that says what is wrong with it."""
