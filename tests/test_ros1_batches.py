"""The ROS 1 index reader hands the decoder several chunks' messages at once (ros1_index.BATCH_BYTES).

A bag of many small chunks, plain and compressed, is read with a small batch size, so that a batch
joins several chunks and there are several batches.  What the decoder is given must be what rosbags
reads: the same messages, in bag order, with the same bytes, whether it decodes them or keeps them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import bag_factory as factory
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader

from exsce_dsl.messages.catalogue import standard_ros1_catalogue
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs import ros1_index
from exsce_dsl.runs.decode import RawMessages, decode


def _bag(tmp_path: Path, fmt: str) -> factory.WrittenBag:
    store = factory.typestore_for(fmt)
    # frame ids of different lengths: the odometry messages differ in size
    odometry = [
        (t, factory.odometry(store, i, t, frame_id="odom" + "_x" * (i % 4)))
        for i, (t, _) in enumerate(factory.series(store, factory.ODOMETRY, 120))
    ]
    tf = factory.series(store, factory.TF_MESSAGE, 90, period_ns=70_000_000)
    topics = [factory.Topic("/odom", factory.ODOMETRY, odometry), factory.Topic("/tf", factory.TF_MESSAGE, tf)]
    return factory.write_bag(tmp_path / "many_chunks.bag", fmt, topics, store, chunk_bytes=2_000)


@pytest.mark.parametrize("fmt", ["ros1", "ros1-bz2", "ros1-lz4"])
def test_batches_of_chunks_give_the_messages_rosbags_reads(
    tmp_path: Path, fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    written = _bag(tmp_path, fmt)
    monkeypatch.setattr(ros1_index, "BATCH_BYTES", 10_000)
    x = path_of("pose", "pose", "position", "x")
    calls: list[tuple[str, int]] = []
    decoded: list[np.ndarray] = []

    def decoder(topic: str, msgtype: str, definition: str, times: np.ndarray, messages: RawMessages) -> bool:
        calls.append((topic, len(messages)))
        if topic == "/tf":
            return False  # keep the raw bytes
        out = decode(standard_ros1_catalogue(), msgtype, messages, [x], cdr=False)
        decoded.append(out[x.key])
        return True

    found = ros1_index.read_topics(written.path, {"/odom", "/tf"}, decoder)

    with Reader(written.path) as plain:
        chunks = len(plain.chunk_infos)  # type: ignore[attr-defined]
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
