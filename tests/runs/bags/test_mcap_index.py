"""The MCAP index reader (``runs/bags/mcap_index.py``) and the MCAP reader (``runs/bags/mcap.py``).

Bags are written with rosbags' writer and read back two ways: by our reader,
and by rosbags' AnyReader, one message at a time (an independent path).  Per
topic, the (receive time, raw bytes) pairs must be the same.  rosbags writes
chunks of 1 MiB, zstd-compressed or not; to get lz4 chunks and small chunks we
set its chunk writer's compressor and close its chunks ourselves.  Broken files
are made from good ones by rewriting their records (the helpers below parse
MCAP records on their own, from the specification).
"""

from __future__ import annotations

import shutil
import struct
import zlib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import lz4.frame
import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.errors import UnsupportedBag
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bags import reading as bagdata
from exsce_dsl.runs.bags.data import OBJECTS, Wanted
from exsce_dsl.runs.bags.mcap import mcap_files
from exsce_dsl.runs.bags.mcap_index import read_topics, schemas
from exsce_dsl.runs.bags.raw_messages import RawMessages
from exsce_dsl.runs.bags.reading import read_bag
from exsce_dsl.runs.bags.rosbags_fallback import read_with_rosbags
from exsce_dsl.sim.messages import FEEDBACK
from exsce_dsl.sim.messages import typestore as sim_typestore

STORE = get_typestore(Stores.ROS2_HUMBLE)
T = STORE.types
MAGIC = b"\x89MCAP0\r\n"
OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_CHUNK, OP_MESSAGE_INDEX = 0x02, 0x03, 0x04, 0x06, 0x07
OP_CHUNK_INDEX, OP_STATISTICS, OP_SUMMARY_OFFSET, OP_DATA_END = 0x08, 0x0B, 0x0E, 0x0F
START = 1_700_000_000 * 10**9
WANTED = {"/odom", "/chatter", "/pose", "/late"}
IDL = (
    "=" * 80 + "\nIDL: test_msgs/msg/Reading\n"
    "module test_msgs {\n  module msg {\n    struct Reading {\n"
    "      double value;\n      string label;\n    };\n  };\n};\n"
)

Written = tuple[str, int, int, bytes]  # topic, channel (0 or 1), receive time (ns), raw CDR


# ------------------------------------------------------------------ writing bags
def _qos(depth: int) -> Qos:
    zero = QosTime(0, 0)
    return Qos(
        QosHistory.KEEP_LAST, depth, QosReliability.RELIABLE, QosDurability.VOLATILE,
        zero, zero, QosLiveliness.AUTOMATIC, zero, False,
    )  # fmt: skip


def _header(t: int, frame: str) -> Any:
    stamp = T["builtin_interfaces/msg/Time"](sec=t // 10**9, nanosec=t % 10**9)
    return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def _odometry(t: int, i: int) -> bytes:
    point = T["geometry_msgs/msg/Point"](x=float(i), y=-float(i), z=0.0)
    quat = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    vec = T["geometry_msgs/msg/Vector3"](x=0.5 * i, y=0.0, z=0.25)
    msg = T["nav_msgs/msg/Odometry"](
        header=_header(t, "odom" + "_" * (i % 5)),
        child_frame_id="base_link" + "x" * (i % 3),
        pose=T["geometry_msgs/msg/PoseWithCovariance"](
            pose=T["geometry_msgs/msg/Pose"](position=point, orientation=quat), covariance=np.zeros(36)
        ),
        twist=T["geometry_msgs/msg/TwistWithCovariance"](
            twist=T["geometry_msgs/msg/Twist"](linear=vec, angular=vec), covariance=np.zeros(36)
        ),
    )
    return bytes(STORE.serialize_cdr(msg, "nav_msgs/msg/Odometry"))


def _string(text: str) -> bytes:
    return bytes(STORE.serialize_cdr(T["std_msgs/msg/String"](data=text), "std_msgs/msg/String"))


def _pose(t: int, i: int) -> bytes:
    point = T["geometry_msgs/msg/Point"](x=float(i), y=2.0, z=0.0)
    quat = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    pose = T["geometry_msgs/msg/Pose"](position=point, orientation=quat)
    msg = T["geometry_msgs/msg/PoseStamped"](header=_header(t, "map" * (1 + i % 2)), pose=pose)
    return bytes(STORE.serialize_cdr(msg, "geometry_msgs/msg/PoseStamped"))


TYPES = {
    "/odom": "nav_msgs/msg/Odometry",
    "/chatter": "std_msgs/msg/String",
    "/pose": "geometry_msgs/msg/PoseStamped",
    "/late": "std_msgs/msg/String",
    "/other": "std_msgs/msg/Int32",
}


def recording(seed: int = 1, count: int = 400, big: int = 40_000) -> list[Written]:
    """Several topics interleaved, in write order: strings of 0 to ``big`` characters, /pose on two
    channels, /late with receive times out of order, /other never asked for."""
    rng = np.random.default_rng(seed)
    out: list[Written] = []
    for i in range(count):
        t = START + i * 10_000_000 + int(rng.integers(0, 1000))
        kind = i % 5
        if kind == 0:
            out.append(("/odom", 0, t, _odometry(t, i)))
        elif kind == 1:
            size = int(rng.integers(0, big + 1))
            out.append(("/chatter", 0, t, _string("".join(rng.choice(list("abcdef"), size)))))
        elif kind == 2:
            out.append(("/pose", i % 2, t, _pose(t, i)))
        elif kind == 3:
            late = t - int(rng.integers(0, 500_000_000))  # a receive time before earlier messages
            out.append(("/late", 0, late, _string("late" * int(rng.integers(0, 40)))))
        else:
            out.append(
                ("/other", 0, t, bytes(STORE.serialize_cdr(T["std_msgs/msg/Int32"](data=i), TYPES["/other"])))
            )
    return out


def write_bag(
    path: Path,
    written: list[Written],
    compression: str = "",
    chunk_every: int | None = None,
    version: int = 9,
) -> Path:
    """An MCAP bag folder of ``written``: chunks compressed with ``compression`` ('', zstd, lz4), closed
    every ``chunk_every`` messages if given (else at rosbags' 1 MiB)."""
    writer = Writer(path, version=version, storage_plugin=StoragePlugin.MCAP)
    if compression == "zstd":
        writer.set_compression(CompressionMode.STORAGE, CompressionFormat.ZSTD)
    with writer:
        storage = writer.storage
        if compression == "lz4" or chunk_every:
            if not all(hasattr(storage, a) for a in ("compression", "compressor", "close_chunk")):
                pytest.skip("this rosbags' MCAP writer cannot be set to lz4 or small chunks")
        if compression == "lz4":  # rosbags writes zstd or uncompressed chunks: lz4 by hand
            storage.compression, storage.compressor = "lz4", lz4.frame.compress
        conns: dict[tuple[str, int], Any] = {}
        for i, (topic, channel, t, raw) in enumerate(written):
            if (topic, channel) not in conns:
                conns[(topic, channel)] = writer.add_connection(
                    topic, TYPES[topic], typestore=STORE, offered_qos_profiles=[_qos(1 + channel)]
                )
            writer.write(conns[(topic, channel)], t, raw)
            if chunk_every and i % chunk_every == chunk_every - 1:
                storage.close_chunk()
    return path


def mcap_of(folder: Path) -> Path:
    return folder / f"{folder.name}.mcap"


# ------------------------------------------------------------------ reading them
def by_rosbags(path: Path, topics: set[str]) -> dict[str, list[tuple[int, bytes]]]:
    """Per topic, the sorted (receive time, raw bytes) pairs, by rosbags' AnyReader."""
    out: dict[str, list[tuple[int, bytes]]] = {}
    with AnyReader([path], default_typestore=STORE) as reader:
        conns = [c for c in reader.connections if c.topic in topics]
        for conn, t, raw in reader.messages(connections=conns):
            out.setdefault(conn.topic, []).append((t, bytes(raw)))
    return {topic: sorted(pairs) for topic, pairs in out.items()}


def by_index(file: Path, topics: set[str], keep: bool = True) -> dict[str, list[tuple[int, bytes]]]:
    """Per topic, the sorted (receive time, raw bytes) pairs, from the messages our reader hands
    out; when ``keep``, the raw bytes it keeps must be the same."""
    handed: dict[str, list[tuple[int, bytes]]] = {}

    def decoder(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        assert msgtype == TYPES[topic] and definition
        assert times.dtype == np.int64 and len(times) == len(messages)
        raws = [messages.buffer[s:e].tobytes() for s, e in zip(messages.starts, messages.ends, strict=True)]
        handed.setdefault(topic, []).extend(zip(times.tolist(), raws, strict=True))
        return not keep

    found = read_topics(file, topics, decoder)
    assert set(found) == set(handed)
    for topic, messages in found.items():
        assert messages.msgtype == TYPES[topic]
        assert len(messages.times) == len(handed[topic])
        if keep:
            assert sorted(zip(messages.times.tolist(), messages.raws, strict=True)) == sorted(handed[topic])
        else:
            assert messages.raws == []
    return {topic: sorted(pairs) for topic, pairs in handed.items()}


def expected(written: list[Written], topics: set[str]) -> dict[str, list[tuple[int, bytes]]]:
    out: dict[str, list[tuple[int, bytes]]] = {}
    for topic, _, t, raw in written:
        if topic in topics:
            out.setdefault(topic, []).append((t, raw))
    return {topic: sorted(pairs) for topic, pairs in out.items()}


# ------------------------------------------------------------------ MCAP records, for the broken files
def records(blob: bytes) -> list[tuple[int, int, bytes]]:
    """(opcode, where the record starts, its content) of every top-level record."""
    found, pos = [], len(MAGIC)
    while pos < len(blob) - len(MAGIC):
        op, length = struct.unpack_from("<BQ", blob, pos)
        found.append((op, pos, blob[pos + 9 : pos + 9 + length]))
        pos += 9 + length
    return found


def record(op: int, content: bytes) -> bytes:
    return struct.pack("<BQ", op, len(content)) + content


def data_section(blob: bytes) -> bytes:
    """The magic, header and data section, up to the data end record."""
    found = records(blob)
    end = next(i for i, (op, _, _) in enumerate(found) if op == OP_DATA_END)
    return MAGIC + b"".join(record(op, content) for op, _, content in found[: end + 1])


def without_summary(blob: bytes) -> bytes:
    """The file as a recorder writes it without a summary section."""
    return data_section(blob) + record(OP_FOOTER, struct.pack("<QQI", 0, 0, 0)) + MAGIC


def with_summary(blob: bytes, change: Callable[[int, bytes], bytes | None], crc: int | None = 0) -> bytes:
    """The file with each summary record's content changed by ``change`` (None: the record dropped;
    summary offsets are dropped); ``crc`` None: the summary's true CRC."""
    head = data_section(blob)
    changed = [
        (op, change(op, content))
        for op, pos, content in records(blob)
        if pos >= len(head) and op not in (OP_SUMMARY_OFFSET, OP_FOOTER)
    ]
    summary = b"".join(record(op, content) for op, content in changed if content is not None)
    footer_start = struct.pack("<BQQQ", OP_FOOTER, 20, len(head), 0)
    if crc is None:
        crc = zlib.crc32(summary + footer_start)
    return head + summary + footer_start + struct.pack("<I", crc) + MAGIC


def chunk_compression(content: bytes) -> str:
    (size,) = struct.unpack_from("<I", content, 28)
    return content[32 : 32 + size].decode()


# ------------------------------------------------------------------ fixtures
@pytest.fixture(scope="module")
def written() -> list[Written]:
    return recording()


LAYOUTS = {
    # name: (compression, close a chunk every so many messages; None: rosbags' 1 MiB chunks)
    "zstd": ("zstd", None),
    "uncompressed": ("", None),
    "zstd-small-chunks": ("zstd", 7),
    "uncompressed-small-chunks": ("", 5),
    "lz4-small-chunks": ("lz4", 11),
    "lz4": ("lz4", None),
}


@pytest.fixture(scope="module")
def bags(tmp_path_factory: pytest.TempPathFactory, written: list[Written]) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("mcap")
    return {name: write_bag(folder / name, written, *layout) for name, layout in LAYOUTS.items()}


# ------------------------------------------------------------------ reading good bags
@pytest.mark.parametrize("layout", list(LAYOUTS))
def test_reads_what_rosbags_reads(bags: dict[str, Path], written: list[Written], layout: str) -> None:
    bag = bags[layout]
    compression, chunk_every = LAYOUTS[layout]
    chunks = [content for op, _, content in records(mcap_of(bag).read_bytes()) if op == OP_CHUNK]
    assert len(chunks) >= (len(written) // chunk_every if chunk_every else 2)  # many chunks
    assert {chunk_compression(c) for c in chunks} == {compression}
    ours = by_index(mcap_of(bag), WANTED)
    assert set(ours) == WANTED  # /other is not read
    assert ours == by_rosbags(bag, WANTED)
    assert ours == expected(written, WANTED)


def test_messages_handed_and_not_kept(bags: dict[str, Path], written: list[Written]) -> None:
    assert by_index(mcap_of(bags["zstd-small-chunks"]), WANTED, keep=False) == expected(written, WANTED)


def test_channels_of_one_topic_are_merged(bags: dict[str, Path], written: list[Written]) -> None:
    file = mcap_of(bags["uncompressed-small-chunks"])
    with AnyReader([bags["uncompressed-small-chunks"]], default_typestore=STORE) as reader:
        assert len([c for c in reader.connections if c.topic == "/pose"]) == 2
    found = read_topics(file, {"/pose"}, lambda *_: False)
    assert sorted(found["/pose"].times.tolist()) == [t for topic, _, t, _ in written if topic == "/pose"]


def test_definitions_and_schemas_are_the_bags(bags: dict[str, Path]) -> None:
    bag = bags["zstd"]
    seen: dict[str, str] = {}

    def decoder(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        seen[topic] = definition
        return True

    found = read_topics(mcap_of(bag), WANTED, decoder)
    with AnyReader([bag], default_typestore=STORE) as reader:
        theirs = {c.topic: (c.msgtype, c.msgdef.data) for c in reader.connections}
    assert {t: (m.msgtype, m.definition) for t, m in found.items()} == {t: theirs[t] for t in WANTED}
    assert seen == {t: theirs[t][1] for t in WANTED}
    assert {t: (s.name, s.encoding, s.text) for t, s in schemas(mcap_of(bag)).items()} == {
        t: (msgtype, "ros2msg", text) for t, (msgtype, text) in theirs.items()
    }


def test_idl_schemas_say_so(tmp_path: Path) -> None:
    writer = Writer(tmp_path / "idl", version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        conn = writer.add_connection(
            "/reading", "test_msgs/msg/Reading", msgdef=IDL, rihs01="RIHS01_" + "0" * 64
        )
        writer.write(
            conn, START, bytes([0, 1, 0, 0]) + struct.pack("<d", 1.5) + struct.pack("<I", 2) + b"a\x00"
        )
    [schema] = schemas(mcap_of(tmp_path / "idl")).values()
    assert (schema.name, schema.encoding, schema.text) == ("test_msgs/msg/Reading", "ros2idl", IDL)
    data = read_bag(tmp_path / "idl", {"/reading": Wanted("test_msgs/msg/Reading", (path_of("value"),))})
    assert data.series["/reading"].fields["value"].tolist() == [1.5]


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    seed=st.integers(0, 1000),
    count=st.integers(1, 60),
    big=st.sampled_from([0, 50, 3000]),
    layout=st.sampled_from(list(LAYOUTS.values())),
)
def test_any_layout_reads_like_rosbags(tmp_path: Path, seed: int, count: int, big: int, layout: Any) -> None:
    folder = tmp_path / f"bag{seed}_{count}_{big}_{layout[0]}_{layout[1]}"
    recorded = recording(seed, count, big)
    bag = write_bag(folder, recorded, *layout)
    try:
        ours = by_index(mcap_of(bag), WANTED)
        assert ours == by_rosbags(bag, WANTED) == expected(recorded, WANTED)
    finally:
        shutil.rmtree(folder)


# ------------------------------------------------------------------ files it does not read
def test_truncated_copies_raise(tmp_path: Path, bags: dict[str, Path]) -> None:
    """A copy cut short has lost its footer (and its summary): nothing of it is read; rosbags is
    left to say what it can of it."""
    blob = mcap_of(bags["zstd-small-chunks"]).read_bytes()
    kinds = {pos: op for op, pos, _ in records(blob)}
    summary_at = min(pos for pos, op in kinds.items() if op == OP_CHUNK_INDEX)
    chunk_at = min(pos for pos, op in kinds.items() if op == OP_CHUNK)
    cuts = {
        0,
        5,
        8,
        20,
        chunk_at + 30,
        len(blob) // 2,
        summary_at,
        summary_at + 40,
        len(blob) - 37,
        len(blob) - 8,
    }
    cuts |= {len(blob) - 1, len(blob) - 20}
    for cut in sorted(cuts):
        copy = tmp_path / f"cut{cut}.mcap"
        copy.write_bytes(blob[:cut])
        with pytest.raises(UnsupportedBag):
            read_topics(copy, WANTED, lambda *_: True)
        with pytest.raises(UnsupportedBag):
            schemas(copy)


def test_file_without_summary_raises(tmp_path: Path, bags: dict[str, Path]) -> None:
    copy = tmp_path / "nosummary.mcap"
    copy.write_bytes(without_summary(mcap_of(bags["zstd"]).read_bytes()))
    with pytest.raises(UnsupportedBag, match="no summary"):
        read_topics(copy, WANTED, lambda *_: True)


def test_rewritten_summary_reads_the_same(
    tmp_path: Path, bags: dict[str, Path], written: list[Written]
) -> None:
    """The rewriting helper keeps a file readable (so that what the tests below break is what they
    say), and a summary's true CRC is accepted."""
    blob = mcap_of(bags["lz4-small-chunks"]).read_bytes()
    for crc in (0, None):
        copy = tmp_path / f"same{crc}.mcap"
        copy.write_bytes(with_summary(blob, lambda op, content: content, crc=crc))
        assert by_index(copy, WANTED) == expected(written, WANTED)


def _no_message_indexes(op: int, content: bytes) -> bytes:
    if op != OP_CHUNK_INDEX:
        return content
    (size,) = struct.unpack_from("<I", content, 32)
    return content[:32] + struct.pack("<IQ", 0, 0) + content[32 + 4 + size + 8 :]


def _chunk_far_away(op: int, content: bytes) -> bytes:
    if op != OP_CHUNK_INDEX:
        return content
    return content[:16] + struct.pack("<Q", 1 << 40) + content[24:]


def _chunk_shifted(op: int, content: bytes) -> bytes:
    if op != OP_CHUNK_INDEX:
        return content
    (start,) = struct.unpack_from("<Q", content, 16)
    return content[:16] + struct.pack("<Q", start + 3) + content[24:]


def _one_message_more(op: int, content: bytes) -> bytes:
    if op != OP_STATISTICS:
        return content
    at = 8 + 2 + 4 * 4 + 8 * 2 + 4  # the counts, times, then the first (channel, count) of the map
    (count,) = struct.unpack_from("<Q", content, at + 2)
    return content[: at + 2] + struct.pack("<Q", count + 1) + content[at + 10 :]


def _no_channels(op: int, content: bytes) -> bytes | None:
    return None if op == OP_CHANNEL else content


def _unknown_compression_in_index(op: int, content: bytes) -> bytes:
    """The chunk indexes' compression is not what is read: the chunk's own is."""
    if op != OP_CHUNK_INDEX:
        return content
    (size,) = struct.unpack_from("<I", content, 32)
    at = 32 + 4 + size + 8
    (name,) = struct.unpack_from("<I", content, at)
    return content[:at] + struct.pack("<I", 3) + b"xyz" + content[at + 4 + name :]


@pytest.mark.parametrize(
    "change, match",
    [
        (_no_message_indexes, "no message indexes"),
        (_chunk_far_away, "outside the file"),
        (_chunk_shifted, "expected"),
        (_one_message_more, "statistics"),
        (_no_channels, "which the summary lacks"),
    ],
    ids=[
        "no-message-indexes",
        "chunk-outside-file",
        "chunk-index-misplaced",
        "statistics-disagree",
        "no-channels",
    ],
)
def test_broken_summaries_raise(
    tmp_path: Path, bags: dict[str, Path], change: Callable[[int, bytes], bytes | None], match: str
) -> None:
    copy = tmp_path / "broken.mcap"
    copy.write_bytes(with_summary(mcap_of(bags["uncompressed-small-chunks"]).read_bytes(), change))
    with pytest.raises(UnsupportedBag, match=match):
        read_topics(copy, WANTED, lambda *_: True)


def _schema_encoding_unknown(op: int, content: bytes) -> bytes:
    """rosbag2's schema for a type whose definition it lacks: no text, encoding 'unknown'."""
    if op != OP_SCHEMA:
        return content
    (size,) = struct.unpack_from("<I", content, 2)
    name = content[2 : 2 + 4 + size]
    return content[:2] + name + struct.pack("<I", 7) + b"unknown" + struct.pack("<I", 0)


def _statistics_without_channel_counts(op: int, content: bytes) -> bytes:
    return content[:42] + struct.pack("<I", 0) if op == OP_STATISTICS else content


@pytest.mark.parametrize(
    "change", [_unknown_compression_in_index, _statistics_without_channel_counts, _schema_encoding_unknown]
)
def test_summaries_read_the_same(
    tmp_path: Path, bags: dict[str, Path], written: list[Written], change: Callable[[int, bytes], bytes]
) -> None:
    """What the reader does not need of the summary may differ."""
    copy = tmp_path / "changed.mcap"
    copy.write_bytes(with_summary(mcap_of(bags["zstd-small-chunks"]).read_bytes(), change))
    handed: dict[str, list[tuple[int, bytes]]] = {}

    def decoder(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        raws = [messages.buffer[s:e].tobytes() for s, e in zip(messages.starts, messages.ends, strict=True)]
        handed.setdefault(topic, []).extend(zip(times.tolist(), raws, strict=True))
        return True

    read_topics(copy, WANTED, decoder)
    assert {topic: sorted(pairs) for topic, pairs in handed.items()} == expected(written, WANTED)


def test_damaged_summary_crc_raises(tmp_path: Path, bags: dict[str, Path]) -> None:
    copy = tmp_path / "crc.mcap"
    copy.write_bytes(with_summary(mcap_of(bags["zstd"]).read_bytes(), lambda op, content: content, crc=12345))
    with pytest.raises(UnsupportedBag, match="CRC"):
        read_topics(copy, WANTED, lambda *_: True)


def _first_message_index(blob: bytearray) -> int:
    """Where the content of the first message index record is."""
    return next(pos + 9 for op, pos, _ in records(bytes(blob)) if op == OP_MESSAGE_INDEX)


def _entry_offset_far(blob: bytearray) -> None:
    at = _first_message_index(blob) + 6 + 8  # the first entry's offset
    blob[at : at + 8] = struct.pack("<Q", 1 << 62)


def _entry_offset_off_by_one(blob: bytearray) -> None:
    at = _first_message_index(blob) + 6 + 8
    (offset,) = struct.unpack_from("<Q", blob, at)
    blob[at : at + 8] = struct.pack("<Q", offset + 1)


def _entry_time_changed(blob: bytearray) -> None:
    at = _first_message_index(blob) + 6
    blob[at : at + 8] = struct.pack("<Q", 7)


def _index_length_huge(blob: bytearray) -> None:
    at = _first_message_index(blob) + 2
    blob[at : at + 4] = struct.pack("<I", 0xFFFFFFF0)


def _message_length_huge(blob: bytearray) -> None:
    at = _first_message_index(blob) + 6 + 8
    (offset,) = struct.unpack_from("<Q", blob, at)
    chunk = max(pos for op, pos, _ in records(bytes(blob)) if op == OP_CHUNK and pos < at)
    (name_size,) = struct.unpack_from("<I", blob, chunk + 9 + 28)
    message = chunk + 9 + 32 + name_size + 8 + offset
    blob[message + 1 : message + 9] = struct.pack("<Q", 1 << 50)


def _compression_unknown(blob: bytearray) -> None:
    chunk = next(pos for op, pos, _ in records(bytes(blob)) if op == OP_CHUNK)
    blob[chunk + 9 + 32 : chunk + 9 + 36] = b"zstX"


def _zstd_damaged(blob: bytearray) -> None:
    chunk = next(pos for op, pos, _ in records(bytes(blob)) if op == OP_CHUNK)
    frame = chunk + 9 + 32 + 4 + 8
    blob[frame : frame + 4] = b"\0\0\0\0"  # the zstd frame's magic


@pytest.mark.parametrize(
    "layout, damage, match",
    [
        ("uncompressed-small-chunks", _entry_offset_far, "points outside its chunk"),
        ("uncompressed-small-chunks", _entry_offset_off_by_one, "does not point at its message"),
        ("uncompressed-small-chunks", _entry_time_changed, "does not point at its message"),
        ("uncompressed-small-chunks", _index_length_huge, "runs past its record"),
        ("uncompressed-small-chunks", _message_length_huge, "length that does not fit"),
        ("zstd-small-chunks", _compression_unknown, "compression 'zstX'"),
        ("zstd-small-chunks", _zstd_damaged, "does not decompress"),
        ("lz4-small-chunks", _entry_offset_off_by_one, "does not point at its message"),
    ],
    ids=lambda x: x.__name__.strip("_") if callable(x) else x,
)
def test_records_that_do_not_fit_raise(
    tmp_path: Path, bags: dict[str, Path], layout: str, damage: Callable[[bytearray], None], match: str
) -> None:
    """The summary is intact, a record it points to is not: never an IndexError or struct.error."""
    blob = bytearray(mcap_of(bags[layout]).read_bytes())
    damage(blob)
    copy = tmp_path / "damaged.mcap"
    copy.write_bytes(bytes(blob))
    with pytest.raises(UnsupportedBag, match=match):
        read_topics(copy, WANTED | {"/other"}, lambda *_: True)


def test_empty_and_foreign_files_raise(tmp_path: Path) -> None:
    for name, content in {"empty": b"", "short": MAGIC, "foreign": b"#ROSBAG V2.0\n" + bytes(100)}.items():
        (tmp_path / f"{name}.mcap").write_bytes(content)
        with pytest.raises(UnsupportedBag):
            read_topics(tmp_path / f"{name}.mcap", WANTED, lambda *_: True)


def test_topic_with_channels_of_two_types_raises(tmp_path: Path) -> None:
    writer = Writer(tmp_path / "two", version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        a = writer.add_connection("/mixed", "std_msgs/msg/String", typestore=STORE)
        b = writer.add_connection("/mixed", "std_msgs/msg/Int32", typestore=STORE)
        c = writer.add_connection("/fine", "std_msgs/msg/String", typestore=STORE)
        writer.write(a, START, _string("a"))
        writer.write(
            b, START + 1, bytes(STORE.serialize_cdr(T["std_msgs/msg/Int32"](data=1), "std_msgs/msg/Int32"))
        )
        writer.write(c, START + 2, _string("c"))
    with pytest.raises(UnsupportedBag, match="different types"):
        read_topics(mcap_of(tmp_path / "two"), {"/mixed"}, lambda *_: True)
    assert len(read_topics(mcap_of(tmp_path / "two"), {"/fine"}, lambda *_: True)["/fine"].times) == 1


def test_channel_not_in_cdr_raises(tmp_path: Path) -> None:
    writer = Writer(tmp_path / "json", version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        conn = writer.add_connection(
            "/json", "std_msgs/msg/String", typestore=STORE, serialization_format="json"
        )
        writer.write(conn, START, b'{"data": "a"}')
    with pytest.raises(UnsupportedBag, match="CDR"):
        read_topics(mcap_of(tmp_path / "json"), {"/json"}, lambda *_: True)


# ------------------------------------------------------------------ the map always closes
@pytest.mark.parametrize("layout", ["uncompressed-small-chunks", "zstd", "lz4-small-chunks"])
def test_decoder_error_is_not_hidden_by_buffer_error(bags: dict[str, Path], layout: str) -> None:
    """The ROS 1 index reader's bug: an error while a view of the map existed became ``BufferError: cannot close
    exported pointers exist``.  Here the decoder's own error comes out, whatever the chunks."""
    calls = []

    def failing(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        calls.append(topic)
        if len(calls) == 3:
            raise RuntimeError("the decoder's own error")
        return True

    with pytest.raises(RuntimeError, match="own error"):
        read_topics(mcap_of(bags[layout]), WANTED, failing)


@pytest.mark.parametrize("layout", ["uncompressed-small-chunks", "uncompressed", "zstd"])
def test_decoder_may_keep_what_it_is_handed(
    bags: dict[str, Path], written: list[Written], layout: str
) -> None:
    """Buffers kept past reading are the decoder's own (no view of the closed map)."""
    kept: list[tuple[np.ndarray, RawMessages]] = []

    def keeping(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        kept.append((times, messages))
        return True

    read_topics(mcap_of(bags[layout]), {"/chatter"}, keeping)
    pairs = sorted(
        (t, msgs.buffer[s:e].tobytes())
        for times, msgs in kept
        for t, s, e in zip(times.tolist(), msgs.starts.tolist(), msgs.ends.tolist(), strict=True)
    )
    assert pairs == expected(written, {"/chatter"})["/chatter"]


# ------------------------------------------------------------------ the fast path, through read_bag
ODOM_PATHS = (path_of("pose", "pose", "position", "x"), path_of("twist", "twist", "angular", "z"))


def _same_data(a: bagdata.BagData, b: bagdata.BagData) -> None:
    assert a.series.keys() == b.series.keys()
    for topic, series in a.series.items():
        other = b.series[topic]
        assert series.msgtype == other.msgtype
        assert np.array_equal(series.t, other.t)
        assert series.fields.keys() == other.fields.keys()
        for key, values in series.fields.items():
            assert np.array_equal(values, other.fields[key], equal_nan=True), (topic, key)
    assert _statuses(a) == _statuses(b)
    assert a.problems == b.problems


def _statuses(data: bagdata.BagData) -> dict[str, list[tuple[float, list[tuple[str, int]]]]]:
    """The dispatcher's statuses of each topic kept as message objects, with their times."""
    return {
        topic: [(t, [(s.goal_id.id, s.status) for s in m.feedback.goal_status.status_list]) for t, m in found]
        for topic, found in data.messages.items()
    }


def _dispatcher_bag(tmp_path: Path, written: list[Written]) -> tuple[Path, dict[str, Wanted]]:
    """The recording with the dispatcher's feedback (kept as message objects) on its own topic."""
    store = sim_typestore("mcap")
    types = store.types
    path = tmp_path / "dispatcher"
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    with writer:
        conns: dict[str, Any] = {}
        feedback = writer.add_connection("/wd/feedback", FEEDBACK, typestore=store)
        for i, (topic, _, t, raw) in enumerate(written):
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, TYPES[topic], typestore=STORE)
            writer.write(conns[topic], t, raw)
            if i % 50 == 0:
                status = types["actionlib_msgs/msg/GoalStatus"](
                    goal_id=types["actionlib_msgs/msg/GoalID"](
                        stamp=types["builtin_interfaces/msg/Time"](sec=1, nanosec=0), id=f"wp{i}"
                    ),
                    status=1,
                    text="",
                )
                array = types["actionlib_msgs/msg/GoalStatusArray"](
                    header=_header(t, "map"), status_list=[status]
                )
                msg = types[FEEDBACK](
                    header=_header(t, "map"),
                    status=status,
                    feedback=types["waypoint_dispatcher/msg/FollowWaypointsFeedback"](goal_status=array),
                )
                writer.write(feedback, t, bytes(store.serialize_cdr(msg, FEEDBACK)))
    wanted = {
        "/odom": Wanted("nav_msgs/msg/Odometry", ODOM_PATHS),
        "/pose": Wanted("geometry_msgs/msg/PoseStamped", (path_of("pose", "position", "x"),)),
        "/late": Wanted("nav_msgs/msg/Odometry", ODOM_PATHS),  # the wrong type: a problem
        "/wd/feedback": Wanted(OBJECTS),
    }
    return path, wanted


def test_read_bag_reads_what_rosbags_reads(tmp_path: Path, written: list[Written]) -> None:
    bag, wanted = _dispatcher_bag(tmp_path, written)
    ours = read_bag(bag, wanted)
    theirs = read_with_rosbags(bag, wanted, None, None)
    _same_data(ours, theirs)
    assert len(ours.series["/odom"]) == len([w for w in written if w[0] == "/odom"])
    assert len(ours.messages["/wd/feedback"]) == (len(written) + 49) // 50
    assert len(ours.problems) == 1 and "/late" in ours.problems[0]  # of the wrong type
    _same_data(read_bag(mcap_of(bag), wanted), theirs)  # the .mcap file itself


def test_read_bag_falls_back_to_rosbags(tmp_path: Path, written: list[Written]) -> None:
    bag, wanted = _dispatcher_bag(tmp_path, written)
    good = read_bag(bag, wanted)
    file = mcap_of(bag)
    file.write_bytes(without_summary(file.read_bytes()))
    _same_data(read_bag(bag, wanted), good)


def test_read_bag_without_definitions_in_the_bag(tmp_path: Path, written: list[Written]) -> None:
    """A schema without text (rosbag2's, when it lacks the definition): the standard one is used."""
    bag = write_bag(tmp_path / "bag", written)
    wanted = {"/odom": Wanted("nav_msgs/msg/Odometry", ODOM_PATHS)}
    good = read_bag(bag, wanted)
    mcap_of(bag).write_bytes(with_summary(mcap_of(bag).read_bytes(), _schema_encoding_unknown))
    assert {s.encoding for s in schemas(mcap_of(bag)).values()} == {"unknown"}
    _same_data(read_bag(bag, wanted), good)
    assert len(good.series["/odom"]) == len([w for w in written if w[0] == "/odom"])


def _metadata(folder: Path, **changes: Any) -> None:
    path = folder / "metadata.yaml"
    meta = yaml.safe_load(path.read_text())
    meta["rosbag2_bagfile_information"].update(changes)
    path.write_text(yaml.safe_dump(meta))


def test_mcap_files(tmp_path: Path, written: list[Written]) -> None:
    bag = write_bag(tmp_path / "bag", written[:20])
    assert mcap_files(bag) == [mcap_of(bag)]
    assert mcap_files(mcap_of(bag)) == [mcap_of(bag)]
    for changes in (
        {"compression_mode": "MESSAGE"},
        {"compression_mode": "file"},
        {"storage_identifier": "sqlite3"},
    ):
        _metadata(bag, compression_mode="", storage_identifier="mcap")
        _metadata(bag, **changes)
        assert mcap_files(bag) is None
    (bag / "metadata.yaml").write_text("not: [yaml")
    assert mcap_files(bag) is None
    assert mcap_files(tmp_path) is None
