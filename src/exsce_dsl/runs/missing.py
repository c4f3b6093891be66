"""What a run lacks, said so that the user can mend it.

- :func:`unread_topics`: the topics the specification names (a robot type's signal sources and
  navigation actions, a metric's reads) that the bag does not hold, once per topic, each with
  the bag's topics most like it (did-you-mean: a relative name, another namespace and a typo
  count as close) and the bag's topics of the type the specification expects there;
- :func:`missing_metrics`: the values a run of the scenario should have and has not, which
  ``exscec ingest --strict`` refuses to store.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

from exsce_dsl.model.conventions import LASER_SCAN, POSE_TYPES, VELOCITY_TYPES, TopicSource
from exsce_dsl.model.messages import DISPATCHER, canonical_type
from exsce_dsl.model.metrics import ComputedFor, MetricDefinition, expand_topic
from exsce_dsl.model.robots import Robot
from exsce_dsl.model.runs import ActionId, MetricScope, MetricValue
from exsce_dsl.runs.segments.recorded import RecordedAction
from exsce_dsl.suggest import closest_several

SIGNAL_TYPES = {"pose": POSE_TYPES, "velocity": VELOCITY_TYPES, "scan": (LASER_SCAN,)}
"""The types a robot type's signal line may be read from, when it names none."""
ACTION_STATUS = ("action_msgs/msg/GoalStatusArray", "actionlib_msgs/msg/GoalStatusArray")
"""What a navigation action's status topic carries (ROS 2, ROS 1): the topics that name actions."""
LISTED = 8
Lacks = Callable[[str, tuple[str, ...], str, str], None]
"""Topics of the expected type listed at most (the rest counted)."""


@dataclass(frozen=True)
class Unread:
    """A topic the specification names that the bag lacks."""

    topic: str
    types: tuple[str, ...]
    """The types expected there (any of them), or ``()`` for a navigation action."""
    kind: str
    """What the expected types are called: one type, ``a pose``, ``a navigation action``."""
    readers: tuple[str, ...]
    """Who reads it: ``the pose of 'bot'``, ``metric gt_path``."""


def unread_topics(
    metrics: Iterable[MetricDefinition],
    robots: Sequence[Robot],
    bag: Mapping[str, str],
) -> list[str]:
    """One warning per topic that ``metrics`` (the specification's own, not the standard
    library's) or the robots' types name but ``bag`` (topic → type) lacks."""
    found: dict[str, Unread] = {}

    def lacks(topic: str, types: tuple[str, ...], kind: str, reader: str) -> None:
        if topic in bag:
            return
        before = found.get(topic, Unread(topic, types, kind, ()))
        more = tuple(t for t in types if t not in before.types)
        kind = before.kind if not more else " or ".join(before.types + more)
        readers = before.readers + (reader,) * (reader not in before.readers)
        found[topic] = Unread(topic, before.types + more, kind, readers)

    for robot in robots:
        _robot_sources(robot, bag, lacks)
    for metric in metrics:
        for read in metric.reads:
            if read.signal or read.msgtype in DISPATCHER:
                continue
            for robot in robots:
                msgtype = canonical_type(read.msgtype)
                lacks(expand_topic(read.topic, robot.namespace), (msgtype,), msgtype, f"metric {metric.name}")
    return [_said(unread, bag) for unread in found.values()]


def _robot_sources(robot: Robot, bag: Mapping[str, str], lacks: Lacks) -> None:
    """The robot type's own signal lines of which the bag has none, and its own actions."""
    signals, ns = robot.signals, robot.namespace
    for signal, types in SIGNAL_TYPES.items():
        sources = getattr(signals, signal)
        topics = [s for s in sources if isinstance(s, TopicSource)]
        if signal not in signals.said or len(topics) < len(sources):
            continue  # the convention's own (a fallback is expected to be absent), or a TF chain
        if any(expand_topic(s.topic, ns) in bag for s in topics):
            continue
        for source in topics:
            msgtype = canonical_type(source.msgtype) if source.msgtype else ""
            expected, kind = ((msgtype,), msgtype) if msgtype else (types, f"{signal}")
            lacks(expand_topic(source.topic, ns), expected, kind, f"the {signal} of '{robot.id}'")
    if "navigation" in signals.said:
        actions = [expand_topic(a, ns) for a in signals.actions]
        prefixes = {t.rstrip("/") + "/" for t in actions}
        if not any(expand_topic(t, "").startswith(p) for t in bag for p in prefixes):
            for action in actions:
                lacks(action, (), "navigation action", f"the navigation of '{robot.id}'")


def _said(unread: Unread, bag: Mapping[str, str]) -> str:
    """``topic /x (T), read by ..., is not in this bag; did you mean ...? Its T topics: ...``."""
    kind = unread.kind
    if unread.types:
        candidates: Sequence[str] = list(bag)
        of_type = [t for t in bag if bag[t] in unread.types]
    else:
        candidates = of_type = _actions(bag)
    listing = f"the bag's {kind} topics: {_listed(of_type)}" if of_type else f"the bag has no {kind} topic"
    close = closest_several(unread.topic, candidates, forms=_topic_forms)
    hint = f"; did you mean {' or '.join(close)}?" if close else ""
    what = f"topic {unread.topic}" if unread.types else f"action {unread.topic}"
    return f"{what}, read for {', '.join(unread.readers)}, is not in this bag{hint} ({listing})"


def _actions(bag: Mapping[str, str]) -> list[str]:
    """The navigation actions the bag records (from their status topics)."""
    found = []
    for topic, msgtype in bag.items():
        if msgtype in ACTION_STATUS and topic.endswith("/status"):
            found.append(topic.removesuffix("/status").removesuffix("/_action"))
    return found


def _listed(topics: Sequence[str]) -> str:
    shown = ", ".join(sorted(topics)[:LISTED])
    return shown + (f" and {len(topics) - LISTED} more" if len(topics) > LISTED else "")


def _topic_forms(topic: str) -> tuple[str, str]:
    """A topic compared as its name without the leading ``/``, then by its last part."""
    name = topic.strip("/")
    return name, name.rsplit("/", 1)[-1]


def missing_metrics(
    metrics: Iterable[MetricDefinition],
    robots: Sequence[Robot],
    acting: Iterable[str],
    segments: Sequence[RecordedAction],
    values: Sequence[MetricValue],
) -> list[str]:
    """The values a run should have and has not: each robot metric of each robot that has tasks
    (``acting``), for the whole run and each of its path segments when the metric is per
    segment, and each mission metric (over pairs: with two robots or more)."""
    acting = set(acting)
    held = {(v.metric, v.scope, v.robot if v.action is None else None, v.action) for v in values}
    lacking: list[str] = []
    timed = [s for s in segments if s.start is not None and s.end is not None]
    for metric in metrics:
        if metric.subject is ComputedFor.ROBOT:
            for robot in robots:
                if robot.id not in acting:
                    continue
                if (metric.name, MetricScope.ROBOT, robot.id, None) not in held:
                    lacking.append(f"{metric.name} of '{robot.id}'")
                    continue
                mine = [s for s in timed if s.robot == robot.id] if metric.per_segment else []
                gaps = sum((metric.name, MetricScope.SEGMENT, None, _action(s)) not in held for s in mine)
                if gaps:
                    lacking.append(f"{metric.name} of '{robot.id}' for {gaps} of {len(mine)} path segments")
        elif metric.subject is ComputedFor.MISSION or len(acting) >= 2:
            if not any(v.metric == metric.name and v.scope is MetricScope.MISSION for v in values):
                lacking.append(f"{metric.name} of the mission")
    return lacking


def _action(segment: RecordedAction) -> ActionId:
    return ActionId(segment.robot, segment.allocation, segment.subtask, segment.waypoint)
