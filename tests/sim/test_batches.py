"""A batch of messages serialized from one template gives, message by message, the bytes rosbags
writes for each message built and serialized on its own (the reference), in ROS 1 and CDR."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from exsce_dsl.sim.batches import Batch, stamp_columns
from exsce_dsl.sim.messages import navigation_typestore

FORMATS = ["ros1", "ros2"]


def _reference(batch: Batch, store: Any, serialize: Any) -> list[bytes]:
    found = []
    for i in range(len(batch)):
        values = {
            slot: column[i] if column.ndim > 1 else column[i].item() for slot, column in batch.columns.items()
        }
        found.append(bytes(serialize(batch.build(**values), batch.msgtype)))
    return found


def _serializer(store: Any, fmt: str) -> Any:
    return store.serialize_ros1 if fmt == "ros1" else store.serialize_cdr


def _header(store: Any, sec: int, nanosec: int, frame: str, seq: int) -> Any:
    T = store.types
    stamp = T["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)
    if "seq" in T["std_msgs/msg/Header"].__dataclass_fields__:
        return T["std_msgs/msg/Header"](seq=seq, stamp=stamp, frame_id=frame)
    return T["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)


def _stamps(count: int, rng: np.random.Generator) -> np.ndarray:
    return np.sort(rng.integers(1_700_000_000 * 10**9, 1_800_000_000 * 10**9, count))


@pytest.mark.parametrize("fmt", FORMATS)
def test_transforms_sharing_one_stamp_come_out_as_rosbags_writes_them(fmt: str) -> None:
    store = navigation_typestore(fmt)
    T = store.types
    rng = np.random.default_rng(1)
    stamps = _stamps(500, rng)
    angles = rng.uniform(-math.pi, math.pi, 500)

    def wheels(sec: int, nanosec: int, seq: int, qy: float, qw: float) -> Any:
        transforms = [
            T["geometry_msgs/msg/TransformStamped"](
                header=_header(store, sec, nanosec, "base_link", seq),
                child_frame_id=child,
                transform=T["geometry_msgs/msg/Transform"](
                    translation=T["geometry_msgs/msg/Vector3"](x=0.0, y=side, z=0.0),
                    rotation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=qy, z=0.0, w=qw),
                ),
            )
            for child, side in (("left", 0.2), ("right", -0.2), ("caster", 0.0))
        ]
        return T["tf2_msgs/msg/TFMessage"](transforms=transforms)

    columns = {
        **stamp_columns(stamps),
        "seq": np.arange(500).astype("<u4"),
        "qy": np.sin(angles / 2),
        "qw": np.cos(angles / 2),
    }
    batch = Batch("/tf", "tf2_msgs/msg/TFMessage", stamps, wheels, columns)
    serialize = _serializer(store, fmt)
    assert batch.serialized(serialize) == _reference(batch, store, serialize)


@pytest.mark.parametrize("fmt", FORMATS)
def test_scans_with_their_ranges_come_out_as_rosbags_writes_them(fmt: str) -> None:
    store = navigation_typestore(fmt)
    T = store.types
    rng = np.random.default_rng(2)
    stamps = _stamps(40, rng)
    ranges = rng.uniform(0.05, 10.0, (40, 720)).astype("<f4")
    ranges[3, 100:200] = np.inf

    def scan(sec: int, nanosec: int, seq: int, ranges: np.ndarray) -> Any:
        return T["sensor_msgs/msg/LaserScan"](
            header=_header(store, sec, nanosec, "laser", seq),
            angle_min=-2.0, angle_max=2.0, angle_increment=4.0 / 719, time_increment=0.0, scan_time=0.1,
            range_min=0.05, range_max=10.0, ranges=ranges, intensities=np.zeros(0, dtype=np.float32),
        )  # fmt: skip

    columns = {**stamp_columns(stamps), "seq": np.arange(40).astype("<u4"), "ranges": ranges}
    batch = Batch("/scan", "sensor_msgs/msg/LaserScan", stamps, scan, columns)
    serialize = _serializer(store, fmt)
    assert batch.serialized(serialize) == _reference(batch, store, serialize)


def test_a_message_that_is_not_its_slots_as_given_is_serialized_one_by_one() -> None:
    """A builder that computes with a slot (here: doubles it) cannot be templated: the batch
    notices and serializes each message itself, so the bytes are still right."""
    store = navigation_typestore("ros2")
    T = store.types
    data = np.linspace(0.0, 5.0, 30)
    batch = Batch(
        "/d", "std_msgs/msg/Float64", np.arange(30), lambda data: T["std_msgs/msg/Float64"](data=2 * data + 1),
        {"data": data},
    )  # fmt: skip
    assert batch.serialized(store.serialize_cdr) == _reference(batch, store, store.serialize_cdr)
    assert (
        Batch("/d", "std_msgs/msg/Float64", np.arange(0), batch.build, {"data": data[:0]}).serialized(
            store.serialize_cdr
        )
        == []
    )
