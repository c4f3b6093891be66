"""What a bag holds, for a user who arrives with bags and no specification (``exscec bag info``).

From the bag's own index and metadata: its format, size, time span, and per topic its type,
message count and rate.  From a sample of each topic's first messages (at most :data:`SAMPLE`,
deserialised by rosbags): which clock its stamps are (the recorder's wall clock or a
simulation's, and their offset to log time), the TF tree's edges (static or not), and, read
whole because they are few, the navigation actions' goals and how they ended.  Per namespace,
the convention ingestion would detect and the topics that show it.  Last, read whole, the pose
topics whose steps no robot could make (two tracks, teleports: :mod:`~exsce_dsl.runs.plausible_poses`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from exsce_dsl.errors import BagError
from exsce_dsl.messages.catalogue import standard_catalogue
from exsce_dsl.messages.user import configured_user_catalogue
from exsce_dsl.model.goals import action_names, actionlib_names
from exsce_dsl.model.messages import standard_type
from exsce_dsl.runs.bags.formats import MCAP_FILE
from exsce_dsl.runs.bags.reading import bag_formats, bag_topics
from exsce_dsl.runs.bags.rosbags_fallback import typestore_for
from exsce_dsl.runs.plausible_poses import bag_findings
from exsce_dsl.runs.signals.clock_words import describe_clocks, log_time_is_dated
from exsce_dsl.runs.signals.detect import robot_namespaces
from exsce_dsl.runs.signals.timeline import SAME_CLOCK, SIMULATED_BEFORE

SAMPLE = 50
"""Messages of a topic read for its stamps."""
TF_SAMPLE = 1000
"""Messages of a TF topic read for its edges and their rates (small ones, many edges at many rates)."""
_TF = "tf2_msgs/msg/TFMessage"
_STATUS = {
    "action_msgs/msg/GoalStatusArray": action_names,
    "actionlib_msgs/msg/GoalStatusArray": actionlib_names,
}


@dataclass(frozen=True)
class TopicInfo:
    name: str
    msgtype: str
    messages: int
    rate: float | None
    """Messages per second over the topic's own span (None: fewer than two)."""
    clock: str
    """``log time`` (no stamps), ``wall clock`` or ``simulated`` (its stamps')."""
    offset: float | None = None
    """Median of log time minus stamp over the sample, in seconds."""
    definition: str = ""
    """Where its type's definition comes from: :data:`BAG_OWN`, :data:`USER_OWN`, :data:`TYPESTORE`
    or :data:`UNKNOWN`, in the order ingestion looks."""


@dataclass(frozen=True)
class BagInfo:
    path: str
    format: str
    size: int
    start: float
    end: float
    topics: tuple[TopicInfo, ...]
    tf_edges: tuple[tuple[str, str, bool], ...] = ()
    """(parent, child, static) of the transforms in the sample."""
    tf_rates: Mapping[tuple[str, str], float] = field(default_factory=dict)
    """(parent, child) → transforms a second over the sample (not for static edges, nor for an
    edge seen once)."""
    goals: Mapping[str, Mapping[str, int]] = field(default_factory=dict)
    """A navigation status topic → final status → goals."""
    conventions: tuple[str, ...] = ()
    """Per namespace, the convention ingestion would detect and from what."""
    plausibility: tuple[str, ...] = ()
    """Pose topics no robot could have made (two tracks, teleports): ingestion makes no distance
    or speed of them (:mod:`~exsce_dsl.runs.plausible_poses`)."""

    @property
    def clock_recorded(self) -> bool:
        return any(t.name.lstrip("/") == "clock" for t in self.topics)

    @property
    def dated(self) -> bool:
        """Whether its log times are dates (not simulated time logged by the recorder)."""
        return log_time_is_dated(self.start)

    @property
    def timeline(self) -> str:
        """Its clocks, in the words ``exscec ingest`` uses (:func:`describe_clocks`), decided as
        ingestion decides (:func:`~exsce_dsl.runs.signals.timeline.decide_timeline`): by
        ``/clock`` where it was recorded (a simulation whose clock runs as the wall clock, a
        stand-in's, is the wall clock), else by the stamps."""
        clocks = [t for t in self.topics if t.name.lstrip("/") == "clock"]
        simulated = any(t.clock == "simulated" for t in clocks or self.topics)
        return describe_clocks(self.start, self.clock_recorded, simulated)

    def as_dict(self) -> dict[str, Any]:
        return {
            "path": self.path,
            "format": self.format,
            "size_bytes": self.size,
            "start": self.start,
            "end": self.end,
            "duration_s": self.end - self.start,
            "timeline": self.timeline,
            "dated": self.dated,
            "topics": [t.__dict__ for t in self.topics],
            "tf": [
                {"parent": p, "child": c, "static": s, "rate": self.tf_rates.get((p, c))}
                for p, c, s in self.tf_edges
            ],
            "goals": {topic: dict(ends) for topic, ends in self.goals.items()},
            "conventions": list(self.conventions),
            "plausibility": list(self.plausibility),
        }


def bag_info_of(path: Path) -> BagInfo:
    """What the bag at ``path`` holds (see the module's docstring)."""
    from rosbags.highlevel import AnyReader

    types = bag_topics(path)  # checks the file first, with exsce's messages for broken ones
    try:
        with AnyReader([path], default_typestore=typestore_for(path)) as reader:
            topics, edges, rates, goals = _read(reader)
            start, end = reader.start_time * 1e-9, reader.end_time * 1e-9
    except BagError:
        raise
    except Exception as exc:  # rosbags' readers raise their own errors for corrupt files
        raise BagError(f"{path}: cannot read the bag: {type(exc).__name__}: {exc}") from None
    size = sum(p.stat().st_size for p in ([path] if path.is_file() else path.rglob("*")) if p.is_file())
    if not log_time_is_dated(start) and any(t.name.lstrip("/") == "clock" for t in topics):
        # the recorder logged simulated time: stamps that agree with it are simulated too
        topics = tuple(replace(t, clock="simulated") if t.clock == "wall clock" else t for t in topics)
    return BagInfo(
        str(path), _format(path), size, start, end, topics, edges, rates, goals, _conventions(types),
        _plausibility(path, types),
    )  # fmt: skip


def _plausibility(path: Path, types: Mapping[str, str]) -> tuple[str, ...]:
    """The pose topics no robot could make; a bag whose poses cannot be read says so, and the
    rest of what it holds is still shown."""
    try:
        return bag_findings(path, types)
    except BagError as exc:
        return (f"not checked: {exc.message}",)


def _format(path: Path) -> str:
    if path.is_file():
        return next((f.name for f in bag_formats() if f.suffix == path.suffix), path.suffix)
    return "ROS 2 (MCAP)" if any(path.glob(f"*{MCAP_FILE.suffix}")) else "ROS 2 (sqlite3)"


def _read(
    reader: Any,
) -> tuple[
    tuple[TopicInfo, ...],
    tuple[tuple[str, str, bool], ...],
    dict[tuple[str, str], float],
    dict[str, dict[str, int]],
]:
    by_topic: dict[str, list[Any]] = {}
    for connection in reader.connections:
        by_topic.setdefault(connection.topic, []).append(connection)
    topics: list[TopicInfo] = []
    edges: dict[tuple[str, str], bool] = {}
    seen: dict[tuple[str, str], list[float]] = {}
    goals: dict[str, dict[str, str]] = {}
    for name, connections in sorted(by_topic.items()):
        msgtype = connections[0].msgtype
        count = sum(c.msgcount for c in connections)
        logs, stamps = [], []
        for index, (connection, time_ns, raw) in enumerate(reader.messages(connections=connections)):
            whole = msgtype in _STATUS
            if index >= (TF_SAMPLE if standard_type(msgtype) == _TF else SAMPLE) and not whole:
                break
            logs.append(time_ns * 1e-9)  # the rate is the log times': known whatever the bytes
            try:
                message = reader.deserialize(raw, connection.msgtype)
            except Exception:  # a type (or a version of it) rosbags cannot read: no stamp
                continue
            stamp = _stamp(message)
            if stamp is not None:
                stamps.append(time_ns * 1e-9 - stamp)
            if standard_type(msgtype) == _TF:
                for transform in message.transforms:
                    edge = (transform.header.frame_id, transform.child_frame_id)
                    edges[edge] = name.endswith("tf_static")
                    seen.setdefault(edge, []).append(time_ns * 1e-9)
            if whole:
                _goals(goals.setdefault(name, {}), message, _STATUS[msgtype]())
        info = _topic(name, msgtype, count, logs, stamps)
        topics.append(replace(info, definition=_definition(msgtype, connections, reader.connections)))
    ended = {topic: _ends(found) for topic, found in goals.items()}
    rates = {edge: r for edge, times in seen.items() if not edges[edge] and (r := _rate(times)) is not None}
    return tuple(topics), tuple((p, c, s) for (p, c), s in sorted(edges.items())), rates, ended


BAG_OWN, USER_OWN, TYPESTORE, UNKNOWN = "the bag", "EXSCE_MSG_PATH", "rosbags' typestore", "unknown"


def _definition(msgtype: str, connections: list[Any], every: Sequence[Any] = ()) -> str:
    """Where ingestion finds the definition of ``msgtype``: the bag's own (a ROS 1 connection's,
    an MCAP schema, a ROS 2 bag's type description), else the user's files, else rosbags'
    standard typestores.  Where the bag (``every`` connection) holds several versions of the
    type, each connection is decoded by its own: their hashes are listed."""
    if any(getattr(getattr(c, "msgdef", None), "data", "").strip() for c in connections):
        versions = {
            c.msgdef.data.strip(): c.digest for c in every if c.msgtype == msgtype and c.msgdef.data.strip()
        }
        if len(versions) > 1:
            hashes = ", ".join(sorted(str(d).removeprefix("RIHS01_")[:8] for d in versions.values()))
            return f"{BAG_OWN} ({len(versions)} versions: {hashes})"
        return BAG_OWN
    if msgtype in configured_user_catalogue().definitions:
        return USER_OWN
    return TYPESTORE if msgtype in standard_catalogue().definitions else UNKNOWN


def _rate(times: list[float]) -> float | None:
    return (len(times) - 1) / (times[-1] - times[0]) if len(times) > 1 and times[-1] > times[0] else None


def _stamp(message: Any) -> float | None:
    """A message's stamp: its header's, its first transform's, or a ``/clock`` message's time."""
    header = getattr(message, "header", None)
    if header is None and getattr(message, "transforms", None):
        header = message.transforms[0].header
    stamp = getattr(header, "stamp", None) if header is not None else getattr(message, "clock", None)
    if stamp is None:
        return None
    seconds = float(stamp.sec) + float(stamp.nanosec) * 1e-9
    return seconds if seconds > 0 else None


def _topic(name: str, msgtype: str, count: int, logs: list[float], offsets: list[float]) -> TopicInfo:
    rate = _rate(logs)
    if not offsets:
        return TopicInfo(name, msgtype, count, rate, "log time")
    offset = float(np.median(offsets))
    stamp = logs[0] - offset
    simulated = stamp < SIMULATED_BEFORE <= logs[0]
    clock = "simulated" if simulated else "wall clock" if abs(offset) <= SAME_CLOCK else "wall clock (offset)"
    return TopicInfo(name, msgtype, count, rate, clock, offset)


def _goals(found: dict[str, str], message: Any, names: dict[int, str]) -> None:
    for status in message.status_list:
        info = getattr(status, "goal_info", None)
        key = bytes(info.goal_id.uuid).hex() if info is not None else str(status.goal_id.id)
        found[key] = names.get(int(status.status), str(status.status))


def _ends(found: dict[str, str]) -> dict[str, int]:
    ends: dict[str, int] = {}
    for status in found.values():
        ends[status] = ends.get(status, 0) + 1
    return ends


def _conventions(types: Mapping[str, str]) -> tuple[str, ...]:
    """For the root and each first level of the topics' names: what ingestion would detect."""
    said = []
    for namespace, _, detected in robot_namespaces(types):
        shown = ", ".join(detected.evidence) or "its topics"
        said.append(f"namespace '{namespace or '/'}': convention {detected.convention} (from {shown})")
    return tuple(said)
