"""Write an execution as a real bag (ROS 1, ROS 2 sqlite3 or MCAP) with rosbags.

Which topics a robot gets is its convention's business (:mod:`exsce_dsl.sim.conventions`);
this module only collects every robot's messages, orders them in time and writes them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag1 import Writer as Ros1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Ros2Writer

from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.messages.navigation import ros2_message_definition
from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Signals
from exsce_dsl.sim.batches import Batch
from exsce_dsl.sim.conventions import convention_writer
from exsce_dsl.sim.executor import SimulatedExecution
from exsce_dsl.sim.laser import Laser
from exsce_dsl.sim.writing import RobotRun

_FOREVER = QosTime(9223372036, 854775807)
LATCHED_QOS = Qos(
    history=QosHistory.UNKNOWN,
    depth=0,
    reliability=QosReliability.RELIABLE,
    durability=QosDurability.TRANSIENT_LOCAL,
    deadline=_FOREVER,
    lifespan=_FOREVER,
    liveliness=QosLiveliness.AUTOMATIC,
    liveliness_lease_duration=_FOREVER,
    avoid_ros_namespace_conventions=False,
)
"""The offered QoS rosbag2 records for a latched topic (``tf_static``, an action's status)."""


def write_bag(
    path: Path,
    fmt: str,
    scenario: Scenario,
    execution: SimulatedExecution,
    grid: PlanningGrid,
    start_ns: int,
    seed: int,
    laser: Laser | None = None,
    convention: Signals | str = "method",
    twist_stamped: bool = False,
) -> int:
    """Write the bag, every robot's topics in ``convention``; return the number of messages."""
    writer = convention_writer(convention)
    laser = laser or Laser()
    store = writer.typestore(fmt)
    rng = np.random.default_rng(seed)
    messages: list[tuple[int, int, str, Any]] = []  # (time, order, topic, message or its bytes)
    types: dict[str, str] = {}
    latched: set[str] = set()
    robots = [r for r in scenario.robots if r.id in execution.trajectories]
    for order, robot in enumerate(robots):
        run = RobotRun(
            store, robot.id, robot.namespace.strip("/"), execution, grid, laser, rng, start_ns, twist_stamped
        )
        latched.update(run.topic(name) for name in writer.latched)
        for written in writer.messages(run):
            if isinstance(written, Batch):
                types[written.topic] = written.msgtype
                serialized = written.serialized(_serializer(store, fmt))
                messages.extend(
                    (stamp, order, written.topic, raw)
                    for stamp, raw in zip(written.stamps.tolist(), serialized, strict=True)
                )
            else:
                topic, msgtype, stamp, msg = written
                types[topic] = msgtype
                messages.append((stamp, order, topic, msg))
    messages.sort(key=lambda m: (m[0], m[1], m[2]))
    _write(path, fmt, store, messages, types, latched)
    return len(messages)


def _write(
    path: Path,
    fmt: str,
    store: Any,
    messages: list[tuple[int, int, str, Any]],
    types: dict[str, str],
    latched: set[str],
) -> None:
    serializer = _serializer(store, fmt)

    def serialize(msg: Any, msgtype: str) -> Any:  # a batch's messages come serialized
        return msg if isinstance(msg, bytes) else serializer(msg, msgtype)

    if fmt == "ros1":
        with Ros1Writer(path) as writer:
            connections = {
                t: writer.add_connection(t, types[t], typestore=store, latching=1 if t in latched else None)
                for t in sorted(types)
            }
            for stamp, _, topic, msg in messages:
                writer.write(connections[topic], stamp, serialize(msg, types[topic]))
    else:
        plugin = StoragePlugin.MCAP if fmt == "mcap" else StoragePlugin.SQLITE3
        with Ros2Writer(path, version=8, storage_plugin=plugin) as writer2:
            conns = {t: _ros2_connection(writer2, store, t, types[t], t in latched) for t in sorted(types)}
            for stamp, _, topic, msg in messages:
                writer2.write(conns[topic], stamp, serialize(msg, types[topic]))


def _serializer(store: Any, fmt: str) -> Any:
    return store.serialize_ros1 if fmt == "ros1" else store.serialize_cdr


def _ros2_connection(writer: Ros2Writer, store: Any, topic: str, msgtype: str, latched: bool) -> Any:
    """A ROS 2 connection; an action's message type gets its definition written here, as rosbags'
    generator writes none for ``pkg/action/`` types."""
    action = "/action/" in msgtype
    return writer.add_connection(
        topic,
        msgtype,
        typestore=store,
        msgdef=ros2_message_definition(store, msgtype) if action else None,
        rihs01=store.hash_rihs01(msgtype) if action else None,
        offered_qos_profiles=(LATCHED_QOS,) if latched else (),
    )
