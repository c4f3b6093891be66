"""What a run on a live graph records: exactly the topics ingestion will read of its bag.

:func:`recorded_topics` asks the same questions ingestion asks of a bag (:mod:`exsce_dsl.runs`),
before there is one:

- each robot's signals, every source its convention lists (the first one the bag has is read,
  and which one a stack publishes is not known before the run): pose, velocity, scan and
  distance topics, and for a pose read from TF the robot's ``tf`` and ``tf_static``;
- its navigation goals: the method's dispatcher's ``feedback`` and ``result``, move_base's
  ``goal``, ``status`` and ``result``, Nav2's action ``status`` (``follow_waypoints``' feedback
  too) and the planner's ``plan``;
- every topic a metric reads by name (a signal it reads, ``robot pose``..., is among the
  sources above);
- and :data:`ALWAYS`: ``/tf``, ``/tf_static``, ``/clock`` (which decides the run's clock) and
  :data:`PROV_TOPIC`, where the dispatcher publishes the run-time PROV.

A robot whose type names no convention has it detected from the bag at ingestion: every
convention's topics are recorded for it, unless the caller says which one its stack follows.
Names are made absolute (a recorder resolves a relative name at the root); robots without a
start pose take no part in a run (as in ingestion).  No middleware is imported here.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import CONVENTIONS, Signals, TfSource
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.model.robots import Robot
from exsce_dsl.runs import PROV_TOPIC, StackRobots, run_metrics, topic_key, wanted_topics

ALWAYS = ("/tf", "/tf_static", "/clock", PROV_TOPIC)
"""Recorded in every run: the global TF tree, simulated time and the run-time PROV."""


def recorded_topics(scenario: Scenario, convention: str | None = None) -> list[str]:
    """The topics a run of ``scenario`` records, absolute, sorted, each once.

    ``convention`` (``method``, ``nav2``, ``move_base``): the one the stacks of the robots whose
    type names none follow; None: every convention's topics for them."""
    if convention is not None and convention not in CONVENTIONS:
        raise ExsceError(f"unknown convention '{convention}'; use one of {', '.join(CONVENTIONS)}")
    metrics = run_metrics(scenario)
    found = set(ALWAYS)
    for robot in (r for r in scenario.robots if r.start_pose is not None):
        for signals in _candidates(robot, convention):
            stack = replace(robot, declared_signals=signals)
            found.update(_signal_topics(signals, robot.namespace))
            read = StackRobots({}).adapt(wanted_topics(metrics, [stack]), [stack])
            found.update(read)
    return sorted({topic_key(topic) for topic in found})


def _candidates(robot: Robot, convention: str | None) -> list[Signals]:
    """The signals the robot's stack may follow: its own when its type names a convention, else
    each convention (or the one given), with the type's own lines over it."""
    if robot.names_convention:
        return [robot.signals]
    conventions = [CONVENTIONS[convention]] if convention is not None else list(CONVENTIONS.values())
    if robot.declares_signals:
        return [robot.signals.over(c) for c in conventions]
    return conventions


def _signal_topics(signals: Signals, namespace: str) -> Iterable[str]:
    """Every source of the robot's pose, velocity, scan and distance (TF: ``tf`` and ``tf_static``)."""
    for source in (*signals.pose, *signals.velocity, *signals.scan, *signals.distance):
        if isinstance(source, TfSource):
            yield expand_topic(source.tf, namespace)
            yield expand_topic(source.tf_static, namespace)
        else:
            yield expand_topic(source.topic, namespace)
