"""The ROS 2 recorder's process: an rclpy node that writes a rosbag2 MCAP bag, without rosbag2.

Run as ``python -m exsce_dsl.execute.ros2.record_node CONFIG`` (CONFIG: JSON, see
:func:`~.recorder.config`) by :class:`~.recorder.Ros2Recorder`, which reads the events it
prints.  Its node, :data:`~.recorder.RECORDER_NODE`, subscribes with serialized (raw)
subscriptions to exactly the topics it is given, each once a publisher of it shows on the graph
(looked for every :data:`POLL` seconds; hidden ``_action`` topics included), with the type the
graph names, the QoS its publishers offer (:mod:`.record_types`) and that type's definition and
hash.  Each message is written as it is received, at the wall clock's time; with
``use_sim_time``, at the simulated time it was sent (:mod:`.record_timeline`: a recorder that
falls behind puts no gap into the recording), nothing before the first ``/clock`` message (a
latched topic's messages sent before it are written at its time; others are dropped and
counted).

The bag is written into :func:`~.recorder.partial_folder`, a hidden sibling of the bag, and moved
to the bag's name only once the writer has closed it (on SIGINT or SIGTERM): a recorder killed
on the way leaves nothing under the bag's name.  A topic it cannot record (a type it cannot
describe, several types on one topic) stops it with an error naming the topic, and no bag.

Events, one JSON object a line on stdout: ``ready``; ``status`` (``published``: the topics that
have a publisher; ``subscribed``: those whose every publisher is matched to the recorder) when it
changes; ``error`` (``message``); ``closed`` (``written`` and ``dropped`` per topic).  Its log
lines go to stderr.
"""

from __future__ import annotations

import importlib
import json
import os
import shutil
import signal
import sys
import time
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from types import FrameType
from typing import Any

from rosbags.rosbag2 import StoragePlugin, Writer

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros2.record_timeline import SimTimeline
from exsce_dsl.execute.ros2.record_types import DEPTH, adapted_qos, describe_type, message_class, offered_qos
from exsce_dsl.execute.ros2.recorder import RECORDER_NODE, partial_folder

POLL = 0.1
"""Seconds between two looks at the graph for new publishers."""
SPIN = 0.02
"""Longest wait for a message in one turn of the loop."""
DRAIN = 2.0
"""Longest time spent writing what has arrived when asked to stop."""


def emit(event: str, **fields: Any) -> None:
    """Print an event for the process that started the recorder."""
    print(json.dumps({"event": event, **fields}, sort_keys=True), flush=True)


def ros(module: str) -> Any:
    """A module of rclpy, imported when the recorder runs (importing this module needs none)."""
    return importlib.import_module(module)


def log(text: str) -> None:
    print(f"[{RECORDER_NODE}] {text}", file=sys.stderr, flush=True)


class Recording:
    """The node's subscriptions and the bag they are written to."""

    def __init__(self, node: Any, writer: Any, topics: Sequence[str], use_sim_time: bool) -> None:
        self.node, self.writer, self.use_sim_time = node, writer, use_sim_time
        self.topics = tuple(dict.fromkeys(topics))
        self.subscriptions: dict[str, Any] = {}
        self.connections: dict[str, Any] = {}
        self.latched: set[str] = set()
        self.held: list[tuple[str, bytes]] = []
        """Latched messages received before the first ``/clock`` (on simulated time)."""
        self.timeline = SimTimeline() if use_sim_time else None
        """On ``/clock``: each message placed by when it was sent (:mod:`.record_timeline`)."""
        self.written: Counter[str] = Counter()
        self.dropped: Counter[str] = Counter()
        self.status: tuple[list[str], list[str]] | None = None

    def poll(self) -> None:
        """Subscribe to each topic that has a publisher now; tell the status if it changed."""
        graph = dict(self.node.get_topic_names_and_types())
        for topic in self.topics:
            if topic not in self.subscriptions and topic in graph and self.node.count_publishers(topic) > 0:
                self.subscribe(topic, graph[topic])
        published = [t for t in self.topics if self.node.count_publishers(t) > 0]
        subscribed = [
            t
            for t in published
            if t in self.subscriptions
            and self.subscriptions[t].get_publisher_count() >= self.node.count_publishers(t)
        ]
        if (published, subscribed) != self.status:
            self.status = (published, subscribed)
            emit("status", published=published, subscribed=subscribed)

    def subscribe(self, topic: str, types: Sequence[str]) -> None:
        """Subscribe to ``topic`` (published with ``types``) and add its connection to the bag."""
        if len(types) != 1:
            raise RosGraphError(f"{topic} is published with several types, {sorted(types)}: not recorded")
        msgtype = types[0]
        publishers = self.node.get_publishers_info_by_topic(topic)
        offered = [offered_qos(p.qos_profile) for p in publishers]
        try:
            definition, rihs01, source = describe_type(msgtype, [str(p.topic_type_hash) for p in publishers])
        except RosGraphError as error:
            raise RosGraphError(f"{topic}: {error.message}") from None
        cls = message_class(msgtype)
        if cls is None:
            raise RosGraphError(f"{topic}: the Python package of {msgtype} is not installed here")
        reliable, latched = adapted_qos(offered)
        policies = ros("rclpy.qos")
        reliability, durability = policies.ReliabilityPolicy, policies.DurabilityPolicy
        qos = policies.QoSProfile(
            history=policies.HistoryPolicy.KEEP_LAST,
            depth=DEPTH,
            reliability=reliability.RELIABLE if reliable else reliability.BEST_EFFORT,
            durability=durability.TRANSIENT_LOCAL if latched else durability.VOLATILE,
        )
        self.connections[topic] = self.writer.add_connection(
            topic, msgtype, msgdef=definition, rihs01=rihs01, offered_qos_profiles=offered
        )
        if latched:
            self.latched.add(topic)
        self.subscriptions[topic] = self.node.create_subscription(
            cls, topic, lambda data, info, topic=topic: self.receive(topic, data, info), qos, raw=True
        )
        kind = f"{'reliable' if reliable else 'best effort'}, {'transient local' if latched else 'volatile'}"
        log(f"subscribed to {topic} ({msgtype}, {kind}; its definition from {source})")

    def receive(self, topic: str, data: bytes, info: Any = None) -> None:
        """Write a message: on the wall clock at the time it is received; on ``/clock`` at the
        simulated time it was sent, once known (nothing before the first ``/clock``: a latched
        topic's messages go at its time, others are dropped)."""
        if self.timeline is not None:
            self.timeline.add(topic, data, int(info["source_timestamp"]))
            self.write_ready()
            return
        now = int(self.node.get_clock().now().nanoseconds)
        if self.use_sim_time and now <= 0:
            if topic in self.latched:
                self.held.append((topic, data))
            else:
                self.dropped[topic] += 1
            return
        if self.held:
            held, self.held = self.held, []
            for early, message in held:
                self._write(early, now, message)
        self._write(topic, now, data)

    def write_ready(self, final: bool = False) -> None:
        """Write the messages whose simulated time is known (``final``: every one left)."""
        assert self.timeline is not None
        for topic, data, stamp in self.timeline.ready(final):
            first = self.timeline.first
            if stamp is None and topic in self.latched and first is not None:
                stamp = first
            if stamp is None:
                self.dropped[topic] += 1
            else:
                self._write(topic, stamp, data)

    def received(self) -> int:
        """Messages received so far."""
        waiting = self.timeline.waiting if self.timeline is not None else 0
        return sum(self.written.values()) + sum(self.dropped.values()) + len(self.held) + waiting

    def _write(self, topic: str, stamp: int, data: bytes) -> None:
        self.writer.write(self.connections[topic], stamp, data)
        self.written[topic] += 1


class Stop:
    """Set by SIGINT or SIGTERM: the loop closes the bag and ends."""

    def __init__(self) -> None:
        self.asked = False
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self.ask)

    def ask(self, signum: int, frame: FrameType | None) -> None:
        self.asked = True


def record(bag: Path, topics: Sequence[str], use_sim_time: bool) -> int:
    """Record until SIGINT or SIGTERM; the exit status (0: the bag is closed at ``bag``)."""
    stop = Stop()
    partial = partial_folder(bag)
    shutil.rmtree(partial, ignore_errors=True)  # an earlier, killed recorder's
    partial.mkdir(parents=True)
    try:
        recording = _record_into(partial / bag.name, topics, use_sim_time, stop)
    except BaseException as error:
        shutil.rmtree(partial, ignore_errors=True)  # no half-written bag anywhere
        if not isinstance(error, RosGraphError):
            raise
        log(f"error: {error.message}")
        emit("error", message=error.message)
        return 2
    if bag.exists():
        shutil.rmtree(partial, ignore_errors=True)
        emit("error", message=f"{bag} appeared while recording (not by the recorder): recording dropped")
        return 2
    (partial / bag.name).rename(bag)
    partial.rmdir()
    log(f"closed {bag}: {sum(recording.written.values())} messages")
    emit("closed", written=dict(recording.written), dropped=dict(recording.dropped))
    return 0


def _record_into(path: Path, topics: Sequence[str], use_sim_time: bool, stop: Stop) -> Recording:
    """The node, recording into the bag ``path`` until stopped; the bag closed (or aborted, on
    an error)."""
    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    rclpy = ros("rclpy")
    context = ros("rclpy.context").Context()
    rclpy.init(context=context, signal_handler_options=ros("rclpy.signals").SignalHandlerOptions.NO)
    try:
        sim_time = ros("rclpy.parameter").Parameter("use_sim_time", value=use_sim_time)
        node = rclpy.create_node(RECORDER_NODE, context=context, parameter_overrides=[sim_time])
        executor = ros("rclpy.executors").SingleThreadedExecutor(context=context)
        executor.add_node(node)
        recording = Recording(node, writer, topics, use_sim_time)
        writer.open()
        try:
            emit("ready", node=RECORDER_NODE)
            _loop(executor, recording, stop)
        except BaseException:
            writer.abort()
            raise
        writer.close()
        executor.shutdown()
        node.destroy_node()
        return recording
    finally:
        context.try_shutdown()


def _loop(executor: Any, recording: Recording, stop: Stop) -> None:
    """Spin, looking at the graph every :data:`POLL` seconds, until asked to stop or orphaned
    (the process that started it is gone: a recorder is never left running on its own); then
    write what has arrived (until a turn brings nothing, at most :data:`DRAIN` seconds)."""
    parent = os.getppid()
    next_poll = 0.0
    while not stop.asked:
        if time.monotonic() >= next_poll:
            if os.getppid() != parent:
                log("the process that started the recorder is gone: closing the bag")
                break
            recording.poll()
            next_poll = time.monotonic() + POLL
        executor.spin_once(timeout_sec=SPIN)
    end = time.monotonic() + DRAIN
    while time.monotonic() < end:
        before = recording.received()
        executor.spin_once(timeout_sec=SPIN)
        if recording.received() == before:
            break
    for topic, _ in recording.held:  # /clock never came
        recording.dropped[topic] += 1
    if recording.timeline is not None:
        recording.write_ready(final=True)


def main(argv: Sequence[str] | None = None) -> int:
    arguments = list(sys.argv[1:] if argv is None else argv)
    if len(arguments) != 1:
        print(f"usage: python -m {__spec__.name if __spec__ else __name__} CONFIG", file=sys.stderr)
        return 2
    settings = json.loads(arguments[0])
    return record(Path(settings["bag"]), settings["topics"], bool(settings["use_sim_time"]))


if __name__ == "__main__":
    sys.exit(main())
