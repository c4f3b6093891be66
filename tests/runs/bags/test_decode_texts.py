"""Texts the decoder reads for ingestion itself (TF frame ids): codes into a table of strings.

Reference values are rosbags' own deserialisation of the same bytes.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from exsce_dsl.errors import DecodeError
from exsce_dsl.messages.catalogue import standard_catalogue, standard_ros1_catalogue
from exsce_dsl.model.messages import FieldPath, Index, path_of
from exsce_dsl.runs.bags.data import Wanted
from exsce_dsl.runs.bags.decode import TEXTS, decode, decode_slowly
from exsce_dsl.runs.bags.raw_messages import RawMessages
from exsce_dsl.runs.bags.reading import read_bag

from tests.support import bag_factory as factory

TF = "tf2_msgs/msg/TFMessage"
FRAMES = [("map", "odom"), ("odom", "base_link"), ("base_link", "laser"), ("odom", "base_füßprint")]
TEXT_PATHS = [
    path_of("transforms", "header", "frame_id"),
    path_of("transforms", "child_frame_id"),
    FieldPath(("transforms", Index(-1), "child_frame_id")),
]


def _store(fmt: str) -> Any:
    if fmt != "ros1":
        return get_typestore(Stores.ROS2_HUMBLE)
    store = get_typestore(Stores.ROS1_NOETIC)  # which lacks tf2_msgs: its definition, as a ROS 1 bag has it
    store.register(get_types_from_msg("geometry_msgs/TransformStamped[] transforms", TF))
    return store


def _messages(fmt: str) -> tuple[list[bytes], list[Any]]:
    """TF messages of 0 to 4 transforms, frames of different lengths (one not ASCII)."""
    store = _store(fmt)
    t = store.types
    tf2 = "tf2_msgs/msg/TFMessage"
    raws = []
    rng = np.random.default_rng(3)
    for i in range(40):
        chosen = [FRAMES[j] for j in rng.permutation(len(FRAMES))[: i % 5]]
        transforms = []
        for parent, child in chosen:
            stamp = t["builtin_interfaces/msg/Time"](sec=i, nanosec=7)
            header = (
                t["std_msgs/msg/Header"](seq=i, stamp=stamp, frame_id=parent)
                if fmt == "ros1"
                else t["std_msgs/msg/Header"](stamp=stamp, frame_id=parent)
            )
            transform = t["geometry_msgs/msg/Transform"](
                translation=t["geometry_msgs/msg/Vector3"](x=float(i), y=0.0, z=0.0),
                rotation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0),
            )
            transforms.append(t["geometry_msgs/msg/TransformStamped"](header, child, transform))
        message = t[tf2](transforms=transforms)
        if fmt == "ros1":
            raws.append(bytes(store.serialize_ros1(message, tf2)))
        else:
            raw = bytearray(store.serialize_cdr(message, tf2, little_endian=fmt == "cdr"))
            raws.append(bytes(raw))
    deserialise = _deserialiser(fmt)
    return raws, [deserialise(r) for r in raws]


def _deserialiser(fmt: str) -> Any:
    store = _store(fmt)
    if fmt == "ros1":
        return lambda raw: store.deserialize_ros1(raw, TF)
    return lambda raw: store.deserialize_cdr(raw, TF)


def _texts(out: dict[str, np.ndarray], key: str) -> list[Any]:
    """The strings the codes under ``key`` stand for (None for NaN), per message."""
    table = out[TEXTS]

    def text(code: float) -> str | None:
        return None if math.isnan(code) else str(table[int(code)])

    values = out[key]
    if values.ndim == 1:
        return [text(c) for c in values]
    return [[text(c) for c in row] for row in values]


def _expected(messages: list[Any]) -> dict[str, list[Any]]:
    width = max(len(m.transforms) for m in messages)

    def padded(values: list[str]) -> list[str | None]:
        return values + [None] * (width - len(values))

    return {
        "transforms.header.frame_id": [padded([x.header.frame_id for x in m.transforms]) for m in messages],
        "transforms.child_frame_id": [padded([x.child_frame_id for x in m.transforms]) for m in messages],
        "transforms[-1].child_frame_id": [
            m.transforms[-1].child_frame_id if m.transforms else None for m in messages
        ],
    }


@pytest.mark.parametrize("fmt", ["ros1", "cdr", "cdr_be"])
def test_frame_ids_come_back_as_codes_of_the_strings_rosbags_reads(fmt: str) -> None:
    raws, messages = _messages(fmt)
    catalogue = standard_ros1_catalogue() if fmt == "ros1" else standard_catalogue()
    out = decode(catalogue, TF, RawMessages.join(raws), [], cdr=fmt != "ros1", texts=TEXT_PATHS)
    assert {k: _texts(out, k) for k in _expected(messages)} == _expected(messages)
    assert sorted(out[TEXTS]) == sorted({f for pair in FRAMES for f in pair})  # each text once
    assert out["transforms[-1].child_frame_id#present"].tolist() == [bool(m.transforms) for m in messages]


@pytest.mark.parametrize("fmt", ["ros1", "cdr"])
def test_texts_beside_numbers_and_the_slow_path_agree(fmt: str) -> None:
    raws, messages = _messages(fmt)
    catalogue = standard_ros1_catalogue() if fmt == "ros1" else standard_catalogue()
    numbers = [path_of("transforms", "transform", "translation", "x")]
    fast = decode(catalogue, TF, RawMessages.join(raws), numbers, cdr=fmt != "ros1", texts=TEXT_PATHS)
    slow = decode_slowly(_deserialiser(fmt), raws, numbers, texts=TEXT_PATHS)
    for key in _expected(messages):
        assert _texts(fast, key) == _texts(slow, key)
    np.testing.assert_array_equal(
        fast["transforms.transform.translation.x"], slow["transforms.transform.translation.x"]
    )


@pytest.mark.parametrize(
    "path, said",
    [
        (path_of("transforms", "transform", "translation", "x"), "not a text"),
        (path_of("transforms"), "not a text"),
        (path_of("transforms", "child_frame"), "has no field 'child_frame'"),
    ],
)
def test_a_text_path_to_something_else_is_a_decode_error(path: FieldPath, said: str) -> None:
    raws, _ = _messages("cdr")
    with pytest.raises(DecodeError, match=said):
        decode(standard_catalogue(), TF, RawMessages.join(raws), [], cdr=True, texts=[path])


def test_a_text_is_not_a_number_path() -> None:
    raws, _ = _messages("cdr")
    with pytest.raises(DecodeError, match="is text, not a number"):
        decode(
            standard_catalogue(),
            TF,
            RawMessages.join(raws),
            [path_of("transforms", "child_frame_id")],
            cdr=True,
        )


@pytest.mark.parametrize("fmt", ["ros1-lz4", "sqlite3", "mcap"])
def test_a_bag_of_many_chunks_gives_one_table_of_texts(tmp_path: Path, fmt: str) -> None:
    """Each chunk is decoded apart, with its own codes; read_bag recodes them into the topic's
    table, so that a code means the same frame in every message (checked against rosbags)."""
    store = factory.typestore_for(fmt)
    messages = factory.series(store, factory.TF_MESSAGE, 60)
    written = factory.write_bag(
        tmp_path / ("tf.bag" if fmt.startswith("ros1") else "tf"),
        fmt,
        [factory.Topic("/tf", factory.TF_MESSAGE, messages)],
        store,
        chunk_bytes=600,
    )
    wanted = {"/tf": Wanted(factory.TF_MESSAGE, (), tuple(TEXT_PATHS[:2]))}
    series = read_bag(written.path, wanted).series["/tf"]
    objects = [m for _, m in messages]
    for key in ("transforms.header.frame_id", "transforms.child_frame_id"):
        assert _texts(series.fields, key) == _expected(objects)[key]
    assert len(series.fields[TEXTS]) == 4  # map, odom, base_link, base_laser_link: each once
