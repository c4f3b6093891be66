"""A robot type's signals: its convention, and the sources its own lines override (IR building).

``convention nav2`` takes Nav2's sources; each ``pose``, ``velocity``, ``scan``,
``navigation`` or ``arrival`` line replaces the convention's for that signal
(several ``pose`` lines are a list of preference, tried in order at ingest).  A rate
(``scan on "/{ns}/base_scan" at 10 Hz``, or ``scan at 10 Hz`` for the signal wherever it is read
from) says how often the topic is published: a run that recorded it at less than half of it
is told (``runs.coverage``).
A robot type that names no convention has it detected from each bag at ingest, and its own lines
win over what is detected (``Signals.said``); one that says none of this at all likewise.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.expressions import read_quantity
from exsce_dsl.model.conventions import (
    CONVENTIONS,
    LASER_SCAN,
    METHOD,
    MOVE_BASE,
    NAV2,
    POSE_TYPES,
    VELOCITY_TYPES,
    MetricSpan,
    Navigation,
    PoseSource,
    Signals,
    TfSource,
    Tolerance,
    TopicSource,
)
from exsce_dsl.model.messages import canonical_type
from exsce_dsl.model.names import TOPIC_RULE, is_topic_pattern

_SIGNAL_FACTS = (
    "ConventionFact",
    "PoseFact",
    "VelocityFact",
    "ScanFact",
    "RateFact",
    "NavigationFact",
    "ArrivalFact",
    "WindowFact",
)
_ACTIONS = {
    Navigation.DISPATCHER: METHOD.actions,
    Navigation.NAV2: NAV2.actions,
    Navigation.MOVE_BASE: MOVE_BASE.actions,
    Navigation.NONE: (),
}

_ONCE = {"NavigationFact": "navigation", "ArrivalFact": "arrival tolerance", "WindowFact": "window"}
"""The facts a robot type states once, by the word an error calls them."""
Report = Callable[[str, SourceLocation], None]
Span = Callable[[Any], SourceLocation]


def build_signals(
    type_name: str, facts: list[Any], span: Span, error: Report, base: Signals = METHOD
) -> Signals | None:
    """The signals a robot type's facts declare (or a robot's, over its type's ``base``); None
    when they declare none."""
    mine = [f for f in facts if f.__class__.__name__ in _SIGNAL_FACTS]
    if not mine:
        return None
    conventions = [f for f in mine if f.__class__.__name__ == "ConventionFact"]
    for extra in conventions[1:]:
        error(f"{type_name} names its convention twice", span(extra))
    signals = CONVENTIONS[conventions[0].convention] if conventions else base
    poses: list[PoseSource] = []
    velocities: list[TopicSource] = []
    scans: list[TopicSource] = []
    said: dict[str, Any] = {}
    rates: dict[str, float] = {}
    for fact in mine:
        kind = fact.__class__.__name__
        if kind == "PoseFact":
            if fact.source is None:
                poses.append(TfSource(fact.fixed, fact.body))
            elif (source := _topic(fact.source, POSE_TYPES, "a pose", span, error)) is not None:
                poses.append(source)
        elif kind == "VelocityFact":
            if (source := _topic(fact.source, VELOCITY_TYPES, "a velocity", span, error)) is not None:
                velocities.append(source)
        elif kind == "ScanFact":
            if (source := _topic(fact.source, (LASER_SCAN,), "a laser scan", span, error)) is not None:
                scans.append(source)
        elif kind == "RateFact":
            if fact.signal in rates:
                error(f"{type_name} states the rate of its {fact.signal} twice", span(fact))
            rate = _rate(fact.rate, span(fact), error)
            if rate is not None:
                rates[fact.signal] = rate
        elif kind in ("NavigationFact", "ArrivalFact", "WindowFact"):
            if kind in said:
                word = _ONCE[kind]
                error(f"{type_name} states its {word} twice", span(fact))
            said[kind] = fact
    changes: dict[str, Any] = {}
    if poses:
        changes["pose"] = tuple(poses)
    if velocities:
        changes["velocity"] = tuple(velocities)
    if scans:
        changes["scan"] = tuple(scans)
    if rates:
        changes["rates"] = tuple(rates.items())
    if "NavigationFact" in said:
        fact = said["NavigationFact"]
        navigation = Navigation(fact.navigation)
        actions = tuple(fact.actions) or _ACTIONS[navigation]
        for action in fact.actions:
            _check_topic(action, span(fact), error)
        changes["navigation"], changes["actions"] = navigation, actions
    if "ArrivalFact" in said:
        changes["tolerance"] = _tolerance(said["ArrivalFact"], span, error)
    if "WindowFact" in said:
        changes["window"] = MetricSpan.RECORDING if said["WindowFact"].recording else MetricSpan.GOALS
    location = span(conventions[0] if conventions else mine[0])
    named = bool(conventions) or (base.named and base is not METHOD)
    own = frozenset(changes) - {"actions"}
    return signals.overridden(
        **changes, location=location, named=named, said=own if conventions else base.said | own
    )


def _topic(source: Any, allowed: tuple[str, ...], what: str, span: Span, error: Report) -> TopicSource | None:
    where = span(source)
    if not _check_topic(source.topic, where, error):
        return None
    rate = _rate(source.rate, where, error) if source.rate is not None else None
    if source.msgtype is None:
        return TopicSource(source.topic, rate=rate)
    msgtype = canonical_type(source.msgtype)
    if msgtype not in allowed:
        error(f"{what} is read from {', '.join(allowed)}, not from {msgtype}", where)
        return None
    return TopicSource(source.topic, msgtype, rate)


def _rate(text: str, where: SourceLocation, error: Report) -> float | None:
    """A rate as written (``10 Hz``) in Hz; one not above zero is an error at ``where``."""
    rate = float(text.strip().removesuffix("Hz"))
    if not rate > 0:
        error(f"a rate is a frequency above zero, not {text.strip()}", where)
        return None
    return rate


def _check_topic(topic: str, where: SourceLocation, error: Report) -> bool:
    if is_topic_pattern(topic):
        return True
    error(
        f"'{topic}' is not a ROS topic name ({TOPIC_RULE})",
        where,
    )
    return False


def _tolerance(fact: Any, span: Span, error: Report) -> Tolerance:
    position = read_quantity(fact.position)[0]  # in SI: metres, radians
    heading = read_quantity(fact.heading)[0] if fact.heading is not None else None
    if position <= 0 or (heading is not None and heading <= 0):
        error("an arrival tolerance is a distance (and an angle) above zero", span(fact))
        return Tolerance()
    written = (fact.position,) + ((fact.heading,) if fact.heading is not None else ())
    return Tolerance(position, heading, written)
