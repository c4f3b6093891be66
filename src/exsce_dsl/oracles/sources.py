"""What an oracle or a verdict read: the bag topics its values were computed from, from the store.

A metric's value in the store names the topics it really came from (its ``R:<metric>-topics``
collection): for a robot that runs Nav2 or move_base, its odometry, ``/cmd_vel`` or TF, not
the method's ``/nav_vel``.  An oracle learnt from runs names the sources of the values it learnt
from; a verdict names those of the judged run's value.  The method's default topics
(:func:`~exsce_dsl.model.metrics.default_topics`) are no evidence of what a stack's robot
published: an oracle no stored value was learnt from (fixed numbers, the method's oracle files)
names them only when its robots declare no signals of their own (:func:`unread_topics`).
"""

from __future__ import annotations

from collections.abc import Iterable

from exsce_dsl.model import Scenario
from exsce_dsl.model.metrics import default_topics
from exsce_dsl.store import MetricSource, Store, metric_sources

__all__ = ["ValueSources", "unread_topics"]


def unread_topics(scenario: Scenario, metric: str, robot: str | None) -> tuple[str, ...]:
    """The topics of an oracle no stored value was learnt from: the method's topics of ``metric``
    (those its oracle files name) when the robots it is about (``robot``, or all for the mission)
    declare no signals of their own; none when one does (a Nav2 robot's are known from its runs)."""
    robots = [r for r in scenario.robots if robot is None or r.id == robot]
    if any(r.declares_signals for r in robots):
        return ()
    return default_topics(scenario, metric, robot)


class ValueSources:
    """The topics of the stored values of runs, asked once per run and metric."""

    def __init__(self, store: Store) -> None:
        self.store = store
        self._known: dict[tuple[str, str], list[MetricSource]] = {}

    def of(self, run: str, metric: str) -> list[MetricSource]:
        """Each value of ``metric`` in ``run`` with the topics it was computed from."""
        key = (run, metric)
        found = self._known.get(key)
        if found is None:
            found = self._known[key] = metric_sources(self.store, run, metric)
        return found

    def topics(
        self, runs: Iterable[str], metric: str, robot: str | None, *, whole_run: bool
    ) -> tuple[str, ...]:
        """The topics the values of ``metric`` of ``robot`` (None: the mission's) in ``runs``
        were computed from, sorted; ``whole_run``: only whole-run values (else segment values
        too, for a clause over a part of the run)."""
        found = {
            topic
            for run in dict.fromkeys(runs)
            for source in self.of(run, metric)
            if source.robot == robot and (source.segment is None or not whole_run)
            for topic in source.topics
        }
        return tuple(sorted(found))
