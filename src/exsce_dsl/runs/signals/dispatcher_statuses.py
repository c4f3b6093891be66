"""The method's waypoint dispatcher's goal statuses, as its bag recorded them.

The dispatcher is an actionlib server (``FollowWaypoints``): its feedback and result topics carry
one status per waypoint of the goal it runs.  Few messages, so they are read as message objects
(:data:`~exsce_dsl.runs.bags.reading.OBJECTS`), like Nav2's and move_base's goals, and walked here
into :class:`StatusUpdate`\\ s in time order; the topics are the method's convention's
(:data:`~exsce_dsl.model.conventions.METHOD_TOPICS`).
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import BagError
from exsce_dsl.model.conventions import DISPATCHER_FEEDBACK, DISPATCHER_RESULT
from exsce_dsl.model.metrics import expand_topic
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Wanted

_PROGRESS = {0: 0, 1: 1}  # PENDING, ACTIVE; every other status is final


@dataclass(frozen=True)
class StatusUpdate:
    """A dispatcher feedback or result: the status of each waypoint of one goal."""

    t: float
    goal: str  # the actionlib goal id (may be empty)
    waypoints: tuple[str, ...]
    statuses: tuple[int, ...]


@dataclass(frozen=True)
class DispatcherStatuses:
    """One robot's dispatcher as its bag has it: the updates of its feedback and of its result
    topic (None: the bag has no such topic), and their names."""

    feedback: list[StatusUpdate] | None
    result: list[StatusUpdate] | None
    topics: tuple[str, str]


def dispatcher_wanted(namespace: str) -> dict[str, Wanted]:
    """What the dispatcher's statuses are read from: its feedback and result, as message objects."""
    return {expand_topic(t, namespace): Wanted(OBJECTS) for t in (DISPATCHER_FEEDBACK, DISPATCHER_RESULT)}


def dispatcher_statuses(namespace: str, data: BagData) -> DispatcherStatuses:
    """The statuses the robot at ``namespace``'s dispatcher recorded in ``data``."""
    feedback, result = (expand_topic(t, namespace) for t in (DISPATCHER_FEEDBACK, DISPATCHER_RESULT))
    return DispatcherStatuses(
        _updates(feedback, data.messages.get(feedback)),
        _updates(result, data.messages.get(result)),
        (feedback, result),
    )


def _updates(topic: str, messages: Sequence[tuple[float, Any]] | None) -> list[StatusUpdate] | None:
    """The updates of ``messages`` (in time order); updates at one instant go in the order the
    statuses move (PENDING, ACTIVE, final)."""
    if messages is None:
        return None
    updates = [_status_update(m, t, topic) for t, m in messages]
    ordered: list[StatusUpdate] = []
    for _, same in itertools.groupby(updates, key=lambda u: u.t):
        ordered += sorted(same, key=lambda u: sum(_PROGRESS.get(s, 2) for s in u.statuses))
    return ordered


def _status_update(msg: Any, t: float, topic: str) -> StatusUpdate:
    try:
        payload = getattr(msg, "feedback", None) or msg.result
        status_list = payload.goal_status.status_list
        goal = getattr(getattr(msg, "status", None), "goal_id", None)
    except AttributeError:
        raise BagError(f"topic {topic} does not carry the waypoint dispatcher's goal statuses") from None
    return StatusUpdate(
        t,
        getattr(goal, "id", "") or "",
        tuple(str(s.goal_id.id) for s in status_list),
        tuple(int(s.status) for s in status_list),
    )
