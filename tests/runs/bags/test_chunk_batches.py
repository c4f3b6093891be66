"""The ROS 1 and MCAP index readers hand the decoder several chunks' messages at once (BATCH_BYTES).

A bag of many small chunks, plain and compressed, is read with a small batch size, so that a batch
joins several chunks and there are several batches.  What the decoder is given must be what rosbags
reads: the same messages, in bag order, with the same bytes, whether it decodes them or keeps them.
"""

from __future__ import annotations

import gc
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.messages.catalogue import standard_catalogue, standard_ros1_catalogue
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bags import chunk_batches, mcap_index, ros1
from exsce_dsl.runs.bags.buffers import mapped
from exsce_dsl.runs.bags.decode import decode
from exsce_dsl.runs.bags.raw_messages import RawMessages

from tests.support import bag_factory as factory


def _bag(tmp_path: Path, fmt: str) -> factory.WrittenBag:
    store = factory.typestore_for(fmt)
    # frame ids of different lengths: the odometry messages differ in size
    odometry = [
        (t, factory.odometry(store, i, t, frame_id="odom" + "_x" * (i % 4)))
        for i, (t, _) in enumerate(factory.series(store, factory.ODOMETRY, 120))
    ]
    tf = factory.series(store, factory.TF_MESSAGE, 90, period_ns=70_000_000)
    topics = [
        factory.Topic("/odom", factory.ODOMETRY, odometry),
        factory.Topic("/tf", factory.TF_MESSAGE, tf),
    ]
    name = "many_chunks.bag" if fmt.startswith("ros1") else "many_chunks"
    return factory.write_bag(tmp_path / name, fmt, topics, store, chunk_bytes=2_000)


def _chunks(path: Path, is_ros1: bool) -> int:
    """How many chunks the bag has, counted from its chunk records (op 0x05 in ROS 1, 0x06 in MCAP)."""
    if is_ros1:
        with mapped(path) as data:
            _, pos, count = ros1._connections(data, None)
        return count
    [file] = path.glob("*.mcap")
    with mapped(file) as data:
        return len(mcap_index._summary(data).chunks)


@pytest.mark.parametrize("fmt", ["ros1", "ros1-bz2", "ros1-lz4", "mcap", "mcap-zstd"])
def test_batches_of_chunks_give_the_messages_rosbags_reads(
    tmp_path: Path, fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    written = _bag(tmp_path, fmt)
    is_ros1 = fmt.startswith("ros1")
    monkeypatch.setattr(chunk_batches, "BATCH_BYTES", 10_000)
    x = path_of("pose", "pose", "position", "x")
    calls: list[tuple[str, int]] = []
    decoded: list[np.ndarray] = []

    def decoder(
        topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages, publisher: str
    ) -> bool:
        calls.append((topic, len(messages)))
        if topic == "/tf":
            return False  # keep the raw bytes
        catalogue = standard_ros1_catalogue() if is_ros1 else standard_catalogue()
        out = decode(catalogue, msgtype, messages, [x], cdr=not is_ros1)
        decoded.append(out[x.key])
        return True

    reader = ros1 if is_ros1 else mcap_index
    path = written.path if is_ros1 else next(written.path.glob("*.mcap"))
    found = reader.read_topics(path, {"/odom", "/tf"}, decoder)

    chunks = _chunks(written.path, is_ros1)
    odom_calls = [n for topic, n in calls if topic == "/odom"]
    assert 1 < len(odom_calls) < chunks  # several batches, each joining several chunks
    expected: dict[str, list[tuple[int, Any, bytes]]] = {"/odom": [], "/tf": []}
    with AnyReader([written.path]) as reader:
        for conn, t, raw in reader.messages():
            expected[conn.topic].append((t, reader.deserialize(raw, conn.msgtype), raw))
    odom = expected["/odom"]
    assert found["/odom"].times.tolist() == [t for t, _, _ in odom]
    assert np.concatenate(decoded).tolist() == [m.pose.pose.position.x for _, m, _ in odom]
    assert found["/tf"].times.tolist() == [t for t, _, _ in expected["/tf"]]
    assert found["/tf"].raws == [raw for _, _, raw in expected["/tf"]]


def test_a_view_of_the_map_left_in_a_cycle_does_not_fail_a_read_that_succeeded(tmp_path: Path) -> None:
    # a Dask worker collects cycles rarely: a numpy view caught in one outlives the reading
    path = tmp_path / "some.bag"
    path.write_bytes(b"#ROSBAG V2.0\n" + bytes(4096))
    cycle: list[object] = []
    with mapped(path) as data:
        cycle.extend([np.frombuffer(data, dtype=np.uint8, count=16), cycle])
        first = bytes(data[:13])
    assert first == b"#ROSBAG V2.0\n"  # and leaving the block raised nothing
    gc.disable()
    try:
        with mapped(path) as data:
            kept = np.frombuffer(data, dtype=np.uint8, count=16)  # alive after the block: still no error
        assert kept[:8].tobytes() == b"#ROSBAG "
    finally:
        gc.enable()
